//! The driver of `penumbra bench`: a converged reference, then every method at a ladder of
//! budgets, each render timed whole (for the ratio methods: U, the samples and the denoiser,
//! as 000 Sect. 5 counts them) and compared with the reference.

use super::table::{BenchReport, BenchRow, ReferenceInfo};
use crate::render::compare::compare;
use crate::render::request::RenderRequest;
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings, RenderStats};
use crate::scene::Camera;
use crate::stochastic::LightSampling;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a cancelled run returns (the command line's Ctrl-C, Python's KeyboardInterrupt).
pub(crate) const CANCELLED: &str = "cancelled";

fn check(cancel: Option<&AtomicBool>) -> crate::Result<()> {
    match cancel {
        Some(c) if c.load(Ordering::Relaxed) => Err(CANCELLED.into()),
        _ => Ok(()),
    }
}

/// What to run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BenchConfig {
    pub scene: String,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub aa: u32,
    /// Samples per camera ray for the stochastic methods.
    pub ladder: Vec<u32>,
    pub methods: Vec<RenderMethod>,
    pub reference_spp: u32,
    pub seed: u64,
    pub light_sampling: LightSampling,
    /// Deterministic methods are timed as the best of this many renders.
    pub repeats: u32,
    /// Also run `mc` with area sampling of the lights (001 Sect. 3.6's baseline), reported as
    /// `mc-area`.
    pub area_baseline: bool,
    /// Also run `ratio` and `control-variate` with the unbiased U of `--exact-u` (the LTC plus
    /// its sampled correction), reported as `ratio+exact-u` and `control-variate+exact-u`.
    #[serde(default)]
    pub exact_u_variants: bool,
    /// Also time the analytic image with its exact derivative along this motion,
    /// `OBJECT:AXIS` (`render::derivative`), reported as `analytic+derivative`.
    #[serde(default)]
    pub derivative: Option<String>,
    /// How scenes are prepared (the tree cache): the caller's, not part of the report.
    #[serde(skip)]
    pub prepare: crate::shading::PrepareConfig,
}

impl BenchConfig {
    /// Every method but the reference, spp 1 to 256, a 4096-spp reference.
    pub fn new(scene: &str, camera: Camera, width: u32, height: u32) -> Self {
        BenchConfig {
            scene: scene.into(),
            camera,
            width,
            height,
            aa: 1,
            ladder: vec![1, 2, 4, 8, 16, 32, 64, 128, 256],
            methods: RenderMethod::ALL
                .into_iter()
                .filter(|&m| m != RenderMethod::Reference)
                .collect(),
            reference_spp: 4096,
            seed: 1,
            light_sampling: LightSampling::SolidAngle,
            repeats: 2,
            area_baseline: true,
            exact_u_variants: true,
            derivative: None,
            prepare: Default::default(),
        }
    }

    /// `scene` prepared as `penumbra render` prepares it for this config's image
    /// (`RenderContext::for_render`: the cost model sizes the trees for its camera rays), so
    /// that what the benchmark times is what a render of the same settings runs.
    pub fn prepare(&self, scene: &crate::scene::Scene) -> RenderContext {
        RenderContext::for_render(
            scene,
            &RenderRequest {
                settings: self.settings(RenderMethod::Analytic, 1, self.seed),
                prepare: self.prepare.clone(),
                ..RenderRequest::default()
            },
        )
    }

    fn settings(&self, method: RenderMethod, spp: u32, seed: u64) -> RenderSettings {
        self.settings_with(method, spp, seed, self.light_sampling, false)
    }

    fn settings_with(
        &self,
        method: RenderMethod,
        spp: u32,
        seed: u64,
        light_sampling: LightSampling,
        exact_u: bool,
    ) -> RenderSettings {
        RenderSettings {
            width: self.width,
            height: self.height,
            aa: self.aa,
            method,
            spp,
            seed,
            light_sampling,
            collect_stats: false,
            exact_u,
        }
    }
}

/// A converged image and its per-pixel standard error.
#[derive(Clone, Debug)]
pub struct ReferenceImage {
    pub image: Image,
    pub stderr: Image,
    pub spp: u32,
    pub seconds: f64,
}

/// Renders the reference: the full-stochastic estimator at `reference_spp`, with a seed no
/// ladder render uses. Stops with `CANCELLED` soon after `cancel` is raised.
pub fn render_reference(
    ctx: &RenderContext,
    config: &BenchConfig,
    cancel: Option<&AtomicBool>,
) -> crate::Result<ReferenceImage> {
    let settings = config.settings(
        RenderMethod::Reference,
        config.reference_spp,
        config.seed ^ 0x9e37_79b9_7f4a_7c15,
    );
    let out = ctx.render_full(&config.camera, &settings, cancel)?;
    check(cancel)?;
    Ok(ReferenceImage {
        image: out.image,
        stderr: out
            .stderr
            .ok_or("the reference method returned no standard error")?,
        spp: config.reference_spp,
        seconds: out.stats.seconds,
    })
}

/// One rendered image of the run, kept for the equal-time strip.
#[derive(Clone, Debug)]
pub struct BenchImage {
    /// The method's name in the report (`mc-area` for area-sampled `mc`).
    pub label: String,
    pub method: RenderMethod,
    pub spp: Option<u32>,
    pub seconds: f64,
    pub image: Image,
}

