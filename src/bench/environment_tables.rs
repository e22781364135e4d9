//! `penumbra bench --env SCENE`: the environment light's methods in the form of 002's tables.
//!
//! * **Table 1** (002 Table 1): per-pass times of `rt` at 128 rays without culling, with
//!   direction culling, and with direction + length culling; the exact method on the same
//!   passes; and, for many dynamic objects (002 Sect. 6), `rt` with its cones clustered.
//! * **Table 2** (002 Table 2): the ladder of 16…512 rays, filtered as published, with the
//!   error against the unfiltered 512-ray image and against a converged reference (Monte
//!   Carlo of the map with shadow rays); the exact method's row; and the time each `rt`
//!   variant needs to reach the exact method's error (log–log interpolation on the ladder).
//!
//! The map is the scene's, made band-limited (`sky-sh` for the embedded sky, the SH
//! reconstruction of a file's map) so that the errors measure the methods, not the
//! truncation to three bands that every method but the reference shares.

use crate::environment::prt::PrtReport;
use crate::environment::{EnvMethod, EnvironmentLight, EnvironmentMap};
use crate::render::compare::{Comparison, compare};
use crate::render::environment_passes::{
    Culling, EnvironmentSettings, EnvironmentStats, StaticTerm,
};
use crate::render::request::RenderRequest;
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::{Camera, Scene};
use std::fmt::Write as _;
use std::sync::Arc;

/// One timed render of the environment term.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct EnvBenchRow {
    pub label: String,
    pub method: EnvMethod,
    pub spp: u32,
    pub culling: Culling,
    pub filter: bool,
    pub max_cones: Option<usize>,
    /// Wall time of the whole render (best of the repeats), and its passes.
    pub seconds: f64,
    pub passes: EnvironmentStats,
    /// Error against the unfiltered 512-ray `rt` image and against the reference.
    pub vs_rt512: Option<Comparison>,
    pub vs_reference: Option<Comparison>,
    /// RMSE against the reference with the reference's own noise taken out:
    /// √max(0, mean(d²) − mean(σ²)), σ its per-pixel standard error.
    pub vs_reference_corrected: Option<f64>,
}

/// The report of one scene.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnvBenchReport {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub aa: u32,
    pub reference_spp: u32,
    pub reference_seconds: f64,
    /// Seconds to prepare the scene (trees of precomputed silhouettes, BVH).
    pub prepare_seconds: f64,
    pub table1: Vec<EnvBenchRow>,
    pub table2: Vec<EnvBenchRow>,
    /// For each `rt` variant of Table 2's ladder (filtered, unfiltered): the seconds it
    /// needs to reach the exact method's RMSE against the reference (`None` when the ladder
    /// does not reach it), by log–log interpolation.
    pub time_to_analytic_error: Vec<(String, Option<f64>)>,
    /// The precomputed transfer of the static surfaces the ray methods read E_static from
    /// (002 Eq. 6): computed (or read from the cache) once, before the first `rt` row.
    #[serde(default)]
    pub prt: Option<PrtReport>,
}

/// What the bench runs.
#[derive(Clone, Debug)]
pub struct EnvBenchOptions {
    pub width: u32,
    pub height: u32,
    pub aa: u32,
    pub reference_spp: u32,
    pub ladder: Vec<u32>,
    pub repeats: u32,
    pub seed: u64,
    /// How the scene is prepared (the tree cache).
    pub prepare: crate::shading::PrepareConfig,
}

