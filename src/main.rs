//! The `penumbra` command line: `render`, `reference`, `stress`, `fit-ltc`.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use glam::DVec3;
use penumbra::environment::{EnvMethod, EnvironmentLight, EnvironmentSource, EnvironmentSpec};
use penumbra::render::environment::{EnvironmentSettings, StaticTerm};
use penumbra::render::{Image, RenderContext, RenderMethod, RenderSettings, image_io};
use penumbra::scene::{Camera, Scene, scene_file};
use penumbra::stochastic::LightSampling;
use std::path::{Path, PathBuf};

/// `println!` that ignores a closed stdout (e.g. piped into `head`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "penumbra",
    version,
    about = "Analytic soft shadows from polyhedral area lights"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
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
    },
    /// Fit the 64×64 GGX LTC table (Nelder–Mead) and write it.
    FitLtc {
        #[arg(long, default_value = "assets/ltc/ggx_ltc.bin")]
        out: PathBuf,
        #[arg(long, default_value_t = 64)]
        size: usize,
        /// The fit's error metric (docs/ltc.md) [default: the committed table's].
        #[arg(long, value_enum)]
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
    Gui(penumbra::app::RunOptions),
    /// Move one object rigidly and save the scene as a TOML scene file (with its meshes, in
    /// world space, in OUT's stem .obj/.mtl beside it). The object turns about the vertical
    /// axis through the pivot first, then is translated. See docs/scenes.md, "Editing and
    /// saving scenes".
    Edit {
        /// A scene file or embedded scene name.
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
struct CameraArgs {
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<DVec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<DVec3>,
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<DVec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    fov: Option<f64>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum BenchSuite {
    Realworld,
}

#[derive(Args, Clone)]
struct BenchArgs {
    /// A scene file or embedded scene name (not needed with --scaling).
    scene: Option<String>,
    #[command(flatten)]
    camera: CameraArgs,
    #[arg(long, default_value = "320x240", value_parser = parse_size)]
    size: (u32, u32),
    #[arg(long, default_value_t = 1)]
    aa: u32,
    /// Samples per camera ray of the stochastic methods.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1,2,4,8,16,32,64,128,256"
    )]
    ladder: Vec<u32>,
    /// Methods to run (default: all but `reference`).
    #[arg(long, value_enum, value_delimiter = ',')]
    methods: Vec<RenderMethod>,
    /// Use this reference image (PFM) instead of rendering one; its standard error is read
    /// from NAME_stderr.pfm beside it.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Samples per camera ray of the reference (when --reference is given: the count it was
    /// rendered with, for the report).
    #[arg(long, default_value_t = 4096)]
    reference_spp: u32,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Deterministic methods are timed as the best of this many renders.
    #[arg(long, default_value_t = 2)]
    repeats: u32,
    /// Output directory (default out/bench/SCENE, or out/bench/scaling).
    #[arg(long)]
    out_dir: Option<PathBuf>,
    #[arg(long, default_value_t = 0.0)]
    exposure: f64,
    /// Run the scaling study instead (000 Figs. 5 and 7).
    #[arg(long)]
    scaling: bool,
    /// Measure 001 Tables 7.2 and 7.4 on the nine polyhedra of Table 7.1 instead: shading
    /// face by face, with silhouettes on the fly and from BSP trees; tree precomputation.
    #[arg(long)]
    polyhedra: bool,
    /// Run a suite of scenes instead: `realworld` (exporter-style scenes and a scanned mesh;
    /// analytic, per-triangle and unshadowed against the ray-cast reference).
    #[arg(long, value_enum)]
    suite: Option<BenchSuite>,
    /// Benchmark the environment light of this scene instead (002 Tables 1 and 2: per-pass
    /// times with and without culling, the ladder of rays against the exact method).
    #[arg(long)]
    env: Option<String>,
    /// With --suite: run only these scenes.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Render nothing: read a bench.json written by an earlier run and write its tables and
    /// chart again (into --out-dir, default beside the JSON).
    #[arg(long)]
    from_json: Option<PathBuf>,
    /// Scaling: copies of the lights / occluders of the fig4 scene (1..=N).
    #[arg(long, default_value_t = 5)]
    max_copies: u32,
    /// Scaling: subdivision levels of the icosahedral light (0..=N).
    #[arg(long, default_value_t = 4)]
    max_level: u32,
}

#[derive(Args, Clone)]
struct RenderArgs {
    /// A scene file (.toml or .obj) or the name of an embedded scene (see `penumbra scenes`).
    scene: String,
    #[command(flatten)]
    camera: CameraArgs,
    /// Image size WxH.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    size: (u32, u32),
    /// N×N stratified sub-pixel positions per pixel.
    #[arg(long, default_value_t = 1)]
    aa: u32,
    #[arg(long, value_enum, default_value_t = RenderMethod::Analytic)]
    method: RenderMethod,
    /// Stochastic methods: samples (shadow rays) per camera ray [default: 16; for the
    /// environment's ray methods 128, or the scene file's `spp`].
    #[arg(long)]
    spp: Option<u32>,
    /// Stochastic methods: random seed (renders are reproducible bit for bit).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Stochastic methods: how lights are sampled.
    #[arg(long, value_enum, default_value_t = LightSampling::SolidAngle)]
    light_sampling: LightSampling,
    /// Ratio and control-variate methods: an unbiased U, the LTC plus its correction sampled
    /// over the unshadowed light (as `analytic-exact` does over the visible one).
    #[arg(long)]
    exact_u: bool,
    /// Output path; the extension is replaced by .pfm, .exr and .png.
    #[arg(long, default_value = "out/render.png")]
    out: PathBuf,
    #[command(flatten)]
    env: EnvArgs,
    /// Exposure in stops for the tone-mapped PNG.
    #[arg(long, default_value_t = 0.0)]
    exposure: f64,
    /// The LTC table of the analytic specular term: `embedded`, `published` (Heitz et al.
    /// 2016, assets/ltc/heitz2016_ggx_ltc_64.bin) or a table file; `+renorm` appended applies
    /// the horizon renormalisation (docs/ltc.md).
    #[arg(long, default_value = "embedded")]
    ltc_table: String,
}

/// The environment light (paper 002), on top of or instead of the scene file's
/// `[environment]`.
#[derive(Args, Clone, Default)]
struct EnvArgs {
    /// Light the scene with an environment too: `sky` (embedded), `sky-sh` (its 3-band
    /// projection: band-limited), an equirectangular .hdr/.exr file, or `none`.
    #[arg(long)]
    env: Option<String>,
    /// Rotation of the environment about +y, degrees.
    #[arg(long, allow_hyphen_values = true)]
    env_rotate: Option<f64>,
    /// Scale of the environment's radiance.
    #[arg(long)]
    env_scale: Option<f64>,
    /// How the environment's shadows are computed [default: analytic].
    #[arg(long, value_enum)]
    env_method: Option<EnvMethod>,
    /// `rt`: leave out the 5×5 cross-bilateral filter (the unfiltered images of 002 Fig. 7d).
    #[arg(long)]
    env_no_filter: bool,
    /// `rt`: cluster each point's merged cones into at most this many.
    #[arg(long)]
    env_max_cones: Option<usize>,
    /// How the ray methods (`rt`, `rt-unculled`, `rtao`, `unshadowed`) find E_static on static
    /// surfaces: `prt`, transfer vectors precomputed by ray casting and cached (002 as
    /// published), or `exact`, the polygon integral at every point [default: prt].
    #[arg(long, value_enum)]
    env_static: Option<StaticTerm>,
}

/// Rays per camera ray of the environment's ray methods when neither `--spp` nor the scene
/// says (002 Sect. 5 uses 128).
const ENV_DEFAULT_SPP: u32 = 128;

/// Puts the environment `args` ask for into `scene.environment` (the command line overrides
/// the scene file's `[environment]`; `--env none` removes it), so that the scene is prepared
/// knowing it has one.
fn resolve_environment(scene: &mut Scene, args: &RenderArgs) -> Result<()> {
    let e = &args.env;
    let mut spec = match (e.env.as_deref(), &scene.environment) {
        (Some("none"), _) => {
            scene.environment = None;
            return Ok(());
        }
        (Some(map), base) => {
            let mut spec =
                EnvironmentSpec::new(map, None, None, None, None).map_err(anyhow::Error::msg)?;
            if let Some(b) = base {
                spec.rotate_deg = b.rotate_deg;
                spec.scale = b.scale;
                spec.method = b.method;
                spec.spp = b.spp;
            }
            spec
        }
        (None, Some(base)) => base.clone(),
        (None, None) => {
            if e.env_method.is_some() || e.env_rotate.is_some() || e.env_scale.is_some() {
                bail!(
                    "--env-method, --env-rotate and --env-scale need an environment: pass --env sky|sky-sh|FILE"
                );
            }
            return Ok(());
        }
    };
    if let Some(r) = e.env_rotate {
        spec.rotate_deg = r;
    }
    if let Some(s) = e.env_scale {
        spec.scale = s;
    }
    spec.method = e.env_method.or(spec.method);
    spec.spp = args.spp.or(spec.spp);
    // Validate the merged values the same way a scene file's are.
    let map = match &spec.source {
        EnvironmentSource::Sky => "sky".to_string(),
        EnvironmentSource::SkySh => "sky-sh".to_string(),
        EnvironmentSource::File(p) => p.display().to_string(),
    };
    scene.environment = Some(
        EnvironmentSpec::new(
            &map,
            Some(spec.rotate_deg),
            Some(spec.scale),
            spec.method,
            spec.spp,
        )
        .map_err(anyhow::Error::msg)?,
    );
    Ok(())
}

/// Loads the scene's environment (after [`resolve_environment`]) and attaches it to `ctx`.
/// GGX lobes get no environment light (002 is diffuse): said once here.
fn attach_environment(
    ctx: &mut RenderContext,
    scene: &Scene,
    args: &RenderArgs,
) -> Result<Option<EnvironmentSettings>> {
    let Some(spec) = &scene.environment else {
        return Ok(None);
    };
    let light = EnvironmentLight::load(spec)?;
    let method = spec.method.unwrap_or(EnvMethod::Analytic);
    let mut settings =
        EnvironmentSettings::new(method, spec.spp.unwrap_or(ENV_DEFAULT_SPP), args.seed);
    if args.env.env_no_filter {
        settings.filter = false;
    }
    settings.max_cones = args.env.env_max_cones;
    if let Some(t) = args.env.env_static {
        settings.static_term = t;
    }
    if scene.objects.iter().any(|o| o.material.has_specular()) {
        eprintln!(
            "note: the environment lights the diffuse lobe only (002 is diffuse); GGX lobes see the area lights alone"
        );
    }
    ctx.set_environment(std::sync::Arc::new(light), settings);
    Ok(Some(settings))
}

fn parse_vec3(s: &str) -> Result<DVec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("'{t}': {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
        _ => Err(format!("expected three finite numbers X,Y,Z, got '{s}'")),
    }
}

