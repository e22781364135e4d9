//! `penumbra bench --suite speed`: the speed guard (docs/speed.md).
//!
//! A machine's speed is not a constant: CI machines of one kind differ by 20 %, and one
//! machine's speed drifts within a run. So the guard compares no time with a time measured
//! elsewhere. It measures, in one run and side by side, each scene's analytic render, its
//! unshadowed render and a fixed calibration workload (a loop of LTC edge integrals, the
//! innermost operation of every analytic method), and keeps three ratios per scene:
//!
//! * analytic / unshadowed: the shadow's cost over the stages both share (camera rays, BVH,
//!   lights' LTC, accumulation);
//! * analytic / calibration and unshadowed / calibration: the stages the first ratio is blind
//!   to, against work whose speed follows the machine's.
//!
//! Each ratio is the median over `runs` rounds, every round measuring the three workloads one
//! after another. [`run_speed`] compares the medians with a baseline committed in the repository
//! (`tests/data/speed_baseline.json`) and reports every workload whose cost grew by more than
//! the baseline's tolerance against its yardsticks (`regressions`). A scene that crosses it
//! is measured again after the others and fails only when the second measurement crosses it
//! too, so that a few noisy seconds of a shared machine are not a failure, while a real
//! slowdown (which every measurement sees) is.

use crate::ltc::edge_integral::form_factor;
use crate::render::request::RenderRequest;
use crate::render::{RenderContext, RenderMethod, RenderSettings};
use crate::scene::Scene;
use crate::scene::scene_file::{embedded_scene_names, load_embedded, load_scene};
use crate::stochastic::LightSampling;
use glam::DVec3;
use rayon::prelude::*;
use std::path::PathBuf;
use web_time::Instant;

/// What the suite measures, and how.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeedConfig {
    pub width: u32,
    pub height: u32,
    pub aa: u32,
    /// Rounds per scene; each ratio is the median over them.
    pub runs: u32,
    /// Worker threads of the suite's own pool (renders and calibration alike), so that the
    /// ratios do not depend on how many cores the machine has.
    pub threads: usize,
    /// A workload shorter than this is repeated until it has taken this long, and its time is
    /// the mean per repetition: timer and thread start-up stay below 1 % of what is measured.
    pub min_seconds: f64,
    /// How scenes are prepared (the tree cache): the caller's, not part of the report.
    #[serde(skip)]
    pub prepare: crate::shading::PrepareConfig,
}

impl Default for SpeedConfig {
    fn default() -> Self {
        Self {
            width: 256,
            height: 256,
            aa: 2,
            runs: 5,
            threads: 2,
            min_seconds: 0.2,
            prepare: Default::default(),
        }
    }
}

/// Where a scene of the suite comes from.
#[derive(Clone, Debug)]
pub enum SpeedScene {
    Embedded(&'static str),
    File(PathBuf),
}

/// The suite's scenes, by name: every embedded scene (the `cube` scene among them, the
/// plainest shadow there is), every file of `tests/data/blender` as OBJ and as glTF, and the
/// bunny. Files not found beside the working directory or the source tree are left out.
pub(crate) fn speed_scenes() -> Vec<(String, SpeedScene)> {
    let mut scenes: Vec<(String, SpeedScene)> = embedded_scene_names()
        .iter()
        .map(|&n| (n.to_string(), SpeedScene::Embedded(n)))
        .collect();
    for (stem, _) in super::realworld::BLENDER_SCENES {
        for (ext, kind) in [("toml", "obj"), ("glb", "glb")] {
            let rel = format!("tests/data/blender/{stem}.{ext}");
            if let Some(p) = super::realworld::source_path(&rel) {
                scenes.push((format!("blender_{stem}_{kind}"), SpeedScene::File(p)));
            }
        }
    }
    if let Some(p) = super::realworld::source_path("assets/scenes/bunny.toml") {
        scenes.push(("bunny".into(), SpeedScene::File(p)));
    }
    scenes
}

/// One scene's ratios: medians over the rounds.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeedRatios {
    pub analytic_to_unshadowed: f64,
    pub analytic_to_calibration: f64,
    pub unshadowed_to_calibration: f64,
}

