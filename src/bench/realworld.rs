//! `penumbra bench --suite realworld`: the scenes users load (exporter output, a scanned
//! mesh), each rendered with the analytic method, the per-triangle method and unshadowed, and
//! compared with the ray-cast reference (docs/benchmarks.md, "Real-world scenes").

use super::realworld_scenes::{ExportedScene, generated_scenes};
use crate::render::compare::{Comparison, compare};
use crate::render::image_io::{write_pfm, write_png};
use crate::render::request::RenderRequest;
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::Camera;
use crate::scene::scene_file::load_scene;
use crate::shading::Shortcuts;
use crate::stochastic::LightSampling;
use std::path::{Path, PathBuf};
use web_time::Instant;

/// What to run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RealWorldConfig {
    pub width: u32,
    pub height: u32,
    pub aa: u32,
    /// Samples per camera ray of the reference (`aa`² camera rays per pixel).
    pub reference_spp: u32,
    /// Deterministic methods are timed as the best of this many renders.
    pub repeats: u32,
    pub seed: u64,
    /// Run only the scenes with these names (all when empty).
    pub only: Vec<String>,
    /// How scenes are prepared (the tree cache): the caller's, not part of the report.
    #[serde(skip)]
    pub prepare: crate::shading::PrepareConfig,
}

/// One mesh of a scene and the path it took.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MeshRow {
    pub name: String,
    pub vertices: usize,
    pub faces: usize,
    pub light: bool,
    pub path: crate::shading::PathKind,
    pub path_text: String,
}

/// One method's render of a scene.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MethodRow {
    pub method: String,
    /// Best of `repeats` renders.
    pub seconds: f64,
    /// Against the reference, in units of its standard error.
    pub error: Comparison,
    /// How the light pieces of every camera ray ended (deterministic methods).
    #[serde(default)]
    pub shortcuts: Option<Shortcuts>,
    /// Light pieces whose visible polygon was not inside the light's (`shading::invariant`),
    /// over the last render: a bug wherever it is not zero.
    #[serde(default)]
    pub violations: u64,
    /// Pixel channels brighter than the unshadowed image of the same run (beyond 1e-9
    /// relative): a shadow that adds light.
    #[serde(default)]
    pub above_unshadowed: u64,
    /// Shading points where a path gave up for one exact there, over the last render.
    #[serde(default)]
    pub fallbacks: crate::render::FallbackTotals,
    /// The process's peak resident memory during the method's renders, in MB (Linux).
    #[serde(default)]
    pub peak_mb: Option<f64>,
}

/// One scene of the suite.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SceneRow {
    pub scene: String,
    pub description: String,
    /// How the coordinates were written (`%.6f`, `%.9g`, or the file's own for the bunny).
    pub format: String,
    /// Loading the files: OBJ parsing, repairs, triangulation of folded n-gons.
    pub load_seconds: f64,
    /// Preparing the scene: adjacency, classification, trees (read from the disk cache when
    /// it has them), BVH.
    pub prepare_seconds: f64,
    pub trees_built: u32,
    pub meshes: Vec<MeshRow>,
    pub warnings: Vec<String>,
    pub notes: Vec<String>,
    pub methods: Vec<MethodRow>,
    pub reference_seconds: f64,
}

impl SceneRow {
    pub(crate) fn seconds(&self, method: &str) -> Option<f64> {
        self.methods
            .iter()
            .find(|m| m.method == method)
            .map(|m| m.seconds)
    }
}

/// The whole report.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RealWorldReport {
    pub config: RealWorldConfig,
    pub threads: usize,
    pub scenes: Vec<SceneRow>,
}

/// Where the bunny scene lives: `assets/scenes/bunny.toml` under the working directory, else
/// under the source tree the binary was built from.
fn bunny_scene_path() -> Option<PathBuf> {
    source_path("assets/scenes/bunny.toml")
}