fn parse_vec2(s: &str) -> Result<(f64, f64), String> {
    penumbra::inspect::parse_pair(s)
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
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

/// `penumbra edit`: one rigid edit of one object, then the scene saved.
fn edit(
    name: &str,
    object: &str,
    translate: Option<DVec3>,
    rotate_y: Option<f64>,
    pivot: Option<DVec3>,
    out: &Path,
) -> Result<()> {
    use penumbra::scene::edit::{EditHistory, Rigid, resolve_object};
    if out
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("toml"))
    {
        bail!(
            "--out must name a .toml scene file, got '{}'",
            out.display()
        );
    }
    let mut scene = load_scene(name)?;
    let index = resolve_object(&scene, object).map_err(anyhow::Error::msg)?;
    let mut history = EditHistory::new(&scene);
    let pivot = match pivot {
        Some(p) => p,
        None => history.pivot(index).map_err(anyhow::Error::msg)?,
    };
    let rotation = Rigid::rotation_about(pivot, DVec3::Y, rotate_y.unwrap_or(0.0).to_radians())
        .map_err(anyhow::Error::msg)?;
    let motion = rotation.then(Rigid::translation(translate.unwrap_or(DVec3::ZERO)));
    history
        .edit(&mut scene, index, motion)
        .map_err(anyhow::Error::msg)?;
    let saved = penumbra::scene::save::save_scene(&scene, scene.camera.as_ref(), out)
        .map_err(anyhow::Error::msg)?;
    for (old, new) in &saved.renamed {
        eprintln!("note: '{old}' is written as '{new}' (names must be unique)");
    }
    say!(
        "moved object {index} '{}' (rotated {}° about +y through {}, then translated by {}); wrote {}, {}, {}",
        scene.objects[index].name,
        rotate_y.unwrap_or(0.0),
        fmt_vec(pivot),
        fmt_vec(translate.unwrap_or(DVec3::ZERO)),
        saved.toml.display(),
        saved.obj.display(),
        saved.mtl.display()
    );
    Ok(())
}

