//! The command line's grammar: the subcommands and their arguments (clap), and the parsers of
//! vectors, pairs, sizes and row ranges.

use super::choice::choice;
use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use glam::DVec3;
use penumbra::render::RenderMethod;
use penumbra::render::environment_passes::StaticTerm;
use penumbra::scene::environment_spec::EnvMethod;
use penumbra::stochastic::LightSampling;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "penumbra",
    version,
    about = "Analytic soft shadows from polyhedral area lights"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Render a scene with any method (analytic or stochastic); writes .pfm, .exr and .png
    /// (and name_stderr.pfm for `--method reference`).
    Render(RenderArgs),
    /// Render a converged brute-force Monte Carlo reference (ray-cast shadow rays) and its
    /// per-pixel standard error.
    Reference {
        #[command(flatten)]
        render: RenderArgs,
        /// Area samples per light per sub-pixel position.
        #[arg(long, default_value_t = 1024)]
        samples: u32,
    },
    /// Compare two linear images (PFM); with --stderr, in units of the reference's noise.
    Compare {
        image: PathBuf,
        reference: PathBuf,
        /// Per-pixel standard error of the reference (PFM).
        #[arg(long)]
        stderr: Option<PathBuf>,
    },
    /// Random and adversarial shading configurations against a ray-cast oracle.
    Stress {
        #[arg(long, default_value_t = 100_000)]
        cases: u64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Oracle rays per case.
        #[arg(long, default_value_t = 256)]
        rays: u32,
        /// Write the report as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Run only this case and describe it.
        #[arg(long)]
        only: Option<u64>,
        /// Which cases: the generated families in turn, or the meshes of Blender's files and
        /// the bunny shaded where a render shades them.
        #[arg(long, value_parser = choice::<penumbra::stress::Family>(), default_value = "mixed")]
        family: penumbra::stress::Family,
    },
    /// Fit the 64×64 GGX LTC table (Nelder–Mead) and write it.
    FitLtc {
        #[arg(long, default_value = "assets/ltc/ggx_ltc.bin")]
        out: PathBuf,
        #[arg(long, default_value_t = 64)]
        size: usize,
        /// The fit's error metric (docs/ltc.md) [default: the committed table's].
        #[arg(long, value_parser = choice::<penumbra::ltc::fit::Objective>())]
        objective: Option<penumbra::ltc::fit::Objective>,
        /// Store scale = 1 instead of the horizon renormalisation 1/H.
        #[arg(long)]
        no_renorm: bool,
        /// Fit no clamped cosine beside the LTC (share 0 in every entry; the committed table
        /// fits one with `--objective polygons`, docs/ltc.md "Candidates").
        #[arg(long)]
        no_cosine_tail: bool,
        /// Refit only rows FIRST-LAST (roughness rows) of --base, keep the others (experiments).
        #[arg(long, requires = "base", value_parser = parse_rows)]
        rows: Option<(usize, usize)>,
        /// The table whose other rows --rows keeps (as for `render --ltc-table`).
        #[arg(long)]
        base: Option<String>,
        /// Also write the per-cell fit report (TSV, as assets/ltc/fit_report.tsv).
        #[arg(long, conflicts_with = "rows")]
        report: Option<PathBuf>,
    },
    /// The error of LTC tables on polygon integrals over (view angle, roughness): CSV and a
    /// PNG heat map (docs/ltc.md, "Error on polygon integrals").
    LtcError {
        /// Tables as for `render --ltc-table` (repeatable).
        #[arg(long = "table", default_values_t = ["embedded".to_string(), "published".to_string()])]
        tables: Vec<String>,
        /// Also fit an LTC at every map cell itself with this objective (`OBJ`, `OBJ+renorm`,
        /// `polygons+renorm+cosine`; OBJ one of l3-sphere, l3-upper, l2-upper, polygons;
        /// repeatable): candidates without building a table.
        #[arg(long)]
        fit: Vec<String>,
        #[arg(long, default_value = "out/ltc-error")]
        out: PathBuf,
        /// Map cells per axis.
        #[arg(long, default_value_t = 16)]
        grid: usize,
        /// Oracle strata per axis (k × k samples per cell).
        #[arg(long, default_value_t = 1024)]
        samples: usize,
    },
    /// Convert three.js's RectAreaLightTexturesLib.js (Heitz et al.'s published LTC table)
    /// into our table format.
    LtcImportThree {
        js: PathBuf,
        #[arg(long, default_value = "assets/ltc/heitz2016_ggx_ltc_64.bin")]
        out: PathBuf,
    },
    /// Shade one pixel with the stage recorder and write every intermediate polygon as JSON
    /// (the debug dump the workbench replays).
    Probe {
        #[command(flatten)]
        render: RenderArgs,
        /// Pixel position X,Y (fractional positions allowed; the pixel centre is X+0.5,Y+0.5).
        #[arg(long, value_parser = parse_vec2, allow_hyphen_values = true)]
        pixel: (f64, f64),
        /// Record the Greiner–Hormann phases too.
        #[arg(long)]
        gh_steps: bool,
        #[arg(long, default_value = "out/probe.json")]
        json: PathBuf,
    },
    /// A view of one pixel's recorded stages as a figure (SVG, PDF or PNG): live, as `probe
    /// --gh-steps` records it, or from a debug dump given in place of the scene. The views are
    /// the workbench's (`--view`), at the stepper's stage `--stage`. `--out` names the figure:
    /// .svg, .pdf or .png.
    #[command(mut_arg("out", |a| a.default_value("out/figure.svg")
        .help("The figure: .svg or .png")))]
    Figure {
        #[command(flatten)]
        render: RenderArgs,
        #[command(flatten)]
        figure: FigureArgs,
    },
    /// Run time against error: a reference, then every method across a ladder of budgets;
    /// writes CSV, JSON, an equal-time table and a log–log chart. With --scaling, run time
    /// against light and occluder vertices (000 Figs. 5 and 7).
    Bench(BenchArgs),
    /// List the embedded scenes.
    Scenes,
    /// Show the tree cache (where it is, its files and size, its bound) or clear it.
    Cache {
        /// Delete every file of the cache.
        #[arg(long)]
        clear: bool,
        /// Delete the least recently used files until the cache is within its bound.
        #[arg(long)]
        trim: bool,
        /// Write what is shown as JSON here.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Open the workbench window (what `penumbra` without arguments does).
    #[cfg(feature = "gui")]
    Gui(super::gui::GuiArgs),
    /// Move one object rigidly and save the scene as a TOML scene file (with its meshes, in
    /// world space, in OUT's stem .obj/.mtl beside it). The object turns about the vertical
    /// axis through the pivot first, then is translated. See docs/scenes.md, "Editing and
    /// saving scenes".
    Edit {
        #[arg(help = SCENE_HELP)]
        scene: String,
        /// The object to move: its index (0-based, in scene order) or its (unique) name.
        #[arg(long = "move", value_name = "OBJ")]
        object: String,
        /// Translation X,Y,Z in scene units, applied after the rotation.
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
        translate: Option<DVec3>,
        /// Rotation about the vertical (+y) axis through the pivot, degrees (right-handed:
        /// counter-clockwise seen from above).
        #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
        rotate_y: Option<f64>,
        /// The point the rotation's axis goes through [default: the centre of the object's
        /// bounding box].
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
        pivot: Option<DVec3>,
        /// The scene file to write (.toml).
        #[arg(long, value_name = "FILE.toml")]
        out: PathBuf,
    },
}