/// `rel` under the working directory, else under the source tree the binary was built from.
pub(crate) fn source_path(rel: &str) -> Option<PathBuf> {
    let rel = Path::new(rel);
    [
        rel.to_path_buf(),
        Path::new(env!("CARGO_MANIFEST_DIR")).join(rel),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// The scenes Blender built and wrote itself (`tests/data/blender`), each as OBJ and `.glb`.
pub(crate) const BLENDER_SCENES: [(&str, &str); 5] = [
    (
        "suzanne",
        "Blender's monkey, subdivided twice (7,872 quads, 7,686 not planar; open: 168 boundary \
         edges) above a floor under a tilted quad light",
    ),
    (
        "text",
        "An extruded text 'BOP8' converted to a mesh, limited dissolve: n-gon caps split at the \
         holes, non-planar sides, open (caps not joined to the sides)",
    ),
    (
        "penumbra_text",
        "The word 'penumbra' lying flat under a 1.6 m x 0.8 m quad light, converted to a mesh \
         with Blender's default limited dissolve: keyhole n-gon caps, open seams",
    ),
    (
        "primitives",
        "Blender's default primitives (cube, UV sphere, ico sphere, cylinder, cone, torus) under \
         a quad light and an emissive cylinder",
    ),
    (
        "torus_light",
        "A torus as a non-convex light above a cube and a UV sphere",
    ),
];

/// Writes an exported scene's OBJ, MTL and scene file into `dir`; returns the scene file.
pub(crate) fn write_exported(scene: &ExportedScene, dir: &Path) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join(format!("{}.obj", scene.name)), scene.obj())?;
    std::fs::write(dir.join(format!("{}.mtl", scene.name)), scene.mtl())?;
    let toml = dir.join(format!("{}.toml", scene.name));
    std::fs::write(&toml, scene.toml())?;
    Ok(toml)
}