fn fmt_vec(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

fn load_scene(name: &str) -> Result<Scene> {
    let scene = penumbra::scene::scene_file::load_scene_by_name(name)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

fn camera(args: &CameraArgs, scene: &Scene) -> Result<Camera> {
    let base = scene.camera;
    let pick = |v: Option<DVec3>, f: fn(&Camera) -> DVec3, what: &str| -> Result<DVec3> {
        v.or(base.as_ref().map(f))
            .with_context(|| format!("the scene has no camera: pass --{what}"))
    };
    let cam = Camera {
        eye: pick(args.eye, |c| c.eye, "eye")?,
        target: pick(args.target, |c| c.target, "target")?,
        up: pick(args.up, |c| c.up, "up")?,
        fov_deg: args
            .fov
            .or(base.map(|c| c.fov_deg))
            .context("the scene has no camera: pass --fov")?,
        // A field of view given by flag is vertical, whatever the image's aspect.
        aspect: if args.fov.is_some() {
            None
        } else {
            base.and_then(|c| c.aspect)
        },
    };
    cam.basis().map_err(anyhow::Error::msg)?;
    Ok(cam)
}

fn write_outputs(img: &Image, out: &Path, exposure: f64) -> Result<Vec<PathBuf>> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    let rgb = img.to_rgb32();
    let pfm = out.with_extension("pfm");
    let exr = out.with_extension("exr");
    let png = out.with_extension("png");
    image_io::write_pfm(&pfm, img.width, img.height, &rgb)
        .with_context(|| format!("{}", pfm.display()))?;
    image_io::write_exr(&exr, img.width, img.height, &rgb)?;
    image_io::write_png(&png, img.width, img.height, &rgb, exposure)?;
    Ok(vec![pfm, exr, png])
}

/// `dir/name_stderr.pfm` beside `dir/name.ext`: the standard error of a reference image.
fn stderr_path(out: &Path) -> PathBuf {
    out.with_file_name(format!(
        "{}_stderr.pfm",
        out.file_stem()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default()
    ))
}

fn settings(args: &RenderArgs) -> RenderSettings {
    RenderSettings {
        width: args.size.0,
        height: args.size.1,
        aa: args.aa,
        method: args.method,
        spp: args.spp.unwrap_or(16),
        seed: args.seed,
        light_sampling: args.light_sampling,
        collect_stats: false,
        exact_u: args.exact_u,
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    let mut scene = load_scene(&args.scene)?;
    resolve_environment(&mut scene, args)?;
    let cam = camera(&args.camera, &scene)?;
    let settings = settings(args);
    let mut ctx = RenderContext::for_render(&scene, &settings);
    ctx.prepared.ltc = ltc_table(&args.ltc_table)?;
    for n in &ctx.prepared.notes {
        eprintln!("note: {n}");
    }
    let env = attach_environment(&mut ctx, &scene, args)?;
    let out = ctx
        .render_full(&cam, &settings, None)
        .map_err(anyhow::Error::msg)?;
    let (img, stats) = (&out.image, out.stats);
    let (nan, inf, neg) = img.invalid_counts();
    let mut files = write_outputs(img, &args.out, args.exposure)?;
    if let Some(err) = &out.stderr {
        let p = stderr_path(&args.out);
        image_io::write_pfm(&p, err.width, err.height, &err.to_rgb32())?;
        files.push(p);
    }
    say!(
        "{} {}x{} aa {} method {}: {:.3} s, {:.0} pixels/s ({} threads)",
        args.scene,
        settings.width,
        settings.height,
        settings.aa,
        settings.method.name(),
        stats.seconds,
        stats.pixels_per_second,
        rayon::current_num_threads()
    );
    if let (Some(env), Some(e)) = (env, &out.environment) {
        let t = &e.stats;
        say!(
            "environment {} method {} spp {}: g-buffer {:.3} s, occlusion {:.3} s, filter {:.3} s, composition {:.3} s; rays traced {} of {}",
            ctx.environment
                .as_ref()
                .map_or("", |x| x.light.label.as_str()),
            env.method.name(),
            env.spp,
            t.gbuffer_seconds,
            t.occlusion_seconds,
            t.filter_seconds,
            t.composition_seconds,
            t.rays_traced,
            t.rays_total
        );
        if let Some(r) = ctx.environment.as_ref().and_then(|x| x.transfer_report) {
            say!("precomputed transfer (PRT) of the static surfaces: {r}");
        }
    }
    if nan + inf + neg > 0 {
        eprintln!("warning: {nan} NaN, {inf} infinite and {neg} negative pixel values");
    }
    if settings.method.analytic().is_some() {
        say!(
            "invariant, shadowed <= unshadowed per light piece: {} violations",
            stats.violations
        );
    }
    if stats.violations > 0 {
        let p = args.out.with_extension("violations.json");
        std::fs::write(&p, serde_json::to_string(&out.violation_pixels)?)
            .with_context(|| format!("writing {}", p.display()))?;
        eprintln!(
            "warning: {} light pieces saw more than the light (a visible polygon not inside the \
             light's: shadowed > unshadowed) at the pixels listed in {}; this is a bug, please \
             report it with the scene",
            stats.violations,
            p.display()
        );
    }
    for f in files {
        say!("wrote {}", f.display());
    }
    Ok(())
}

fn reference(args: &RenderArgs, samples: u32, seed: u64) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let cam = camera(&args.camera, &scene)?;
    let ctx = RenderContext::new(&scene);
    let settings = settings(args);
    let start = std::time::Instant::now();
    let (img, err) = penumbra::reference::render_reference(&ctx, &cam, &settings, samples, seed)
        .map_err(anyhow::Error::msg)?;
    say!(
        "reference {}: {samples} samples per light, {:.3} s",
        args.scene,
        start.elapsed().as_secs_f64()
    );
    for f in write_outputs(&img, &args.out, args.exposure)? {
        say!("wrote {}", f.display());
    }
    let stderr_path = stderr_path(&args.out);
    image_io::write_pfm(&stderr_path, err.width, err.height, &err.to_rgb32())?;
    say!("wrote {}", stderr_path.display());
    Ok(())
}

/// Writes the debug dump of one shading point (`penumbra probe`).
fn probe(args: &RenderArgs, pixel: (f64, f64), gh_steps: bool, json: &Path) -> Result<()> {
    let mut scene = load_scene(&args.scene)?;
    // The environment exactly as `render` resolves and attaches it (the same --env options).
    resolve_environment(&mut scene, args)?;
    let cam = camera(&args.camera, &scene)?;
    let mut ctx = RenderContext::new(&scene);
    ctx.prepared.ltc = ltc_table(&args.ltc_table)?;
    attach_environment(&mut ctx, &scene, args)?;
    // analytic-exact: the analytic stages plus the LTC's correction, sampled as the first
    // pass of an `--aa 1` render with the same --spp and --seed samples this pixel.
    let (method, correction) = match (args.method, args.method.analytic()) {
        (_, Some(m)) => (m, None),
        (RenderMethod::AnalyticExact, None) => (
            penumbra::shading::Method::Analytic,
            Some(penumbra::shading::CorrectionSampling {
                samples: args.spp.unwrap_or(16),
                seed: args.seed,
                stream: penumbra::inspect::correction_stream(pixel, args.size.0),
            }),
        ),
        _ => bail!(
            "probe records the analytic stages: --method must be analytic, analytic-exact, \
             per-triangle or unshadowed"
        ),
    };
    let mut dump = penumbra::inspect::probe_corrected(
        &ctx,
        &args.scene,
        &cam,
        args.size,
        pixel,
        method,
        correction,
        gh_steps,
    )
    .map_err(anyhow::Error::msg)?;
    if let (Some(sp), Some(m)) = (dump.point, dump.material.clone()) {
        dump.monte_carlo = Some(penumbra::inspect::monte_carlo(
            &ctx, &sp, &m, 65536, args.seed,
        ));
    }
    if let Some(dir) = json.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    }
    std::fs::write(json, serde_json::to_string_pretty(&dump)?)
        .with_context(|| format!("{}", json.display()))?;
    say!("radiance {} at pixel {pixel:?}", dump.radiance);
    for l in &dump.lights {
        say!(
            "  light {} '{}': shadowed {} unshadowed {}, visible {:.1} % of {:.4} sr",
            l.light,
            l.name,
            l.shadowed,
            l.unshadowed,
            100.0 * l.visible_fraction(),
            l.solid_angle
        );
    }
    if let Some(mc) = dump.monte_carlo {
        say!(
            "  Monte Carlo ({} samples): {} ± {} (1σ)",
            mc.samples,
            mc.mean,
            mc.stderr
        );
    }
    if let Some(e) = &dump.environment {
        let env = &dump.recording.environment;
        say!(
            "  environment {} (rotate {}°, scale {}), {}: radiance {}{}",
            e.label,
            e.rotate_deg,
            e.scale,
            e.settings.map_or("", |s| s.method.name()),
            e.radiance,
            if e.filtered_in_render {
                " (before the 5×5 filter)"
            } else {
                ""
            }
        );
        if let Some(s) = &e.sample {
            say!(
                "    E_unshadowed {} E_static {:?} E_occluded {:?} E {}",
                s.unshadowed,
                s.e_static,
                s.occluded,
                s.irradiance
            );
        }
        if let (Some(st), Some(oc)) = (e.exact_static, e.exact_occluded) {
            say!("    exact: E_static {st} E_occluded {oc}");
        }
        let terms = if env.terms.is_empty() {
            &e.exact_terms
        } else {
            &env.terms
        };
        say!(
            "    {} union terms, {} cones ({} merged), {} rays ({} traced)",
            terms.len(),
            env.cones.len(),
            env.merged_cones.len(),
            env.rays.len(),
            env.rays
                .iter()
                .filter(|r| r.outcome != penumbra::shading::RayOutcome::Culled)
                .count()
        );
    }
    say!("wrote {}", json.display());
    Ok(())
}