/// The camera flags shared by every command that renders (default: the scene's camera).
#[derive(Args, Clone, Default)]
pub(crate) struct CameraArgs {
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) eye: Option<DVec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) target: Option<DVec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) up: Option<DVec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    pub(crate) fov: Option<f64>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub(crate) enum BenchSuite {
    Realworld,
    Speed,
}

#[derive(Args, Clone)]
pub(crate) struct BenchArgs {
    #[arg(help = concat!(
        "A penumbra scene file (.toml), a Wavefront OBJ (.obj, with its .mtl), a glTF 2.0 ",
        "file (.glb or .gltf), or the name of an embedded scene (see `penumbra scenes`); not ",
        "needed with --scaling or --suite"
    ))]
    pub(crate) scene: Option<String>,
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    #[arg(long, default_value = "320x240", value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    #[arg(long, default_value_t = 1)]
    pub(crate) aa: u32,
    /// Samples per camera ray of the stochastic methods.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1,2,4,8,16,32,64,128,256"
    )]
    pub(crate) ladder: Vec<u32>,
    /// Methods to run (default: all but `reference`).
    #[arg(long, value_parser = choice::<RenderMethod>(), value_delimiter = ',')]
    pub(crate) methods: Vec<RenderMethod>,
    /// Use this reference image (PFM) instead of rendering one; its standard error is read
    /// from NAME_stderr.pfm beside it.
    #[arg(long)]
    pub(crate) reference: Option<PathBuf>,
    /// Samples per camera ray of the reference (when --reference is given: the count it was
    /// rendered with, for the report).
    #[arg(long, default_value_t = 4096)]
    pub(crate) reference_spp: u32,
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Deterministic methods are timed as the best of this many renders.
    #[arg(long, default_value_t = 2)]
    pub(crate) repeats: u32,
    /// Also time the analytic image with its exact derivative along OBJECT:AXIS (as
    /// `penumbra render --derivative` computes it), as the row `analytic+derivative`.
    #[arg(long)]
    pub(crate) derivative: Option<String>,
    /// Output directory (default out/bench/SCENE, or out/bench/scaling).
    #[arg(long)]
    pub(crate) out_dir: Option<PathBuf>,
    #[arg(long, default_value_t = 0.0)]
    pub(crate) exposure: f64,
    /// Run the scaling study instead (000 Figs. 5 and 7).
    #[arg(long)]
    pub(crate) scaling: bool,
    /// Measure 001 Tables 7.2 and 7.4 on the nine polyhedra of Table 7.1 instead: shading
    /// face by face, with silhouettes on the fly and from BSP trees; tree precomputation.
    #[arg(long)]
    pub(crate) polyhedra: bool,
    /// Run a suite of scenes instead: `realworld` (exporter-style scenes and a scanned mesh;
    /// analytic, per-triangle and unshadowed against the ray-cast reference), or `speed` (the
    /// speed guard: every embedded scene, tests/data/blender and the bunny, each timed as
    /// ratios to its unshadowed render and to a calibration workload measured in the same
    /// run; 256x256 --aa 2, 2 threads, median of 5 rounds).
    #[arg(long, value_enum)]
    pub(crate) suite: Option<BenchSuite>,
    /// --suite speed: compare with this baseline (its size, --aa, threads and rounds are
    /// used) and exit with status 1 when a ratio grew by more than its tolerance, twice.
    #[arg(long)]
    pub(crate) baseline: Option<PathBuf>,
    /// --suite speed: write the measured ratios as a new baseline to this file (a deliberate
    /// commit; --why says why).
    #[arg(long, requires = "why")]
    pub(crate) write_baseline: Option<PathBuf>,
    /// --suite speed: the reason written into a new baseline.
    #[arg(long)]
    pub(crate) why: Option<String>,
    /// --suite speed, internal: measure this one scene in this process with the settings of
    /// --speed-config (JSON), and print its row as JSON. The suite runs each scene so.
    #[arg(long, hide = true, requires = "speed_config")]
    pub(crate) measure_scene: Option<String>,
    #[arg(long, hide = true)]
    pub(crate) speed_config: Option<String>,
    /// Benchmark the environment light of this scene instead (002 Tables 1 and 2: per-pass
    /// times with and without culling, the ladder of rays against the exact method).
    #[arg(long)]
    pub(crate) env: Option<String>,
    /// With --suite: run only these scenes.
    #[arg(long, value_delimiter = ',')]
    pub(crate) only: Vec<String>,
    /// Render nothing: read a bench.json written by an earlier run and write its tables and
    /// chart again (into --out-dir, default beside the JSON).
    #[arg(long)]
    pub(crate) from_json: Option<PathBuf>,
    /// Scaling: copies of the lights / occluders of the fig4 scene (1..=N).
    #[arg(long, default_value_t = 5)]
    pub(crate) max_copies: u32,
    /// Scaling: subdivision levels of the icosahedral light (0..=N).
    #[arg(long, default_value_t = 4)]
    pub(crate) max_level: u32,
}