/// Runs the suite, writing the generated scenes into `dir/scenes` and every image into
/// `dir/NAME_METHOD.pfm|png`. `progress` receives one line per step.
pub fn run_realworld(
    dir: &Path,
    config: &RealWorldConfig,
    mut progress: impl FnMut(&str),
    mut scene_done: impl FnMut(&RealWorldReport),
) -> crate::Result<RealWorldReport> {
    let mut inputs: Vec<(String, String, String, PathBuf)> = Vec::new();
    for s in generated_scenes() {
        let path = write_exported(&s, &dir.join("scenes"))
            .map_err(|e| format!("{}: {e}", dir.join("scenes").display()))?;
        inputs.push((
            s.name.into(),
            s.description.into(),
            s.format.describe(),
            path,
        ));
    }
    for (stem, what) in BLENDER_SCENES {
        for ext in ["toml", "glb"] {
            let rel = format!("tests/data/blender/{stem}.{ext}");
            match source_path(&rel) {
                Some(p) => inputs.push((
                    format!(
                        "blender_{stem}_{}",
                        if ext == "toml" { "obj" } else { "glb" }
                    ),
                    format!(
                        "{what}; written by Blender 5.0.1's own {} exporter \
                         (scripts/blender_scenes.py)",
                        if ext == "toml" { "OBJ" } else { "glTF" }
                    ),
                    if ext == "toml" {
                        "%.6f (Blender)".into()
                    } else {
                        "f32 (glTF)".into()
                    },
                    p,
                )),
                None => progress(&format!("{rel} not found: skipped")),
            }
        }
    }
    match bunny_scene_path() {
        Some(p) => inputs.push((
            "bunny".into(),
            "The Stanford bunny (assets/meshes/bunny.obj: 1,839 vertices, 3,674 triangles, closed) \
             on a floor under a quad light"
                .into(),
            "%.6g (as distributed)".into(),
            p,
        )),
        None => progress("assets/scenes/bunny.toml not found: the bunny scene is skipped"),
    }
    inputs.retain(|(name, ..)| config.only.is_empty() || config.only.contains(name));
    let mut rows = Vec::new();
    for (name, description, format, path) in inputs {
        progress(&format!("{name}: loading {}", path.display()));
        let t = Instant::now();
        let scene = load_scene(&path).map_err(|e| e.to_string())?;
        let load_seconds = t.elapsed().as_secs_f64();
        let settings = |method: RenderMethod, spp, seed| RenderSettings {
            width: config.width,
            height: config.height,
            aa: config.aa,
            method,
            spp,
            seed,
            light_sampling: LightSampling::SolidAngle,
            // Per-pixel counters of the deterministic methods: the shortcuts they took.
            collect_stats: method.analytic().is_some(),
            exact_u: false,
        };
        let t = Instant::now();
        // Sized for one render of the suite's camera rays, as `penumbra render` prepares.
        let ctx = RenderContext::for_render(
            &scene,
            &RenderRequest {
                settings: settings(RenderMethod::Analytic, 1, config.seed),
                prepare: config.prepare.clone(),
                ..RenderRequest::default()
            },
        );
        let prepare_seconds = t.elapsed().as_secs_f64();
        let camera: Camera = scene
            .camera
            .ok_or_else(|| format!("{}: no camera", path.display()))?;
        let meshes = ctx
            .prepared
            .objects
            .iter()
            .map(|o| MeshRow {
                name: o.name.clone(),
                vertices: o.poly.vertices.len(),
                faces: o.poly.face_count(),
                light: ctx
                    .prepared
                    .lights
                    .iter()
                    .any(|&(l, _)| ctx.prepared.objects[l as usize].object == o.object),
                path: o.kind(),
                path_text: o.kind().describe().into(),
            })
            .collect();
        progress(&format!(
            "{name}: reference, {} spp per camera ray",
            config.reference_spp
        ));
        let reference = ctx.render_full(
            &camera,
            &settings(
                RenderMethod::Reference,
                config.reference_spp,
                config.seed ^ 0x9e37_79b9_7f4a_7c15,
            ),
            None,
        )?;
        let stderr = reference
            .stderr
            .clone()
            .ok_or("the reference returned no standard error")?;
        save(dir, &name, "reference", &reference.image)?;
        save_pfm(dir, &format!("{name}_reference_stderr"), &stderr)?;
        let mut methods = Vec::new();
        let mut images = Vec::new();
        for method in [
            RenderMethod::Analytic,
            RenderMethod::PerTriangle,
            RenderMethod::Unshadowed,
        ] {
            progress(&format!("{name}: {}", method.name()));
            let mut best = f64::INFINITY;
            let mut image = Image::new(1, 1);
            let mut shortcuts = None;
            let mut violations = 0;
            let mut fallbacks = Default::default();
            super::memory::reset_peak();
            for _ in 0..config.repeats.max(1) {
                let out = ctx.render_full(&camera, &settings(method, 1, config.seed), None)?;
                best = best.min(out.stats.seconds);
                violations = out.stats.violations;
                fallbacks = out.stats.fallbacks;
                image = out.image;
                shortcuts = out.pixel_stats.map(|px| {
                    let mut sum = Shortcuts::default();
                    for p in &px {
                        sum.add(&p.shortcuts);
                    }
                    sum
                });
            }
            save(dir, &name, method.name(), &image)?;
            let error = compare(
                &image.to_rgb32(),
                &reference.image.to_rgb32(),
                Some(&stderr.to_rgb32()),
            );
            methods.push(MethodRow {
                method: method.name().into(),
                seconds: best,
                error,
                shortcuts,
                violations,
                above_unshadowed: 0,
                fallbacks,
                peak_mb: super::memory::peak_mb(),
            });
            images.push(image);
        }
        // The unshadowed image is the last: count what the shadowed ones add to it.
        if let Some(unshadowed) = images.last() {
            for (m, img) in methods.iter_mut().zip(&images) {
                m.above_unshadowed = img
                    .pixels
                    .iter()
                    .zip(&unshadowed.pixels)
                    .map(|(a, u)| {
                        (0..3)
                            .filter(|&c| a[c] > u[c] * (1.0 + 1e-9) + 1e-12)
                            .count() as u64
                    })
                    .sum();
            }
        }
        rows.push(SceneRow {
            scene: name,
            description,
            format,
            load_seconds,
            prepare_seconds,
            trees_built: ctx.prepared.trees_built,
            meshes,
            warnings: scene.warnings.clone(),
            notes: ctx.prepared.report.lines(),
            methods,
            reference_seconds: reference.stats.seconds,
        });
        scene_done(&RealWorldReport {
            config: config.clone(),
            threads: rayon::current_num_threads(),
            scenes: rows.clone(),
        });
    }
    Ok(RealWorldReport {
        config: config.clone(),
        threads: rayon::current_num_threads(),
        scenes: rows,
    })
}