/// `penumbra bench --env SCENE`.
fn bench_environment(args: &BenchArgs, name: &str) -> Result<()> {
    use penumbra::bench::environment::{
        EnvBenchOptions, environment_markdown, run_environment_bench,
    };
    let mut scene = load_scene(name)?;
    if scene.environment.is_none() {
        scene.environment =
            Some(EnvironmentSpec::new("sky", None, None, None, None).map_err(anyhow::Error::msg)?);
    }
    let cam = camera(&args.camera, &scene)?;
    let ladder = if args.ladder == [1, 2, 4, 8, 16, 32, 64, 128, 256] {
        vec![16, 32, 64, 128, 256, 512]
    } else {
        args.ladder.clone()
    };
    let opts = EnvBenchOptions {
        width: args.size.0,
        height: args.size.1,
        aa: args.aa,
        reference_spp: args.reference_spp,
        ladder,
        repeats: args.repeats,
        seed: args.seed,
    };
    let report = run_environment_bench(name, &scene, &cam, &opts, |m| eprintln!("{m}"))
        .map_err(anyhow::Error::msg)?;
    let stem = Path::new(name)
        .file_stem()
        .map_or_else(|| name.to_string(), |s| s.to_string_lossy().into_owned());
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("out/bench/env_{stem}")));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let md = environment_markdown(&report);
    say!("{md}");
    for (path, text) in [
        (dir.join("environment.md"), md),
        (
            dir.join("environment.json"),
            serde_json::to_string_pretty(&report)?,
        ),
    ] {
        std::fs::write(&path, text).with_context(|| format!("{}", path.display()))?;
        say!("wrote {}", path.display());
    }
    Ok(())
}