/// Every input format a SCENE argument takes.
const SCENE_HELP: &str = "A penumbra scene file (.toml), a Wavefront OBJ (.obj, with its .mtl), \
     a glTF 2.0 file (.glb or .gltf), or the name of an embedded scene (see `penumbra scenes`)";

#[derive(Args, Clone)]
pub(crate) struct RenderArgs {
    #[arg(help = SCENE_HELP)]
    pub(crate) scene: String,
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    /// Image size WxH.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    /// N×N stratified sub-pixel positions per pixel.
    #[arg(long, default_value_t = 1)]
    pub(crate) aa: u32,
    #[arg(long, value_parser = choice::<RenderMethod>(), default_value = "analytic")]
    pub(crate) method: RenderMethod,
    /// Stochastic methods: samples (shadow rays) per camera ray [default: 16; for the
    /// environment's ray methods 128, or the scene file's `spp`].
    #[arg(long)]
    pub(crate) spp: Option<u32>,
    /// Stochastic methods: random seed (renders are reproducible bit for bit).
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Stochastic methods: how lights are sampled.
    #[arg(long, value_parser = choice::<LightSampling>(), default_value = "solid-angle")]
    pub(crate) light_sampling: LightSampling,
    /// Ratio and control-variate methods: an unbiased U, the LTC plus its correction sampled
    /// over the unshadowed light (as `analytic-exact` does over the visible one).
    #[arg(long)]
    pub(crate) exact_u: bool,
    /// Output path; the extension is replaced by .pfm, .exr and .png.
    #[arg(long, default_value = "out/render.png")]
    pub(crate) out: PathBuf,
    #[command(flatten)]
    pub(crate) env: EnvArgs,
    /// Exposure in stops for the tone-mapped PNG.
    #[arg(long, default_value_t = 0.0)]
    pub(crate) exposure: f64,
    /// The LTC table of the analytic specular term: `embedded`, `published` (Heitz et al.
    /// 2016, assets/ltc/heitz2016_ggx_ltc_64.bin) or a table file; `+renorm` appended applies
    /// the horizon renormalisation (docs/ltc.md).
    #[arg(long, default_value = "embedded")]
    pub(crate) ltc_table: String,
    /// Also write the image's exact derivative along a rigid motion of one object,
    /// OBJECT:AXIS with AXIS one of tx, ty, tz (per scene unit) or ry (per radian, about +y
    /// through the centre of its bounding box): OUT_derivative.pfm/.exr/.png and
    /// OUT_derivative_mask.pfm (1 where a pixel is masked). `--method analytic` only.
    #[arg(long)]
    pub(crate) derivative: Option<String>,
}