impl SpeedRatios {
    /// The three ratios with their names, in the report's order.
    pub(crate) fn named(&self) -> [(&'static str, f64); 3] {
        [
            ("analytic/unshadowed", self.analytic_to_unshadowed),
            ("analytic/calibration", self.analytic_to_calibration),
            ("unshadowed/calibration", self.unshadowed_to_calibration),
        ]
    }
}

/// One scene of the report.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SpeedRow {
    pub scene: String,
    pub ratios: SpeedRatios,
    /// Median seconds per render and per calibration (for reading, not for the guard).
    pub analytic_seconds: f64,
    pub unshadowed_seconds: f64,
    pub calibration_seconds: f64,
    /// Invariant violations of the analytic renders (a bug wherever not 0).
    pub violations: u64,
    /// The process's peak resident memory over the scene's renders, in MB (Linux).
    pub peak_mb: Option<f64>,
}

/// What `penumbra bench --suite speed` writes (`speed.json`).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SpeedReport {
    pub config: SpeedConfig,
    pub rows: Vec<SpeedRow>,
}

/// The committed reference the guard compares with. Updating it is a deliberate commit whose
/// `why` says what changed.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SpeedBaseline {
    pub why: String,
    /// A ratio may grow by this fraction before the guard fails (0.10: 10 %).
    pub tolerance: f64,
    pub config: SpeedConfig,
    pub scenes: Vec<BaselineRow>,
}

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BaselineRow {
    pub scene: String,
    pub ratios: SpeedRatios,
}

impl SpeedBaseline {
    /// The baseline that `report` would be, with the reason for the update.
    pub fn from_report(report: &SpeedReport, tolerance: f64, why: &str) -> Self {
        Self {
            why: why.into(),
            tolerance,
            config: report.config.clone(),
            scenes: report
                .rows
                .iter()
                .map(|r| BaselineRow {
                    scene: r.scene.clone(),
                    ratios: r.ratios.clone(),
                })
                .collect(),
        }
    }

    pub(crate) fn ratios(&self, scene: &str) -> Option<&SpeedRatios> {
        self.scenes
            .iter()
            .find(|r| r.scene == scene)
            .map(|r| &r.ratios)
    }
}

/// A ratio that grew past the tolerance.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Regression {
    pub scene: String,
    pub ratio: String,
    pub baseline: f64,
    pub measured: f64,
}

impl Regression {
    /// `measured / baseline − 1`.
    pub(crate) fn growth(&self) -> f64 {
        self.measured / self.baseline - 1.0
    }
}

impl std::fmt::Display for Regression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} {:.4} against the baseline's {:.4} (+{:.1} %)",
            self.scene,
            self.ratio,
            self.measured,
            self.baseline,
            100.0 * self.growth()
        )
    }
}

/// The workloads of `measured` whose cost grew by more than `tolerance` over `baseline`'s,
/// as the ratios that show it:
///
/// * the analytic render, when it grew against **both** of its yardsticks: analytic/unshadowed
///   and analytic/calibration each past the tolerance. A ratio also grows when its
///   denominator shrinks: an unshadowed render that runs faster in one measurement than in
///   the baseline's (a short, memory-bound render moved by up to 20 % here with the state of
///   its process, docs/speed.md) lifts analytic/unshadowed with nothing slower, and the
///   calibration tells the two apart;
/// * the unshadowed render, when unshadowed/calibration grew past the tolerance (the shared
///   stages: camera rays, BVH, the light's LTC, accumulation, to which analytic/unshadowed is
///   blind).
pub(crate) fn regressions(
    scene: &str,
    measured: &SpeedRatios,
    baseline: &SpeedRatios,
    tolerance: f64,
) -> Vec<Regression> {
    let [au, ac, uc] = measured.named();
    let [bau, bac, buc] = baseline.named();
    let grew = |(_, m): (&str, f64), (_, b): (&str, f64)| m > b * (1.0 + tolerance);
    let regression = |(name, m): (&str, f64), (_, b): (&str, f64)| Regression {
        scene: scene.into(),
        ratio: name.into(),
        baseline: b,
        measured: m,
    };
    let mut out = Vec::new();
    if grew(au, bau) && grew(ac, bac) {
        out.push(regression(au, bau));
        out.push(regression(ac, bac));
    }
    if grew(uc, buc) {
        out.push(regression(uc, buc));
    }
    out
}