fn bench(args: &BenchArgs) -> Result<()> {
    use penumbra::bench::{output, runner, scaling};
    if let Some(json) = &args.from_json {
        let report = penumbra::bench::table::read_json(json)
            .with_context(|| format!("{}", json.display()))?;
        let dir = args.out_dir.clone().unwrap_or_else(|| {
            json.parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
        });
        say!("{}", output::equal_time_markdown(&report));
        for f in output::write_bench_files(&report, &[], &dir, args.exposure)? {
            say!("wrote {}", f.display());
        }
        return Ok(());
    }
    if let Some(BenchSuite::Realworld) = args.suite {
        return bench_realworld(args);
    }
    if let Some(name) = &args.env {
        return bench_environment(args, name);
    }
    if args.polyhedra {
        let report = penumbra::bench::polyhedra::run_polyhedra(
            args.size.0,
            args.size.1,
            args.repeats,
            |m| eprintln!("{m}"),
        )
        .map_err(anyhow::Error::msg)?;
        let dir = args
            .out_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/bench/polyhedra"));
        std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
        let md = penumbra::bench::polyhedra::polyhedra_markdown(&report);
        say!("{md}");
        let files = [
            (dir.join("polyhedra.md"), md),
            (
                dir.join("polyhedra.json"),
                serde_json::to_string_pretty(&report)?,
            ),
        ];
        for (path, text) in files {
            std::fs::write(&path, text).with_context(|| format!("{}", path.display()))?;
            say!("wrote {}", path.display());
        }
        return Ok(());
    }
    if args.scaling {
        let base = scene_file::load_embedded("fig4")?;
        let report = scaling::run_scaling(
            &base,
            args.max_copies.max(2),
            args.max_level,
            args.size.0,
            args.size.1,
            args.repeats,
            |m| eprintln!("{m}"),
        )
        .map_err(anyhow::Error::msg)?;
        let dir = args
            .out_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/bench/scaling"));
        say!("{}", output::scaling_markdown(&report));
        for f in output::write_scaling_files(&report, &dir)? {
            say!("wrote {}", f.display());
        }
        return Ok(());
    }
    let Some(scene_name) = args.scene.clone() else {
        bail!("bench needs a SCENE (or --scaling)");
    };
    let scene = load_scene(&scene_name)?;
    let cam = camera(&args.camera, &scene)?;
    let ctx = RenderContext::new(&scene);
    let label = Path::new(&scene_name)
        .file_stem()
        .map_or(scene_name.clone(), |s| s.to_string_lossy().into_owned());
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench").join(&label));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let mut config = runner::BenchConfig::new(&label, cam, args.size.0, args.size.1);
    config.aa = args.aa;
    config.ladder = args.ladder.clone();
    if !args.methods.is_empty() {
        config.methods = args.methods.clone();
    }
    config.reference_spp = args.reference_spp;
    config.seed = args.seed;
    config.repeats = args.repeats;
    let reference = match &args.reference {
        Some(path) => {
            let read = |p: &Path| -> Result<Image> {
                image_io::read_pfm_image(p).with_context(|| format!("{}", p.display()))
            };
            runner::ReferenceImage {
                image: read(path)?,
                stderr: read(&stderr_path(path))?,
                spp: args.reference_spp,
                seconds: f64::NAN,
            }
        }
        None => {
            eprintln!(
                "rendering the reference ({} spp, {}x{})...",
                config.reference_spp, config.width, config.height
            );
            let r = runner::render_reference(&ctx, &config).map_err(anyhow::Error::msg)?;
            let p = dir.join("reference.pfm");
            image_io::write_pfm(&p, r.image.width, r.image.height, &r.image.to_rgb32())?;
            let e = stderr_path(&p);
            image_io::write_pfm(&e, r.stderr.width, r.stderr.height, &r.stderr.to_rgb32())?;
            say!(
                "reference: {:.1} s; wrote {} and {}",
                r.seconds,
                p.display(),
                e.display()
            );
            r
        }
    };
    let (report, strip) = runner::run_bench(&ctx, &config, &reference, |k, n, what| {
        eprintln!("[{k}/{n}] {what}")
    })
    .map_err(anyhow::Error::msg)?;
    say!("{}", output::equal_time_markdown(&report));
    for f in output::write_bench_files(&report, &strip, &dir, args.exposure)? {
        say!("wrote {}", f.display());
    }
    Ok(())
}