fn save_pfm(dir: &Path, stem: &str, image: &Image) -> crate::Result<()> {
    let p = dir.join(format!("{stem}.pfm"));
    write_pfm(&p, image.width, image.height, &image.to_rgb32())
        .map_err(|e| crate::Error::file(p.display(), e))
}

fn save(dir: &Path, scene: &str, method: &str, image: &Image) -> crate::Result<()> {
    save_pfm(dir, &format!("{scene}_{method}"), image)?;
    let p = dir.join(format!("{scene}_{method}.png"));
    write_png(&p, image.width, image.height, &image.to_rgb32(), 0.0)
        .map_err(|e| crate::Error::from(format!("{e:#}")))
}

/// The report as the table of docs/benchmarks.md.
pub fn realworld_markdown(r: &RealWorldReport) -> String {
    use std::fmt::Write;
    let c = &r.config;
    let mut s = format!(
        "{}x{} pixels, --aa {}, {} threads; reference {} spp per camera ray. Times are the best \
         of {} renders; z is the error in units of the reference's standard error (rms z ≈ 1 \
         and mean z ≈ 0 when the difference is the reference's noise).\n\n",
        c.width, c.height, c.aa, r.threads, c.reference_spp, c.repeats
    );
    s.push_str(
        "| scene | written | analytic | per-triangle | unshadowed | analytic / unshadowed | \
         per-triangle / analytic | analytic rms z | mean z | within 3σ | prepare | \
         violations | above unshadowed |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for row in &r.scenes {
        let t = |m: &str| row.seconds(m).unwrap_or(f64::NAN);
        let a = row.methods.iter().find(|m| m.method == "analytic");
        let z = |f: fn(&Comparison) -> Option<f64>| {
            a.and_then(|m| f(&m.error))
                .map_or("–".into(), |v| format!("{v:.3}"))
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} s | {:.2} s | {:.3} s | {:.1}× | {:.2}× | {} | {} | {} | {:.2} s | {} | {} |",
            row.scene,
            row.format,
            t("analytic"),
            t("per-triangle"),
            t("unshadowed"),
            t("analytic") / t("unshadowed"),
            t("per-triangle") / t("analytic"),
            z(|e| e.rms_z),
            z(|e| e.mean_z),
            z(|e| e.within_3_sigma),
            row.prepare_seconds,
            // Both deterministic methods: analytic + per-triangle.
            row.methods
                .iter()
                .filter(|m| m.method != "unshadowed")
                .map(|m| m.violations)
                .sum::<u64>(),
            row.methods
                .iter()
                .filter(|m| m.method != "unshadowed")
                .map(|m| m.above_unshadowed)
                .sum::<u64>(),
        );
    }
    s.push_str(
        "\nHow the analytic method's light pieces ended (a light taken whole, or one face of a \
         light taken face by face; per camera ray, summed over the image), in % of all pieces:\n\n\
         | scene | pieces | light below horizon | clipped away | no occluder between | occluders \
         all disjoint | covered | set difference |\n|---|---|---|---|---|---|---|---|\n",
    );
    for row in &r.scenes {
        let Some(sc) = row
            .methods
            .iter()
            .find(|m| m.method == "analytic")
            .and_then(|m| m.shortcuts)
        else {
            continue;
        };
        let n = sc.total().max(1) as f64;
        let pc = |c: u32| format!("{:.1} %", 100.0 * c as f64 / n);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            row.scene,
            sc.total(),
            pc(sc.light_below_horizon),
            pc(sc.clipped_away),
            pc(sc.no_occluder),
            pc(sc.all_disjoint),
            pc(sc.covered),
            pc(sc.subtracted),
        );
    }
    s.push_str("\nThe path each mesh took:\n\n| scene | mesh | vertices | faces | path |\n|---|---|---|---|---|\n");
    for row in &r.scenes {
        for m in &row.meshes {
            let _ = writeln!(
                s,
                "| {} | {}{} | {} | {} | {} |",
                row.scene,
                m.name,
                if m.light { " (light)" } else { "" },
                m.vertices,
                m.faces,
                m.path_text
            );
        }
    }
    s
}