/// Runs Tables 1 and 2 on `scene` (its camera: `camera`). `log` receives progress lines.
pub fn run_environment_bench(
    name: &str,
    scene: &Scene,
    camera: &Camera,
    opts: &EnvBenchOptions,
    mut log: impl FnMut(&str),
) -> crate::Result<EnvBenchReport> {
    let spec = scene
        .environment
        .clone()
        .ok_or_else(|| format!("{name}: the scene has no [environment]"))?;
    let full = EnvironmentLight::load(&spec).map_err(|e| e.to_string())?;
    let (w, h) = (full.map.width(), full.map.height());
    let light = Arc::new(EnvironmentLight::from_map(
        EnvironmentMap::from_sh(&full.sh, w, h),
        format!("{} (3-band)", full.label),
    ));
    let settings = RenderSettings {
        width: opts.width,
        height: opts.height,
        aa: opts.aa,
        method: RenderMethod::Unshadowed,
        ..RenderSettings::default()
    };
    // Prepared as `penumbra render` prepares this image (the scene has an environment: checked
    // above).
    let t = web_time::Instant::now();
    let request = RenderRequest {
        settings,
        prepare: opts.prepare.clone(),
        ..RenderRequest::default()
    };
    let mut ctx = RenderContext::for_render(scene, &request);
    let prepare_seconds = t.elapsed().as_secs_f64();
    let stderr: std::cell::RefCell<Option<Image>> = std::cell::RefCell::new(None);
    let prt: std::cell::Cell<Option<PrtReport>> = std::cell::Cell::new(None);
    let mut run = |label: &str,
                   env: EnvironmentSettings,
                   repeats: u32|
     -> crate::Result<(EnvBenchRow, Image)> {
        ctx.set_environment(light.clone(), env);
        if prt.get().is_none() {
            prt.set(ctx.environment.as_ref().and_then(|e| e.transfer_report));
        }
        let mut best: Option<(f64, EnvironmentStats, Image)> = None;
        for _ in 0..repeats.max(1) {
            let out = ctx.render_full(camera, &settings, None)?;
            let e = out.environment.ok_or("no environment pass")?;
            if best.as_ref().is_none_or(|b| out.stats.seconds < b.0) {
                // The reference's standard error travels in `variance` of its row's image.
                *stderr.borrow_mut() = out.stderr.clone();
                best = Some((out.stats.seconds, e.stats, out.image));
            }
        }
        let (seconds, passes, image) = best.unwrap_or_default();
        log(&format!("{label}: {seconds:.3} s"));
        Ok((
            EnvBenchRow {
                label: label.into(),
                method: env.method,
                spp: env.spp,
                culling: env.culling,
                filter: env.filter,
                max_cones: env.max_cones,
                seconds,
                passes,
                vs_rt512: None,
                vs_reference: None,
                vs_reference_corrected: None,
            },
            image,
        ))
    };

    // The converged reference and the unfiltered 512-ray image.
    let (ref_row, reference) = run(
        "reference",
        EnvironmentSettings::new(EnvMethod::Reference, opts.reference_spp, opts.seed + 1000),
        1,
    )?;
    let ref_stderr = stderr.borrow_mut().take();
    let mut rt512 = EnvironmentSettings::new(EnvMethod::Rt, 512, opts.seed);
    rt512.filter = false;
    let (_, rt512_img) = run("rt 512 unfiltered", rt512, 1)?;
    let f32s = |img: &Image| img.to_rgb32();
    let ref_stderr = ref_stderr.ok_or("the reference has no standard error")?;
    let (ref32, rt32) = (f32s(&reference), f32s(&rt512_img));
    let noise2 = ref_stderr
        .pixels
        .iter()
        .map(|p| p.length_squared())
        .sum::<f64>()
        / (3 * ref_stderr.pixels.len().max(1)) as f64;
    let errors = |row: &mut EnvBenchRow, img: &Image| {
        let a = f32s(img);
        row.vs_rt512 = Some(compare(&a, &rt32, None));
        let c = compare(&a, &ref32, None);
        row.vs_reference_corrected = Some((c.rmse * c.rmse - noise2).max(0.0).sqrt());
        row.vs_reference = Some(c);
    };

    let mut report = EnvBenchReport {
        scene: name.into(),
        width: opts.width,
        height: opts.height,
        aa: opts.aa,
        reference_spp: opts.reference_spp,
        reference_seconds: ref_row.seconds,
        prepare_seconds,
        ..Default::default()
    };

    // Table 1.
    for (label, culling) in [
        ("rt 128, no culling", Culling::None),
        ("rt 128, direction culling", Culling::Direction),
        (
            "rt 128, direction + length culling",
            Culling::DirectionAndLength,
        ),
    ] {
        let mut env = EnvironmentSettings::new(EnvMethod::Rt, 128, opts.seed);
        env.culling = culling;
        let (mut row, img) = run(label, env, opts.repeats)?;
        errors(&mut row, &img);
        report.table1.push(row);
    }
    report.prt = prt.get();
    if report.prt.is_some() {
        // What the precomputed transfer buys: the same rays, E_static exact at every point.
        let mut env = EnvironmentSettings::new(EnvMethod::Rt, 128, opts.seed);
        env.static_term = StaticTerm::Exact;
        let (mut row, img) = run(
            "rt 128, direction + length culling, E_static exact (no PRT)",
            env,
            opts.repeats,
        )?;
        errors(&mut row, &img);
        report.table1.push(row);
    }
    let dynamic = scene
        .objects
        .iter()
        .filter(|o| o.flags.occluder && !o.flags.is_static)
        .count();
    if dynamic > 2 {
        for k in [1usize, 2, 4] {
            let mut env = EnvironmentSettings::new(EnvMethod::Rt, 128, opts.seed);
            env.max_cones = Some(k);
            let (mut row, img) = run(
                &format!("rt 128, direction + length culling, ≤ {k} clustered cones"),
                env,
                opts.repeats,
            )?;
            errors(&mut row, &img);
            report.table1.push(row);
        }
    }
    let (mut analytic_row, analytic_img) = run(
        "analytic",
        EnvironmentSettings::new(EnvMethod::Analytic, 1, opts.seed),
        opts.repeats,
    )?;
    errors(&mut analytic_row, &analytic_img);
    report.table1.push(analytic_row.clone());

    // Table 2.
    for filter in [true, false] {
        for &spp in &opts.ladder {
            let mut env = EnvironmentSettings::new(EnvMethod::Rt, spp, opts.seed);
            env.filter = filter;
            let label = format!("rt {spp}{}", if filter { "" } else { " unfiltered" });
            let (mut row, img) = run(&label, env, opts.repeats)?;
            errors(&mut row, &img);
            report.table2.push(row);
        }
    }
    for (method, label) in [
        (EnvMethod::Rtao, "rtao 128"),
        (EnvMethod::Unshadowed, "unshadowed"),
    ] {
        let (mut row, img) = run(
            label,
            EnvironmentSettings::new(method, 128, opts.seed),
            opts.repeats,
        )?;
        errors(&mut row, &img);
        report.table2.push(row);
    }
    report.table2.push(analytic_row.clone());

    // Time for each rt variant to reach the exact method's error.
    let target = analytic_row.vs_reference_corrected.unwrap_or(f64::NAN);
    for filter in [true, false] {
        let pts: Vec<(f64, f64)> = report
            .table2
            .iter()
            .filter(|r| r.method == EnvMethod::Rt && r.filter == filter)
            .filter_map(|r| r.vs_reference_corrected.map(|c| (r.seconds, c)))
            .collect();
        let label = if filter {
            "rt (filtered)"
        } else {
            "rt (unfiltered)"
        };
        report
            .time_to_analytic_error
            .push((label.into(), time_to_reach(&pts, target)));
    }
    Ok(report)
}