/// `penumbra bench --suite realworld`.
fn bench_realworld(args: &BenchArgs) -> Result<()> {
    use penumbra::bench::realworld::{RealWorldConfig, realworld_markdown, run_realworld};
    let config = RealWorldConfig {
        width: args.size.0,
        height: args.size.1,
        aa: args.aa,
        reference_spp: args.reference_spp,
        repeats: args.repeats,
        seed: args.seed,
        only: args.only.clone(),
    };
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench/realworld"));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    // The tables are written again after every scene, so that a long run leaves what it did.
    let write = |report: &penumbra::bench::realworld::RealWorldReport| -> Result<[PathBuf; 2]> {
        let files = [
            (dir.join("realworld.md"), realworld_markdown(report)),
            (
                dir.join("realworld.json"),
                serde_json::to_string_pretty(report)?,
            ),
        ];
        for (path, text) in &files {
            std::fs::write(path, text).with_context(|| format!("{}", path.display()))?;
        }
        Ok(files.map(|f| f.0))
    };
    let report = run_realworld(
        &dir,
        &config,
        |m| eprintln!("{m}"),
        |partial| {
            if let Err(e) = write(partial) {
                eprintln!("warning: {e:#}");
            }
        },
    )
    .map_err(anyhow::Error::msg)?;
    let md = realworld_markdown(&report);
    say!("{md}");
    for row in &report.scenes {
        for n in row.warnings.iter().chain(&row.notes) {
            say!("{}: {n}", row.scene);
        }
    }
    for path in write(&report)? {
        say!("wrote {}", path.display());
    }
    Ok(())
}

fn compare(image: &Path, reference: &Path, stderr: Option<&Path>) -> Result<()> {
    let read = |p: &Path| image_io::read_pfm(p).with_context(|| format!("{}", p.display()));
    let (w, h, a) = read(image)?;
    let (w2, h2, b) = read(reference)?;
    if (w, h) != (w2, h2) {
        bail!(
            "{} is {w}x{h} but {} is {w2}x{h2}",
            image.display(),
            reference.display()
        );
    }
    let s = stderr.map(read).transpose()?;
    let stats = penumbra::render::compare::compare(&a, &b, s.as_ref().map(|s| &s.2[..]));
    say!("{}", serde_json::to_string_pretty(&stats)?);
    Ok(())
}

/// `penumbra cache`: the tree cache's place, contents and bound; `--trim`, `--clear`.
fn cache(clear: bool, trim: bool, json: Option<&Path>) -> Result<()> {
    use penumbra::shading::tree_cache::{CacheUsage, TreeCache};
    let Some(cache) = TreeCache::from_env().map_err(anyhow::Error::msg)? else {
        say!("the tree cache is disabled (PENUMBRA_CACHE_DIR=off, or no home directory)");
        return Ok(());
    };
    let removed = if clear {
        Some(cache.clear())
    } else if trim {
        Some(cache.trim())
    } else {
        None
    };
    let usage = cache.usage();
    let mb = |b: u64| b as f64 / (1u64 << 20) as f64;
    say!("tree cache: {}", cache.dir.display());
    if let Some(CacheUsage { files, bytes }) = removed {
        say!("deleted {files} files, {:.1} MiB", mb(bytes));
    }
    say!(
        "{} files, {:.1} MiB of at most {:.1} MiB (PENUMBRA_CACHE_MAX)",
        usage.files,
        mb(usage.bytes),
        mb(cache.max_bytes)
    );
    if let Some(path) = json {
        let report = serde_json::json!({
            "dir": cache.dir,
            "files": usage.files,
            "bytes": usage.bytes,
            "max_bytes": cache.max_bytes,
            "deleted": removed,
        });
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("{}", path.display()))?;
    }
    Ok(())
}