/// The environment light (paper 002), on top of or instead of the scene file's
/// `[environment]`.
#[derive(Args, Clone, Default)]
pub(crate) struct EnvArgs {
    /// Light the scene with an environment too: `sky` (embedded), `sky-sh` (its 3-band
    /// projection: band-limited), an equirectangular .hdr/.exr file, or `none`.
    #[arg(long)]
    pub(crate) env: Option<String>,
    /// Rotation of the environment about +y, degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) env_rotate: Option<f64>,
    /// Scale of the environment's radiance.
    #[arg(long)]
    pub(crate) env_scale: Option<f64>,
    /// How the environment's shadows are computed [default: analytic].
    #[arg(long, value_parser = choice::<EnvMethod>())]
    pub(crate) env_method: Option<EnvMethod>,
    /// `rt`: leave out the 5×5 cross-bilateral filter (the unfiltered images of 002 Fig. 7d).
    #[arg(long)]
    pub(crate) env_no_filter: bool,
    /// `rt`: cluster each point's merged cones into at most this many.
    #[arg(long)]
    pub(crate) env_max_cones: Option<usize>,
    /// How the ray methods (`rt`, `rt-unculled`, `rtao`, `unshadowed`) find E_static on static
    /// surfaces: `prt`, transfer vectors precomputed by ray casting and cached (002 as
    /// published), or `exact`, the polygon integral at every point [default: prt].
    #[arg(long, value_parser = choice::<StaticTerm>())]
    pub(crate) env_static: Option<StaticTerm>,
}