/// The median of `v` (the mean of the middle two for an even count); NaN when empty.
pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

/// Quadrilaterals in the upper hemisphere, the same on every machine: a fixed lattice of
/// centres and sizes (no random numbers, so the workload never changes).
fn calibration_quads() -> Vec<[DVec3; 4]> {
    let mut quads = Vec::with_capacity(1024);
    for i in 0..32 {
        for j in 0..32 {
            let (u, v) = ((i as f64 + 0.5) / 32.0, (j as f64 + 0.5) / 32.0);
            let centre = DVec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, 0.3 + u * v);
            let h = 0.05 + 0.3 * ((i * 7 + j * 3) % 11) as f64 / 11.0;
            let (a, b) = (DVec3::X * h, DVec3::Y * h * (0.5 + v));
            quads.push(
                [
                    centre - a - b,
                    centre + a - b,
                    centre + a + b,
                    centre - a + b,
                ]
                .map(|p| p.normalize()),
            );
        }
    }
    quads
}

/// The calibration workload: `passes` × 1024 quadrilaterals' LTC form factors (4 edge
/// integrals each), split over the current rayon pool as a render is. Returns its sum, which
/// the caller keeps so that nothing is optimised away.
pub(crate) fn calibration_work(quads: &[[DVec3; 4]], passes: u32) -> f64 {
    (0..passes)
        .into_par_iter()
        .map(|pass| {
            let tilt = 1.0 + 1e-3 * pass as f64;
            quads
                .iter()
                .map(|q| {
                    let q = q.map(|p| DVec3::new(p.x * tilt, p.y, p.z));
                    form_factor([&q[..]])
                })
                .sum::<f64>()
        })
        .sum()
}

/// Seconds per call of `work`, repeated until `min_seconds` have passed.
fn timed(min_seconds: f64, mut work: impl FnMut() -> crate::Result<f64>) -> crate::Result<f64> {
    let start = Instant::now();
    let mut calls = 0u32;
    let mut sink = 0.0;
    loop {
        sink += work()?;
        calls += 1;
        let spent = start.elapsed().as_secs_f64();
        if spent >= min_seconds {
            std::hint::black_box(sink);
            return Ok(spent / calls as f64);
        }
    }
}

/// Measures one scene: `config.runs` rounds of calibration, unshadowed and analytic.
pub(crate) fn measure_scene(
    scene: &Scene,
    name: &str,
    config: &SpeedConfig,
) -> crate::Result<SpeedRow> {
    let camera = scene.camera.ok_or_else(|| format!("{name}: no camera"))?;
    let settings = |method| RenderSettings {
        width: config.width,
        height: config.height,
        aa: config.aa,
        method,
        spp: 1,
        seed: 1,
        light_sampling: LightSampling::SolidAngle,
        collect_stats: false,
        exact_u: false,
    };
    let request = RenderRequest {
        settings: settings(RenderMethod::Analytic),
        prepare: config.prepare.clone(),
        ..RenderRequest::default()
    };
    let ctx = RenderContext::for_render(scene, &request);
    let quads = calibration_quads();
    let (analytic, unshadowed) = (
        settings(RenderMethod::Analytic),
        settings(RenderMethod::Unshadowed),
    );
    let mut violations = 0;
    let render = |s: &RenderSettings, violations: &mut u64| -> crate::Result<f64> {
        let out = ctx.render_full(&camera, s, None)?;
        *violations = (*violations).max(out.stats.violations);
        Ok(out.stats.seconds)
    };
    super::memory::reset_peak();
    let (mut a, mut u, mut c) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..config.runs.max(1) {
        c.push(timed(config.min_seconds, || {
            Ok(calibration_work(&quads, 512))
        })?);
        u.push(timed(config.min_seconds, || {
            render(&unshadowed, &mut 0).map(|_| 0.0)
        })?);
        a.push(timed(config.min_seconds, || {
            render(&analytic, &mut violations).map(|_| 0.0)
        })?);
    }
    let per_round = |x: &[f64], y: &[f64]| -> f64 {
        median(&x.iter().zip(y).map(|(x, y)| x / y).collect::<Vec<_>>())
    };
    Ok(SpeedRow {
        scene: name.into(),
        ratios: SpeedRatios {
            analytic_to_unshadowed: per_round(&a, &u),
            analytic_to_calibration: per_round(&a, &c),
            unshadowed_to_calibration: per_round(&u, &c),
        },
        analytic_seconds: median(&a),
        unshadowed_seconds: median(&u),
        calibration_seconds: median(&c),
        violations,
        peak_mb: super::memory::peak_mb(),
    })
}