/// The command line: every subcommand takes negative numbers as values (`--exposure -1`,
/// `--seed -1` is then refused for what it is); options whose value is a vector or pair
/// (`--target -0.3,0.2,-0.3`) also allow a leading hyphen (`allow_hyphen_values`).
fn command_line() -> clap::Command {
    use clap::CommandFactory;
    Cli::command().mut_subcommands(|c| c.allow_negative_numbers(true))
}

/// `FIRST-LAST` (inclusive).
fn parse_rows(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once('-').ok_or("expected FIRST-LAST")?;
    Ok((
        a.trim().parse().map_err(|e| format!("{e}"))?,
        b.trim().parse().map_err(|e| format!("{e}"))?,
    ))
}

/// `--ltc-table`: `embedded`, `published` or a table file, optionally followed by `+renorm`
/// (horizon renormalisation). Tables other than the embedded ones live for the whole run.
fn ltc_table(spec: &str) -> Result<&'static penumbra::ltc::LtcTable> {
    use penumbra::ltc::LtcTable;
    let (name, renorm) = match spec.strip_suffix("+renorm") {
        Some(n) => (n, true),
        None => (spec, false),
    };
    let base: &'static LtcTable = match name {
        "embedded" => LtcTable::embedded(),
        "published" => penumbra::ltc::published::published(),
        path => Box::leak(Box::new(
            LtcTable::load(path).with_context(|| format!("LTC table {path}"))?,
        )),
    };
    Ok(if renorm {
        Box::leak(Box::new(base.horizon_renormalized()))
    } else {
        base
    })
}

/// `penumbra ltc-error`: the polygon-integral error map of `tables` (and of LTCs fitted at
/// the map's cells with the objectives `fits`), as CSV, PNG and a printed summary.
fn ltc_error(tables: &[String], fits: &[String], out: &Path, m: usize, k: usize) -> Result<()> {
    use clap::ValueEnum;
    use penumbra::ltc::error_map::{Source, compute_map, heat_map_png, summarize, to_csv};
    use penumbra::ltc::fit::{FitOptions, Objective, fit_grid};
    std::fs::create_dir_all(out).with_context(|| format!("{}", out.display()))?;
    let start = std::time::Instant::now();
    let mut sources = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for t in tables {
        sources.push(Source::Table(ltc_table(t)?));
        names.push(t.clone());
    }
    for f in fits {
        let mut parts = f.split('+');
        let obj = parts.next().unwrap_or_default();
        let objective = Objective::from_str(obj, true).map_err(anyhow::Error::msg)?;
        let mut fo = FitOptions {
            objective,
            renormalize: false,
            cosine_tail: false,
        };
        for flag in parts {
            match flag {
                "renorm" => fo.renormalize = true,
                "cosine" if matches!(objective, Objective::Polygons | Objective::Combined) => {
                    fo.cosine_tail = true
                }
                _ => bail!(
                    "--fit {f}: unknown option +{flag} (expected +renorm, or +cosine with polygons)"
                ),
            }
        }
        // The map's grid plus a normal-incidence column to start every row from.
        let grid = penumbra::ltc::polygon_error::map_grid(m);
        let alphas: Vec<f64> = (0..m).map(|i| grid[i * m].3).collect();
        let mut cosines = vec![1.0];
        cosines.extend((0..m).map(|j| grid[j].2));
        let cells = fit_grid(&alphas, &cosines, &fo, |_, _| {});
        let entries = (0..m * m)
            .map(|q| cells[(q / m) * (m + 1) + q % m + 1].entry)
            .collect();
        eprintln!(
            "fitted {f} at the map's cells: {:.1} s",
            start.elapsed().as_secs_f64()
        );
        sources.push(Source::Entries(entries));
        names.push(format!("fit {f}"));
    }
    let cells = compute_map(&sources, m, k);
    let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
    std::fs::write(out.join("ltc_error.csv"), to_csv(&cells, &name_refs))?;
    heat_map_png(&cells, &name_refs, m, &out.join("ltc_error.png"))?;
    say!(
        "{m}x{m} configurations, {} polygons each, {k}x{k} oracle samples, {:.1} s",
        cells[0].oracle.values.len(),
        start.elapsed().as_secs_f64()
    );
    say!(
        "table | RMS all | RMS (θv>=60°, α<=0.4) | median cell RMS | max cell RMS (cosθv, α) | max rel (>=10% lobe) | mean signed | max CI"
    );
    for (t, name) in names.iter().enumerate() {
        let s = summarize(&cells, t);
        say!(
            "{name} | {:.4} | {:.4} | {:.4} | {:.4} ({:.3}, {:.3}) | {:.3} | {:+.4} | {:.1e}",
            s.rms_all,
            s.rms_grazing_glossy,
            s.median_cell_rms,
            s.max_cell_rms.0,
            s.max_cell_rms.1,
            s.max_cell_rms.2,
            s.max_rel_big,
            s.mean_signed,
            s.max_ci
        );
    }
    say!("wrote {}", out.display());
    Ok(())
}