/// Renders every method of `config` (stochastic ones at every budget of the ladder), times
/// and compares each with `reference`. `progress(done, total, label)` is called before every
/// render. Returns the report and, per method, the image whose time is closest to the
/// analytic method's (for an equal-time comparison strip). Stops with `CANCELLED` soon
/// after `cancel` is raised (each render checks it tile by tile).
pub fn run_bench(
    ctx: &RenderContext,
    config: &BenchConfig,
    reference: &ReferenceImage,
    cancel: Option<&AtomicBool>,
    mut progress: impl FnMut(usize, usize, &str),
) -> crate::Result<(BenchReport, Vec<BenchImage>)> {
    let (w, h) = (reference.image.width, reference.image.height);
    if (w, h) != (config.width, config.height) {
        return Err(crate::Error::from(format!(
            "the reference is {w}x{h} but the bench renders {}x{}",
            config.width, config.height
        )));
    }
    let ref_rgb = reference.image.to_rgb32();
    let err_rgb = reference.stderr.to_rgb32();
    let info = ReferenceInfo::from_stderr(reference.spp, reference.seconds, &err_rgb);
    // (name in the report, method, spp, light sampling, exact U)
    let mut jobs: Vec<(String, RenderMethod, Option<u32>, LightSampling, bool)> = Vec::new();
    for &m in &config.methods {
        if m.is_stochastic() {
            for &n in &config.ladder {
                jobs.push((m.name().into(), m, Some(n), config.light_sampling, false));
            }
        } else {
            jobs.push((m.name().into(), m, None, config.light_sampling, false));
        }
    }
    if config.area_baseline && config.methods.contains(&RenderMethod::Mc) {
        for &n in &config.ladder {
            jobs.push((
                "mc-area".into(),
                RenderMethod::Mc,
                Some(n),
                LightSampling::Area,
                false,
            ));
        }
    }
    if config.exact_u_variants {
        for m in [RenderMethod::Ratio, RenderMethod::ControlVariate] {
            if config.methods.contains(&m) {
                for &n in &config.ladder {
                    let name = format!("{}+exact-u", m.name());
                    jobs.push((name, m, Some(n), config.light_sampling, true));
                }
            }
        }
    }
    let mut rows = Vec::with_capacity(jobs.len());
    let mut images: Vec<BenchImage> = Vec::new();
    for (k, (name, method, spp, sampling, exact_u)) in jobs.iter().enumerate() {
        let (method, spp) = (*method, *spp);
        let label = match spp {
            Some(n) => format!("{name} {n} spp"),
            None => name.clone(),
        };
        progress(k, jobs.len(), &label);
        let settings =
            config.settings_with(method, spp.unwrap_or(1), config.seed, *sampling, *exact_u);
        let repeats = if spp.is_some() {
            1
        } else {
            config.repeats.max(1)
        };
        let mut best: Option<(f64, Image, RenderStats)> = None;
        super::memory::reset_peak();
        for _ in 0..repeats {
            let (img, stats) = ctx.render(&config.camera, &settings, cancel)?;
            check(cancel)?;
            if best.as_ref().is_none_or(|(t, _, _)| stats.seconds < *t) {
                best = Some((stats.seconds, img, stats));
            }
        }
        let peak_mb = super::memory::peak_mb();
        let (seconds, image, stats) = best.expect("at least one render");
        let cmp = compare(&image.to_rgb32(), &ref_rgb, Some(&err_rgb));
        rows.push(BenchRow {
            violations: stats.violations,
            fallbacks: stats.fallbacks,
            peak_mb,
            ..BenchRow::from_comparison(&config.scene, name, spp, seconds, &cmp, info.rms_stderr)
        });
        images.push(BenchImage {
            label: name.clone(),
            method,
            spp,
            seconds,
            image,
        });
    }
    if let Some(spec) = &config.derivative {
        progress(jobs.len(), jobs.len() + 1, "analytic+derivative");
        let settings = config.settings(RenderMethod::Analytic, 1, config.seed);
        let motion = crate::render::derivative::parse_motion(ctx, spec)?;
        let mut best: Option<(f64, Image)> = None;
        super::memory::reset_peak();
        for _ in 0..config.repeats.max(1) {
            let out = ctx.render_derivative(&config.camera, &settings, &motion, cancel)?;
            check(cancel)?;
            if best.as_ref().is_none_or(|(t, _)| out.stats.seconds < *t) {
                best = Some((out.stats.seconds, out.image));
            }
        }
        let peak_mb = super::memory::peak_mb();
        let (seconds, image) = best.expect("at least one render");
        let cmp = compare(&image.to_rgb32(), &ref_rgb, Some(&err_rgb));
        let name = "analytic+derivative";
        rows.push(BenchRow {
            peak_mb,
            ..BenchRow::from_comparison(&config.scene, name, None, seconds, &cmp, info.rms_stderr)
        });
    }
    progress(jobs.len(), jobs.len(), "done");
    let report = BenchReport::new(&config.scene, w, h, info, rows);
    // Keep, per method, the image closest in time (log scale) to the analytic one.
    let t_star = report.speed_ratios.analytic_seconds;
    let mut strip: Vec<BenchImage> = Vec::new();
    for img in images {
        let d = |i: &BenchImage| t_star.map_or(0.0, |t| (i.seconds.max(1e-9) / t).ln().abs());
        match strip.iter_mut().find(|s| s.label == img.label) {
            Some(s) if d(&img) < d(s) => *s = img,
            Some(_) => {}
            None => strip.push(img),
        }
    }
    Ok((report, strip))
}