/// Loads a scene of the suite.
pub fn load(source: &SpeedScene) -> crate::Result<Scene> {
    match source {
        SpeedScene::Embedded(n) => load_embedded(n),
        SpeedScene::File(p) => {
            load_scene(p).map_err(|e| crate::Error::from(format!("{}: {e}", p.display())))
        }
    }
}

/// The outcome of a guarded run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct GuardOutcome {
    pub report: SpeedReport,
    /// Ratios past the tolerance twice in a row.
    pub regressions: Vec<Regression>,
    /// Scenes of the baseline the run did not measure, and measured scenes it lacks.
    pub unmatched: Vec<String>,
}

/// Measures one scene of the suite in this process, on a pool of `config.threads` threads.
pub fn measure_named(name: &str, config: &SpeedConfig) -> crate::Result<SpeedRow> {
    let (_, source) = speed_scenes()
        .into_iter()
        .find(|(n, _)| n == name)
        .ok_or_else(|| format!("{name}: not a scene of the speed suite"))?;
    let scene = load(&source)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| measure_scene(&scene, name, config))
}

/// Runs the suite with `config`, each scene measured by `measure` (by name): the command line
/// measures each in a process of its own, so that no scene runs in the heap and page state
/// the scenes before it left (docs/speed.md, "The check"); [`measure_named`] measures in this
/// process. With a baseline, a scene whose ratios grew past its tolerance is measured once
/// more after the others, and only ratios past it both times are regressions. `only` keeps
/// the scenes of those names (all when empty).
pub fn run_speed(
    config: &SpeedConfig,
    baseline: Option<&SpeedBaseline>,
    only: &[String],
    mut progress: impl FnMut(&str),
    mut measure: impl FnMut(&str) -> crate::Result<SpeedRow>,
) -> crate::Result<GuardOutcome> {
    let mut scenes = speed_scenes();
    scenes.retain(|(n, _)| only.is_empty() || only.contains(n));
    let mut rows: Vec<SpeedRow> = Vec::new();
    let mut unmatched = Vec::new();
    // Scenes past the tolerance, with what they showed, measured again after the others: a
    // neighbour on a shared machine that slows a few seconds of the run moves one measurement,
    // not two minutes apart.
    let mut suspects: Vec<(usize, Vec<Regression>)> = Vec::new();
    for (name, _) in &scenes {
        let row = measure(name)?;
        progress(&row_line(&row));
        if let Some(base) = baseline {
            match base.ratios(name) {
                None => unmatched.push(format!("{name}: not in the baseline")),
                Some(want) => {
                    let first = regressions(name, &row.ratios, want, base.tolerance);
                    for r in &first {
                        progress(&format!("{r}; {name} will be measured again"));
                    }
                    if !first.is_empty() {
                        suspects.push((rows.len(), first));
                    }
                }
            }
        }
        rows.push(row);
    }
    let mut regressed = Vec::new();
    if let Some(base) = baseline {
        for (i, first) in suspects {
            let name = rows[i].scene.clone();
            let name = name.as_str();
            let again = measure(name)?;
            progress(&format!("again: {}", row_line(&again)));
            let want = base.ratios(name).ok_or("a suspect left the baseline")?;
            // A ratio fails when both measurements crossed; its report is the smaller of the
            // two.
            for r in regressions(name, &again.ratios, want, base.tolerance) {
                if let Some(f) = first.iter().find(|f| f.ratio == r.ratio) {
                    regressed.push(if f.measured < r.measured {
                        f.clone()
                    } else {
                        r
                    });
                }
            }
            rows[i] = again;
        }
    }
    if let Some(base) = baseline {
        for b in &base.scenes {
            let wanted = only.is_empty() || only.contains(&b.scene);
            if wanted && !rows.iter().any(|r| r.scene == b.scene) {
                unmatched.push(format!("{}: in the baseline, not measured", b.scene));
            }
        }
    }
    Ok(GuardOutcome {
        report: SpeedReport {
            config: config.clone(),
            rows,
        },
        regressions: regressed,
        unmatched,
    })
}