/// Errors are printed alone, with their causes, whatever `RUST_BACKTRACE` says.
fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<()> {
    use clap::FromArgMatches;
    let cli = Cli::from_arg_matches(&command_line().get_matches()).unwrap_or_else(|e| e.exit());
    match cli.command {
        #[cfg(feature = "gui")]
        None => penumbra::app::run(Default::default()).map_err(|e| anyhow::anyhow!("{e}")),
        #[cfg(feature = "gui")]
        Some(Command::Gui(opts)) => penumbra::app::run(opts).map_err(|e| anyhow::anyhow!("{e}")),
        // Built without the workbench (`--no-default-features`): the command line only.
        #[cfg(not(feature = "gui"))]
        None => {
            command_line().print_help()?;
            Ok(())
        }
        Some(Command::Render(args)) => render(&args),
        Some(Command::Bench(args)) => bench(&args),
        Some(Command::Reference { render, samples }) => reference(&render, samples, render.seed),
        Some(Command::Compare {
            image,
            reference,
            stderr,
        }) => compare(&image, &reference, stderr.as_deref()),
        Some(Command::Stress {
            only: Some(index),
            seed,
            rays,
            ..
        }) => {
            let (case, analytic, estimate, sigma, violations) =
                penumbra::stress::run_one(seed, index, rays);
            say!("case {index}: {:?}, scale {:e}", case.kind, case.scale);
            say!("shading point {:?}", case.point);
            for o in &case.scene.objects {
                say!(
                    "{} ({} vertices): {:?}",
                    o.name,
                    o.mesh.positions.len(),
                    o.mesh.positions
                );
            }
            say!(
                "analytic {analytic}, ray cast {estimate} ± {sigma}; {violations} invariant \
                 violations"
            );
            Ok(())
        }
        Some(Command::Stress {
            cases,
            seed,
            rays,
            json,
            ..
        }) => {
            let last = std::sync::atomic::AtomicU64::new(0);
            let rep = penumbra::stress::run(cases, seed, rays, |done| {
                let step = (cases / 20).max(1);
                let prev = last.fetch_max(done / step, std::sync::atomic::Ordering::Relaxed);
                if done / step > prev {
                    eprintln!("  {done}/{cases}");
                }
            });
            say!("{}", serde_json::to_string_pretty(&rep)?);
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&rep)?)
                    .with_context(|| format!("{}", path.display()))?;
            }
            if rep.nan + rep.inf + rep.negative + rep.panics + rep.invariant_violations > 0 {
                bail!("stress found invalid results");
            }
            Ok(())
        }
        Some(Command::LtcError {
            tables,
            fit,
            out,
            grid,
            samples,
        }) => ltc_error(&tables, &fit, &out, grid, samples),
        Some(Command::LtcImportThree { js, out }) => {
            let text = std::fs::read_to_string(&js).with_context(|| format!("{}", js.display()))?;
            let table = penumbra::ltc::published::from_three_js(&text)
                .with_context(|| format!("{}", js.display()))?;
            table
                .save(&out)
                .with_context(|| format!("{}", out.display()))?;
            say!("wrote {}", out.display());
            Ok(())
        }
        Some(Command::FitLtc {
            out,
            size,
            objective,
            no_renorm,
            no_cosine_tail,
            rows,
            base,
            report,
        }) => {
            let start = std::time::Instant::now();
            let mut fo = penumbra::ltc::fit::FitOptions::default();
            if let Some(o) = objective {
                fo.objective = o;
            }
            fo.renormalize = !no_renorm;
            // The tail is fitted only with the polygon objectives (fit_cell ignores it otherwise).
            fo.cosine_tail = !no_cosine_tail;
            let table = match (rows, base) {
                (Some((first, last)), Some(base)) => {
                    let base = ltc_table(&base)?;
                    let n = base.size();
                    if last >= n || first > last {
                        bail!("--rows {first}-{last} outside the table's 0-{}", n - 1);
                    }
                    let alphas: Vec<f64> = (first..=last).map(|i| base.alpha_at(i)).collect();
                    let mut cosines: Vec<f64> = (0..n).map(|j| base.cos_theta_at(j)).collect();
                    cosines[0] = 1.0;
                    let cells = penumbra::ltc::fit::fit_grid(&alphas, &cosines, &fo, |_, _| {});
                    base.map_entries_indexed(|i, j, e| {
                        if (first..=last).contains(&i) {
                            cells[(i - first) * n + j].entry
                        } else {
                            e
                        }
                    })
                }
                _ => {
                    let (table, cells) =
                        penumbra::ltc::fit::fit_table_cells_with(size, &fo, |done, total| {
                            if done % size == 0 {
                                eprintln!("  {done}/{total}");
                            }
                        });
                    if let Some(path) = &report {
                        std::fs::write(path, penumbra::ltc::fit::report_tsv(&table, &cells))
                            .with_context(|| format!("{}", path.display()))?;
                    }
                    table
                }
            };
            table
                .save(&out)
                .with_context(|| format!("{}", out.display()))?;
            say!(
                "wrote {} in {:.1} s",
                out.display(),
                start.elapsed().as_secs_f64()
            );
            Ok(())
        }
        Some(Command::Probe {
            render,
            pixel,
            gh_steps,
            json,
        }) => probe(&render, pixel, gh_steps, &json),
        Some(Command::Cache { clear, trim, json }) => cache(clear, trim, json.as_deref()),
        Some(Command::Edit {
            scene,
            object,
            translate,
            rotate_y,
            pivot,
            out,
        }) => edit(&scene, &object, translate, rotate_y, pivot, &out),
        Some(Command::Scenes) => {
            for name in scene_file::embedded_scene_names() {
                say!("{name}");
            }
            Ok(())
        }
    }
}