/// The time at which the error falls to `target`, interpolating log(error) against
/// log(time) between the two ladder points that bracket it; `None` if no point reaches it.
fn time_to_reach(points: &[(f64, f64)], target: f64) -> Option<f64> {
    if target.is_nan() || target <= 0.0 {
        return None;
    }
    if let Some(first) = points.first()
        && first.1 <= target
    {
        return Some(first.0);
    }
    for pair in points.windows(2) {
        let ((t0, e0), (t1, e1)) = (pair[0], pair[1]);
        if e1 <= target && e0 > target && t0 > 0.0 && t1 > 0.0 && e1 > 0.0 {
            let f = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return Some((t0.ln() + f * (t1.ln() - t0.ln())).exp());
        }
    }
    None
}

/// The report as Markdown tables (what `docs/benchmarks.md` quotes).
pub fn environment_markdown(r: &EnvBenchReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "### `{}`, {}×{} `--aa {}` (prepare {:.2} s; reference {} rays per camera ray, {:.1} s)\n",
        r.scene, r.width, r.height, r.aa, r.prepare_seconds, r.reference_spp, r.reference_seconds
    );
    if let Some(p) = &r.prt {
        let _ = writeln!(
            s,
            "Precomputed transfer of the static surfaces (PRT, 002 Eq. 6): {p} (once per static geometry; the `rt` rows read E_static from it)\n"
        );
    }
    let _ = writeln!(
        s,
        "Table 1: seconds per pass (G-buffer, occlusion, filter, composition)\n\n| variant | G-buffer | occlusion | filter | composition | total | rays traced | speed-up of occlusion |\n|---|---|---|---|---|---|---|---|"
    );
    let base = r
        .table1
        .first()
        .map_or(f64::NAN, |b| b.passes.occlusion_seconds);
    for row in &r.table1 {
        let p = &row.passes;
        let traced = if p.rays_total > 0 {
            format!(
                "{:.1} %",
                100.0 * p.rays_traced as f64 / p.rays_total as f64
            )
        } else {
            "–".into()
        };
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {:.2}× |",
            row.label,
            p.gbuffer_seconds,
            p.occlusion_seconds,
            p.filter_seconds,
            p.composition_seconds,
            row.seconds,
            traced,
            base / p.occlusion_seconds.max(1e-12)
        );
    }
    let _ = writeln!(
        s,
        "\nTable 2: error against the unfiltered 512-ray image and against the reference\n\n| variant | seconds | RMSE vs rt 512 | RMSE vs reference | the same, reference noise removed |\n|---|---|---|---|---|"
    );
    for row in &r.table2 {
        let f = |c: Option<Comparison>| c.map_or("–".into(), |c| format!("{:.3e}", c.rmse));
        let _ = writeln!(
            s,
            "| {} | {:.3} | {} | {} | {} |",
            row.label,
            row.seconds,
            f(row.vs_rt512),
            f(row.vs_reference),
            row.vs_reference_corrected
                .map_or("–".into(), |c| format!("{c:.3e}"))
        );
    }
    let _ = writeln!(
        s,
        "\nTime to reach the analytic method's error against the reference (its noise removed):\n"
    );
    for (label, t) in &r.time_to_analytic_error {
        let _ = writeln!(
            s,
            "- {label}: {}",
            t.map_or("not reached within the ladder".into(), |t| format!(
                "{t:.3} s"
            ))
        );
    }
    s
}