/// One line per scene, as the progress and the table give it.
pub(crate) fn row_line(r: &SpeedRow) -> String {
    format!(
        "{}: analytic/unshadowed {:.3}, analytic/calibration {:.3}, unshadowed/calibration {:.3} \
         (analytic {:.4} s, unshadowed {:.4} s, calibration {:.4} s; {} violations{})",
        r.scene,
        r.ratios.analytic_to_unshadowed,
        r.ratios.analytic_to_calibration,
        r.ratios.unshadowed_to_calibration,
        r.analytic_seconds,
        r.unshadowed_seconds,
        r.calibration_seconds,
        r.violations,
        r.peak_mb
            .map_or(String::new(), |m| format!(", peak {m:.0} MB"))
    )
}

/// The report as a Markdown table, with the baseline's ratios beside the measured ones.
pub fn speed_markdown(report: &SpeedReport, baseline: Option<&SpeedBaseline>) -> String {
    use std::fmt::Write;
    let c = &report.config;
    let mut md = format!(
        "Speed guard: {}×{} `--aa {}`, {} threads, median of {} rounds\n\n\
         | scene | analytic/unshadowed | analytic/calibration | unshadowed/calibration | \
         analytic | unshadowed | calibration | violations | peak memory |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        c.width, c.height, c.aa, c.threads, c.runs
    );
    for r in &report.rows {
        let base = baseline.and_then(|b| b.ratios(&r.scene));
        let cell = |i: usize| {
            let m = r.ratios.named()[i].1;
            match base {
                Some(b) => {
                    let b = b.named()[i].1;
                    format!("{m:.3} ({:+.1} %)", 100.0 * (m / b - 1.0))
                }
                None => format!("{m:.3}"),
            }
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.4} s | {:.4} s | {:.4} s | {} | {} |",
            r.scene,
            cell(0),
            cell(1),
            cell(2),
            r.analytic_seconds,
            r.unshadowed_seconds,
            r.calibration_seconds,
            r.violations,
            r.peak_mb.map_or("n/a".into(), |m| format!("{m:.0} MB"))
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ratios(a: f64, b: f64, c: f64) -> SpeedRatios {
        SpeedRatios {
            analytic_to_unshadowed: a,
            analytic_to_calibration: b,
            unshadowed_to_calibration: c,
        }
    }

    #[test]
    fn a_ratio_past_the_tolerance_is_a_regression_and_one_within_is_not() {
        let base = ratios(10.0, 4.0, 0.4);
        let names =
            |r: Vec<Regression>| -> Vec<String> { r.into_iter().map(|r| r.ratio).collect() };
        // Within 10 %: nothing.
        assert!(regressions("s", &ratios(10.99, 4.39, 0.439), &base, 0.10).is_empty());
        // The analytic render slower against both yardsticks.
        assert_eq!(
            names(regressions("s", &ratios(11.5, 4.6, 0.4), &base, 0.10)),
            ["analytic/unshadowed", "analytic/calibration"]
        );
        // The unshadowed render faster, the analytic one not slower: not a regression.
        assert!(regressions("s", &ratios(12.0, 4.0, 0.333), &base, 0.10).is_empty());
        // The shared stages slower: unshadowed/calibration (and analytic/calibration, which
        // analytic/unshadowed does not confirm).
        let r = regressions("s", &ratios(10.0, 5.0, 0.5), &base, 0.10);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].ratio, "unshadowed/calibration");
        assert!((r[0].growth() - 0.25).abs() < 1e-12);
    }

    #[test]
    fn the_median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn the_calibration_is_the_same_work_on_any_pool() {
        // The workload's result is fixed by its inputs: one thread or two, the same sum
        // (each pass is summed on its own, then the passes in a fixed tree order).
        let quads = calibration_quads();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| calibration_work(&quads, 8));
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| calibration_work(&quads, 8));
        assert!(one > 0.0 && (one - two).abs() <= 1e-12 * one, "{one} {two}");
    }
}