/// The command line: every subcommand takes negative numbers as values (`--exposure -1`,
/// `--seed -1` is then refused for what it is); options whose value is a vector or pair
/// (`--target -0.3,0.2,-0.3`) also allow a leading hyphen (`allow_hyphen_values`).
pub(crate) fn command_line() -> clap::Command {
    use clap::CommandFactory;
    Cli::command().mut_subcommands(|c| c.allow_negative_numbers(true))
}

pub(crate) fn parse_vec3(s: &str) -> Result<DVec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("'{t}': {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
        _ => Err(format!("expected three finite numbers X,Y,Z, got '{s}'")),
    }
}

/// Parses "X,Y" into two numbers.
pub(crate) fn parse_vec2(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y, got '{s}'"))?;
    let a: f64 = a.trim().parse().map_err(|e| format!("'{a}': {e}"))?;
    let b: f64 = b.trim().parse().map_err(|e| format!("'{b}': {e}"))?;
    Ok((a, b))
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, got '{s}'"))?;
    let w: u32 = w.trim().parse().map_err(|e| format!("width '{w}': {e}"))?;
    let h: u32 = h.trim().parse().map_err(|e| format!("height '{h}': {e}"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size {w}x{h} is out of range (1..=16384)"));
    }
    Ok((w, h))
}

/// `FIRST-LAST` (inclusive).
pub(crate) fn parse_rows(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once('-').ok_or("expected FIRST-LAST")?;
    Ok((
        a.trim().parse().map_err(|e| format!("{e}"))?,
        b.trim().parse().map_err(|e| format!("{e}"))?,
    ))
}

/// What `penumbra figure` draws and how.
#[derive(clap::Args, Debug, Clone)]
pub struct FigureArgs {
    /// Pixel position X,Y, or "auto" for the penumbra point the workbench picks on its own
    /// (`inspect::interesting_pixel`). Not needed with a dump.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub pixel: String,
    /// The view: sphere (3-D, framed on the lights), hemisphere (the Nusselt disk), plane
    /// (the projected plane of a set difference), light or bsp (the light's polyhedron and its
    /// tree), environment (the environment's terms, cones and rays on the sphere).
    #[arg(long, default_value = "sphere")]
    pub view: String,
    /// The stage, numbered as the workbench's stepper numbers it (1 to N; "stage i/N"); every
    /// stage when left out.
    #[arg(long)]
    pub stage: Option<usize>,
    /// Which set difference of the recording the plane view shows (0: the first), when no
    /// --stage names one.
    #[arg(long, default_value_t = 0)]
    pub difference: usize,
    /// print (light background, greyscale-safe) or screen (dark).
    #[arg(long, default_value = "print")]
    pub style: String,
    /// Side of the figure in pixels (SVG user units; PDF points).
    #[arg(long, default_value_t = 800)]
    pub figure_size: u32,
    /// The sphere camera as YAW,PITCH[,ZOOM] (degrees; zoom 1 shows the whole sphere) in
    /// place of the framing on the lights.
    #[arg(long, allow_hyphen_values = true)]
    pub orbit: Option<String>,
    /// The hemisphere magnified to what is drawn.
    #[arg(long)]
    pub fit: bool,
    /// The light the light and bsp views show (by object name); the light of --stage, or the
    /// first light recorded, when left out.
    #[arg(long)]
    pub light: Option<String>,
}
