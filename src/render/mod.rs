//! Images of a scene: camera rays, the shading point of each hit, tiles in parallel.

pub mod compare;
pub mod derivative;
pub mod environment_passes;
pub mod progress;
pub mod progressive;
pub mod request;
pub mod sample_grid;
pub mod slicing;
pub mod stochastic;
mod tile_hits;

// Images and their files are a base layer (`raster`), shared with the denoisers and the
// environment's filter.
pub(crate) use crate::raster::Image;
pub(crate) use crate::raster::io as image_io;

use crate::accel::{Bvh, Ray};
use crate::scene::camera::CameraBasis;
use crate::scene::{Camera, Scene};
use crate::shading::{
    Method, NoRecorder, PreparedScene, Recorder, ShadingPoint, ShadingScratch, shade,
};
use crate::shading::{PrepareConfig, PrepareOptions};
use crate::stochastic::{AreaLights, LightSampling};
use glam::DVec3;
use rayon::prelude::*;
pub(crate) use sample_grid::{Coarser, SampleGrid};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use tile_hits::TileScratch;
use web_time::Instant;

/// The camera rays of pixel (x, y): `aa`×`aa` stratified positions at the centres of the
/// sub-pixel cells, averaged with a box filter by every renderer (analytic and reference alike).
pub fn subpixel_rays(
    basis: &CameraBasis,
    x: u32,
    y: u32,
    aa: u32,
    width: u32,
    height: u32,
) -> impl Iterator<Item = Ray> + '_ {
    (0..aa * aa).map(move |k| {
        let (sx, sy) = (k % aa, k / aa);
        let px = x as f64 + (sx as f64 + 0.5) / aa as f64;
        let py = y as f64 + (sy as f64 + 0.5) / aa as f64;
        Ray {
            origin: basis.eye,
            dir: basis.direction(px, py, width, height),
        }
    })
}

crate::choice! {
    /// Every way `penumbra render` can compute an image.
    ///
    /// The rule every method keeps: a render makes the same `render_tiles` calls, and the same
    /// [`slicing::step`]s, in the same order each time it runs with the same inputs, so that a
    /// render cut into time slices (the browser's, [`slicing`]) replays its finished calls from
    /// the slicer's memo and gives the uninterrupted image bit for bit. The slicing module's test
    /// checks it for every method of [`RenderMethod::ALL`].
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum RenderMethod {
        /// 000 Alg. 1: analytic visibility and LTC shading.
        Analytic = "analytic",
        /// 000 Sect. 4.4: every light and occluder face on its own.
        PerTriangle = "per-triangle",
        /// LTC shading without occluders (003's U).
        Unshadowed = "unshadowed",
        /// Full-stochastic S_N with MIS (003 Eq. 10).
        Mc = "mc",
        /// U − (U_N − S_N) (003 Eq. 11, c = 1).
        ControlVariate = "control-variate",
        /// U · S_N / U_N per channel (003 Eq. 15).
        Ratio = "ratio",
        /// U · lum(S_N) / lum(U_N) (003 Sect. 3.4, grayscale weighted shadow).
        RatioGray = "ratio-gray",
        /// U · denoiseS_N / denoiseU_N with the joint-bilateral filter driven by the noise
        /// estimate E (003 Sect. 4).
        RatioDenoised = "ratio-denoised",
        /// U · bilateralS_N / bilateralU_N with a fixed filter width (000's comparison).
        RatioBilateral = "ratio-bilateral",
        /// A converged full-stochastic image with its per-pixel standard error.
        Reference = "reference",
        /// 000 Alg. 1 with the LTC's error sampled inside each exact visible polygon: the LTC
        /// image plus `∫_V (f_GGX − f_LTC) cos`, no shadow rays; converges to GGX (`--spp`
        /// directions per light per camera ray and pass).
        AnalyticExact = "analytic-exact",
    }
}

impl RenderMethod {
    /// The analytic visibility method, for the deterministic methods.
    pub fn analytic(self) -> Option<Method> {
        match self {
            RenderMethod::Analytic => Some(Method::Analytic),
            RenderMethod::PerTriangle => Some(Method::PerTriangle),
            RenderMethod::Unshadowed => Some(Method::Unshadowed),
            _ => None,
        }
    }

    /// Whether the image depends on the sample count (`--spp`).
    pub(crate) fn is_stochastic(self) -> bool {
        self.analytic().is_none()
    }
}

impl From<Method> for RenderMethod {
    fn from(m: Method) -> Self {
        match m {
            Method::Analytic => RenderMethod::Analytic,
            Method::PerTriangle => RenderMethod::PerTriangle,
            Method::Unshadowed => RenderMethod::Unshadowed,
        }
    }
}

/// Settings of `penumbra render`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// `aa`×`aa` stratified sub-pixel positions per pixel, averaged with a box filter.
    pub aa: u32,
    pub method: RenderMethod,
    /// Stochastic methods: samples (shadow rays) per camera ray, so `spp`·`aa`² per pixel.
    pub spp: u32,
    /// Stochastic methods: the seed; pixel (x, y) draws from stream `y·width + x`, so a render
    /// is reproducible bit for bit whatever the thread count.
    pub seed: u64,
    pub light_sampling: LightSampling,
    /// Also record per-pixel work counters and time ([`PixelStats`]) for the AOVs.
    pub collect_stats: bool,
    /// Ratio and control-variate methods: U = the LTC plus its sampled correction over the
    /// unshadowed light (`shading::ltc_correction`, `spp` directions), an unbiased estimate of
    /// the GGX's unshadowed radiance, instead of the LTC alone.
    #[serde(default)]
    pub exact_u: bool,
}

/// Work done for one pixel (summed over its camera rays): for the workbench's AOVs.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PixelStats {
    /// Occluders left after `GetBetween`, summed over lights.
    pub occluders_kept: u32,
    /// Edges of the horizon-clipped light polygons, summed over lights.
    pub light_edges: u32,
    /// Set differences performed.
    pub set_differences: u32,
    /// How the light pieces ended (shortcuts taken), summed over its camera rays.
    pub shortcuts: crate::shading::Shortcuts,
    /// Wall-clock time spent on the pixel, in nanoseconds.
    pub nanos: u32,
    /// Light pieces whose visible polygon was not inside the light's
    /// (`shading::invariant`): a bug wherever it is not zero. Counted even without
    /// `collect_stats`.
    #[serde(default)]
    pub violations: u32,
    /// Paths that gave up for one exact there (degenerate configurations, bounds crossed).
    /// Counted even without `collect_stats`.
    #[serde(default)]
    pub fallbacks: crate::shading::Fallbacks,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 640,
            height: 480,
            aa: 1,
            method: RenderMethod::Analytic,
            spp: 16,
            seed: 0,
            light_sampling: LightSampling::SolidAngle,
            collect_stats: false,
            exact_u: false,
        }
    }
}

/// Timing of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderStats {
    pub seconds: f64,
    pub pixels_per_second: f64,
    /// Light pieces, over all camera rays, whose visible polygon was not inside the light's
    /// (`shading::invariant`; the analytic methods): a bug wherever it is not zero.
    pub violations: u64,
    /// Shading points where a path gave up for one that is exact there, by reason: a
    /// degenerate configuration, or a walk that crossed the bound its input sets.
    #[serde(default)]
    pub fallbacks: FallbackTotals,
}

/// [`crate::shading::Fallbacks`] summed over a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FallbackTotals {
    pub degenerate: u64,
    pub bounds_crossed: u64,
}

impl FallbackTotals {
    pub(crate) fn add(&mut self, f: &crate::shading::Fallbacks) {
        self.degenerate += f.degenerate as u64;
        self.bounds_crossed += f.bounds_crossed as u64;
    }
}

/// A scene ready to render: the scene, its prepared shading data and its BVH.
pub struct RenderContext {
    /// The scene, shared (the workbench hands one context to its render thread and its UI).
    pub scene: Arc<Scene>,
    pub prepared: PreparedScene,
    pub bvh: Bvh,
    /// The lights prepared for area sampling (the stochastic baseline).
    pub area_lights: AreaLights,
    /// An environment light (paper 002), if the scene has one: its term is added to the area
    /// lights' image by every render (`environment_passes::render_environment`).
    pub environment: Option<environment_passes::SceneEnvironment>,
}

/// What a camera ray sees first: the shading point and the radiance emitted toward the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimaryHit {
    pub point: ShadingPoint,
    pub emitted: DVec3,
    pub receiver: bool,
}

impl RenderContext {
    /// What the stochastic estimators read of this context.
    #[inline]
    pub(crate) fn sampled(&self) -> crate::stochastic::SampledScene<'_> {
        crate::stochastic::SampledScene {
            scene: &self.scene,
            prepared: &self.prepared,
            bvh: &self.bvh,
            area_lights: &self.area_lights,
        }
    }

    /// Prepares a copy of `scene` (see [`RenderContext::from_arc`] to share one).
    pub fn new(scene: &Scene) -> Self {
        Self::from_arc(Arc::new(scene.clone()))
    }

    /// Prepares `scene`: shading data, BVH, area-sampling tables (no disk cache: see
    /// [`RenderContext::configured`]).
    pub fn from_arc(scene: Arc<Scene>) -> Self {
        Self::configured(scene, &PrepareConfig::default())
    }

    /// Prepares `scene` with the caller's `config` (the tree cache, the measuring switches).
    pub fn configured(scene: Arc<Scene>, config: &PrepareConfig) -> Self {
        let options = PrepareOptions {
            environment: scene.environment.is_some(),
            ..config.options()
        };
        Self::with_options(scene, options)
    }

    /// Prepares `scene` for `request`: its trees sized for the request's camera rays (the
    /// cost model, `shading::cost_model`), its LTC table, the caller's choices.
    pub fn for_render(scene: &Scene, request: &request::RenderRequest) -> Self {
        Self::with_options(Arc::new(scene.clone()), request.prepare_options(scene))
    }

    /// Prepares `scene` with `options`.
    pub(crate) fn with_options(scene: Arc<Scene>, options: PrepareOptions) -> Self {
        let prepared = PreparedScene::prepare(&scene, options);
        RenderContext {
            area_lights: AreaLights::new(&scene, &prepared),
            bvh: Bvh::build(&scene),
            prepared,
            scene,
            environment: None,
        }
    }

    /// Lights the scene with `light` too, rendered as `settings` say (replaces any earlier
    /// environment).
    pub fn set_environment(
        &mut self,
        light: Arc<crate::environment::EnvironmentLight>,
        settings: environment_passes::EnvironmentSettings,
    ) {
        // The precomputed transfer depends on the scene alone: a new map, rotation or method
        // reuses it.
        let transfer = self
            .environment
            .take()
            .and_then(|e| e.transfer.zip(e.transfer_report));
        self.environment = Some(environment_passes::SceneEnvironment::new(
            self, light, settings, transfer,
        ));
    }

    /// A copy of this context lit by `environment` instead (or by none): the prepared data and
    /// the BVH are copied, not prepared again, so that the workbench's environment panel can
    /// switch maps and methods while a render still reads the old context.
    pub fn with_environment(
        &self,
        environment: Option<(
            Arc<crate::environment::EnvironmentLight>,
            environment_passes::EnvironmentSettings,
        )>,
    ) -> RenderContext {
        let mut ctx = RenderContext {
            scene: self.scene.clone(),
            prepared: self.prepared.clone(),
            bvh: self.bvh.clone(),
            area_lights: self.area_lights.clone(),
            environment: None,
        };
        if let Some((light, settings)) = environment {
            // The precomputed transfer belongs to the scene: a new map or method keeps it.
            let transfer = self
                .environment
                .as_ref()
                .and_then(|e| e.transfer.clone().zip(e.transfer_report));
            ctx.environment = Some(environment_passes::SceneEnvironment::new(
                &ctx, light, settings, transfer,
            ));
        }
        ctx
    }

    /// The context of `scene`, a copy of this context's scene in which object `index` moved
    /// rigidly (its faces, material and flags unchanged), prepared cheaply for a drag in the
    /// workbench: the other objects' prepared data are shared or copied, the moved object
    /// keeps its trees of precomputed silhouettes under a new map into their frame
    /// ([`PreparedScene::with_moved_object`], which says when it falls back to preparing the
    /// object alone), the BVH is refit (rebuilt only when the refit tree got too much worse,
    /// [`Bvh::with_moved_object`]), the area-sampling tables are rebuilt only when a light
    /// moved, and an environment light is attached again (its precomputed transfer reused
    /// when the moved object is dynamic and the scene's box did not change).
    ///
    /// Renders and probes of the result equal those of a context prepared from scratch on
    /// `scene` up to rounding (the silhouettes are the same vertex loops, read from other
    /// trees or computed at the point). An error when `index` is out of range or `scene`
    /// has another number of objects.
    pub fn with_moved_object(
        &self,
        index: usize,
        scene: Arc<Scene>,
    ) -> crate::Result<RenderContext> {
        let (prepared, _) = self.prepared.with_moved_object(&scene, index)?;
        let bvh = self.bvh.with_moved_object(&self.scene, &scene, index);
        let area_lights =
            if self.scene.objects[index].flags.light || scene.objects[index].flags.light {
                AreaLights::new(&scene, &prepared)
            } else {
                self.area_lights.clone()
            };
        let mut ctx = RenderContext {
            scene,
            prepared,
            bvh,
            area_lights,
            environment: None,
        };
        if let Some(env) = &self.environment {
            let keep =
                !ctx.scene.objects[index].flags.is_static && ctx.bvh.bounds() == self.bvh.bounds();
            let transfer = keep
                .then(|| env.transfer.clone().zip(env.transfer_report))
                .flatten();
            ctx.environment = Some(environment_passes::SceneEnvironment::new(
                &ctx,
                env.light.clone(),
                env.settings,
                transfer,
            ));
        }
        Ok(ctx)
    }

    /// The first surface along `ray`, as a shading point with the geometric normal turned toward
    /// the viewer (two-sided shading). Shared by the renderer and the workbench's pick.
    pub fn primary_hit(&self, ray: &Ray) -> Option<PrimaryHit> {
        let hit = self.bvh.intersect(ray, 0.0, f64::INFINITY)?;
        let obj = &self.scene.objects[hit.object as usize];
        let view = (-ray.dir).normalize();
        let front = hit.geometric_normal.dot(view) > 0.0;
        let normal = if front {
            hit.geometric_normal
        } else {
            -hit.geometric_normal
        };
        // Lights emit from the front side of their faces only.
        let emitted = if obj.flags.light && front {
            obj.material.ke
        } else {
            DVec3::ZERO
        };
        Some(PrimaryHit {
            point: ShadingPoint {
                position: hit.point,
                normal,
                view,
                object: Some(hit.object),
                face: Some(hit.face),
            },
            emitted,
            receiver: obj.flags.receiver,
        })
    }

    /// Radiance toward the eye along a camera ray: emission plus direct lighting.
    pub fn radiance<R: Recorder>(
        &self,
        ray: &Ray,
        method: Method,
        scratch: &mut ShadingScratch,
        rec: &mut R,
    ) -> DVec3 {
        match self.primary_hit(ray) {
            Some(hit) => self.radiance_at(&hit, method, scratch, rec),
            None => DVec3::ZERO,
        }
    }

    /// [`RenderContext::radiance`] at a primary hit already found.
    pub fn radiance_at<R: Recorder>(
        &self,
        hit: &PrimaryHit,
        method: Method,
        scratch: &mut ShadingScratch,
        rec: &mut R,
    ) -> DVec3 {
        let mut l = hit.emitted;
        if hit.receiver {
            let material = &self.prepared.materials[hit.point.object.unwrap_or(0) as usize];
            l += shade(&self.prepared, &hit.point, material, method, scratch, rec);
        }
        l
    }

    /// Renders the image seen by `camera` with `settings.method`; tiles run in parallel.
    /// Stops early (leaving the rest black) when `cancel` becomes true.
    pub fn render(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        cancel: Option<&AtomicBool>,
    ) -> crate::Result<(Image, RenderStats)> {
        let out = self.render_full(camera, settings, cancel)?;
        Ok((out.image, out.stats))
    }

    /// Like [`RenderContext::render`], with everything the method computed on the way: the
    /// standard error of a reference, the stochastic buffers (U, S_N, U_N, G-buffer) and the
    /// denoiser's intermediate images.
    pub fn render_full(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        cancel: Option<&AtomicBool>,
    ) -> crate::Result<RenderOutput> {
        let basis = camera.basis()?;
        if settings.width == 0 || settings.height == 0 || settings.aa == 0 {
            return Err("image size and --aa must be positive".into());
        }
        // analytic-exact with no sample is the LTC image (its progressive previews).
        if settings.method.is_stochastic()
            && settings.spp == 0
            && settings.method != RenderMethod::AnalyticExact
        {
            return Err("--spp must be positive".into());
        }
        let start = Instant::now();
        let mut out = match settings.method.analytic() {
            Some(method) => {
                let grid = SampleGrid::full(settings.width, settings.height, settings.aa);
                let collect = settings.collect_stats;
                self.render_analytic(&basis, &grid, collect, method, cancel, None)
            }
            None => stochastic::render(self, &basis, settings, cancel),
        };
        // The environment's term adds to the area lights' (both are linear in the radiance).
        if let Some(env) = &self.environment {
            let (w, h) = (settings.width, settings.height);
            let Some(e) = environment_passes::render_environment(
                self,
                env,
                &basis,
                w,
                h,
                settings.aa,
                cancel,
            ) else {
                return Ok(RenderOutput::default());
            };
            out.add_environment(e);
        }
        let seconds = start.elapsed().as_secs_f64();
        out.stats = RenderStats {
            seconds,
            pixels_per_second: (settings.width * settings.height) as f64 / seconds.max(1e-12),
            violations: out.violations,
            fallbacks: out.fallbacks,
        };
        Ok(out)
    }

    /// Whether a progressive render with `settings` can interlace its levels
    /// ([`RenderContext::render_level`]): a deterministic method whose every sample is one
    /// camera ray's, with no environment term (rendered on its own pixel grid) and no per-pixel
    /// statistics (they would miss the samples taken over).
    pub(crate) fn interlaces(&self, settings: &RenderSettings) -> bool {
        settings.method.analytic().is_some()
            && self.environment.is_none()
            && !settings.collect_stats
    }

    /// One level of a progressive render of the analytic methods: the samples of `grid` (a
    /// preview, or the full image at stride 1), taking over the samples a `coarser` level
    /// computed already ([`sample_grid`]). At stride 1 the image equals
    /// [`RenderContext::render_full`]'s bit for bit. `None` for the methods and settings whose
    /// samples do not nest (stochastic methods, an environment term, per-pixel statistics):
    /// render those with [`RenderContext::render_full`].
    pub(crate) fn render_level(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        stride: u32,
        coarser: Option<Coarser>,
        cancel: Option<&AtomicBool>,
    ) -> Option<crate::Result<RenderOutput>> {
        if !self.interlaces(settings) {
            return None;
        }
        let method = settings.method.analytic()?;
        let basis = match camera.basis() {
            Ok(b) => b,
            Err(e) => return Some(Err(e)),
        };
        if settings.width == 0 || settings.height == 0 || settings.aa == 0 || stride == 0 {
            return Some(Err("image size and --aa must be positive".into()));
        }
        let grid = SampleGrid {
            stride,
            ..SampleGrid::full(settings.width, settings.height, settings.aa)
        };
        let start = Instant::now();
        let mut out = self.render_analytic(&basis, &grid, false, method, cancel, coarser);
        if let Some(c) = coarser {
            c.add_counts_to(&grid, &mut out);
        }
        let seconds = start.elapsed().as_secs_f64();
        let (w, h) = grid.size();
        out.stats = RenderStats {
            seconds,
            pixels_per_second: (w * h) as f64 / seconds.max(1e-12),
            violations: out.violations,
            fallbacks: out.fallbacks,
        };
        Some(Ok(out))
    }

    /// The analytic methods' image of the samples of `grid`, sample 0 taken from `coarser`
    /// where it has it. `collect`: per-pixel statistics (their time includes only the samples
    /// computed here).
    fn render_analytic(
        &self,
        basis: &CameraBasis,
        grid: &SampleGrid,
        collect: bool,
        method: Method,
        cancel: Option<&AtomicBool>,
        coarser: Option<Coarser>,
    ) -> RenderOutput {
        let (w, h) = grid.size();
        let samples = grid.samples();
        let inv = 1.0 / samples as f64;
        let share = self.prepared.tiles_share_candidates(method);
        let begin = |s: &mut TileScratch, bounds: TileBounds| {
            if share {
                s.hits.find(self, basis, bounds, grid);
            }
        };
        let pixels = render_tiles_with(w, h, cancel, TileScratch::default, begin, |s, x, y| {
            let start = collect.then(Instant::now);
            let mut sum = DVec3::ZERO;
            let mut stats = PixelStats::default();
            let known = coarser.and_then(|c| c.sample(grid, x, y));
            // Lazy: with a tile's hits found already, no camera ray is made again.
            let mut rays = grid.rays(basis, x, y);
            for k in 0..samples as usize {
                let scratch = &mut s.shading;
                if k == 0
                    && let Some(value) = known
                {
                    // The same sum as computing it: 0 + value.
                    sum += value;
                    if !share {
                        rays.next();
                    }
                    continue;
                }
                sum += match share {
                    true => match s.hits.hit(x, y, k) {
                        Some((hit, region)) => {
                            scratch.share_with_tile(region);
                            self.radiance_at(hit, method, scratch, &mut NoRecorder)
                        }
                        None => DVec3::ZERO,
                    },
                    false => rays.next().map_or(DVec3::ZERO, |ray| {
                        self.radiance(&ray, method, scratch, &mut NoRecorder)
                    }),
                };
                stats.violations += scratch.stats.violations;
                scratch.stats.violations = 0;
                stats.fallbacks.add(&scratch.stats.fallbacks);
                scratch.stats.fallbacks = Default::default();
                if collect {
                    stats.occluders_kept += scratch.stats.occluders_kept;
                    stats.light_edges += scratch.stats.light_edges;
                    stats.set_differences += scratch.stats.set_differences;
                    stats.shortcuts.add(&scratch.stats.shortcuts);
                    scratch.stats = Default::default();
                }
            }
            if let Some(t) = start {
                stats.nanos = t.elapsed().as_nanos().min(u32::MAX as u128) as u32;
            }
            (sum * inv, stats)
        });
        let Some(pixels) = pixels else {
            // Cancelled: whatever is returned is discarded; do not assemble a full image.
            return RenderOutput::default();
        };
        let image = Image {
            width: w,
            height: h,
            pixels: pixels.iter().map(|p| p.0).collect(),
        };
        RenderOutput {
            image,
            violations: pixels.iter().map(|p| p.1.violations as u64).sum(),
            fallbacks: pixels.iter().fold(FallbackTotals::default(), |mut t, p| {
                t.add(&p.1.fallbacks);
                t
            }),
            violation_pixels: pixels
                .iter()
                .enumerate()
                .filter(|(_, p)| p.1.violations > 0)
                .map(|(i, p)| [i as u32 % w, i as u32 / w, p.1.violations])
                .collect(),
            pixel_stats: collect.then(|| pixels.iter().map(|p| p.1).collect()),
            ..RenderOutput::default()
        }
    }
}

/// An image and what its method computed on the way.
#[derive(Clone, Debug, Default)]
pub struct RenderOutput {
    pub image: Image,
    /// Per-pixel standard error of the image (the reference method).
    pub stderr: Option<Image>,
    /// U, S_N, U_N and the G-buffer (stochastic methods).
    /// Shared, not copied: a progressive render hands the same buffers to the viewport, the
    /// denoiser thread and its next pass (tens of MB at full resolution).
    pub buffers: Option<std::sync::Arc<stochastic::StochasticBuffers>>,
    /// The denoiser's intermediate images: W_N, E, σ, denoised S_N and U_N.
    pub denoise: Option<crate::denoise::DenoiseAovs>,
    /// Per-pixel work counters and time (deterministic methods, with `collect_stats`).
    pub pixel_stats: Option<Vec<PixelStats>>,
    /// The environment's term and its passes (when the scene has an environment light).
    pub environment: Option<environment_passes::EnvironmentOutput>,
    /// The image's derivative along a rigid motion, with its mask (a progressive render of a
    /// derivative: `progressive::render_progressive_derivative`).
    pub derivative: Option<derivative::DerivativeImages>,
    /// Light pieces whose visible polygon was not inside the light's (`shading::invariant`).
    pub violations: u64,
    /// The pixels where that happened: x, y (row 0 at the top) and how many pieces.
    pub violation_pixels: Vec<[u32; 3]>,
    /// Fallbacks taken over the render (the analytic methods).
    pub fallbacks: FallbackTotals,
    pub stats: RenderStats,
}

impl RenderOutput {
    /// Adds the environment's term `e` to the image (both terms are linear in the radiance;
    /// an image of another size, from a cancelled render, is left alone) and combines the
    /// standard errors of two references.
    pub(crate) fn add_environment(&mut self, e: environment_passes::EnvironmentOutput) {
        if self.image.pixels.len() == e.image.pixels.len() {
            for (p, q) in self.image.pixels.iter_mut().zip(&e.image.pixels) {
                *p += *q;
            }
        }
        let (w, h) = (e.image.width, e.image.height);
        self.stderr = match (self.stderr.take(), &e.stderr) {
            (Some(a), Some(b)) => Some(Image {
                width: w,
                height: h,
                pixels: a
                    .pixels
                    .iter()
                    .zip(&b.pixels)
                    .map(|(x, y)| (*x * *x + *y * *y).map(f64::sqrt))
                    .collect(),
            }),
            (a, b) => a.or_else(|| b.clone()),
        };
        self.environment = Some(e);
    }
}

/// Evaluates `pixel(scratch, x, y)` for every pixel in 16×16 tiles spread over rayon's
/// threads (one scratch per worker), and returns the values in row-major order; `None` once
/// `cancel` has been set (the tiles not yet started are skipped, and nothing is assembled: a
/// cancelled view must give way to the next one at once). Under a [`slicing::Slicer`] the
/// tiles run in order on this thread, a slice at a time.
pub(crate) fn render_tiles<T, S>(
    width: u32,
    height: u32,
    cancel: Option<&AtomicBool>,
    init: impl Fn() -> S + Sync + Send,
    pixel: impl Fn(&mut S, u32, u32) -> T + Sync + Send,
) -> Option<Vec<T>>
where
    T: Default + Clone + Send + 'static,
{
    render_tiles_with(width, height, cancel, init, |_, _| {}, pixel)
}

/// A tile's corner and its far corner (exclusive), in pixels.
pub(crate) type TileBounds = ((u32, u32), (u32, u32));

/// [`render_tiles`] with `begin(scratch, bounds)` called before each tile's pixels: what the
/// tile's pixels share is found there.
pub(crate) fn render_tiles_with<T, S>(
    width: u32,
    height: u32,
    cancel: Option<&AtomicBool>,
    init: impl Fn() -> S + Sync + Send,
    begin: impl Fn(&mut S, TileBounds) + Sync + Send,
    pixel: impl Fn(&mut S, u32, u32) -> T + Sync + Send,
) -> Option<Vec<T>>
where
    T: Default + Clone + Send + 'static,
{
    let tiles = Tiles::new(width, height);
    let count = tiles.count();
    let progress = progress::TileProgress::current();
    if let Some(p) = &progress {
        p.started(count);
    }
    let tile = |scratch: &mut S, t: usize| {
        begin(scratch, tiles.bounds(t));
        let out = tiles.evaluate(t, |x, y| pixel(scratch, x, y));
        if let Some(p) = &progress {
            p.finished_one();
        }
        out
    };
    if let Some(sliced) = slicing::Slicer::with_current(|s| s.tiles(count, &init, tile)) {
        return sliced.map(|done| tiles.assemble(done.into_iter().enumerate()));
    }
    let done: Vec<(usize, Vec<T>)> = (0..count)
        .into_par_iter()
        .map_init(&init, |scratch, t| {
            // A cancelled tile comes back empty and stays at the default value.
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return (t, Vec::new());
            }
            (t, tile(scratch, t))
        })
        .collect();
    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return None;
    }
    Some(tiles.assemble(done.into_iter()))
}

/// An image cut into 16×16 tiles, numbered row by row.
struct Tiles {
    width: u32,
    height: u32,
    across: u32,
}

impl Tiles {
    const SIDE: u32 = 16;

    fn new(width: u32, height: u32) -> Self {
        Tiles {
            width,
            height,
            across: width.div_ceil(Self::SIDE),
        }
    }

    fn count(&self) -> usize {
        (self.across * self.height.div_ceil(Self::SIDE)) as usize
    }

    /// Tile `t`'s corner and its far corner (exclusive).
    fn bounds(&self, t: usize) -> ((u32, u32), (u32, u32)) {
        let t = t as u32;
        let (x0, y0) = (
            (t % self.across) * Self::SIDE,
            (t / self.across) * Self::SIDE,
        );
        let far = (
            (x0 + Self::SIDE).min(self.width),
            (y0 + Self::SIDE).min(self.height),
        );
        ((x0, y0), far)
    }

    /// `pixel(x, y)` over tile `t`, row by row.
    fn evaluate<T>(&self, t: usize, mut pixel: impl FnMut(u32, u32) -> T) -> Vec<T> {
        let ((x0, y0), (x1, y1)) = self.bounds(t);
        let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
        for y in y0..y1 {
            for x in x0..x1 {
                out.push(pixel(x, y));
            }
        }
        out
    }

    /// The image in row-major order from its tiles' values.
    fn assemble<T: Default + Clone>(&self, tiles: impl Iterator<Item = (usize, Vec<T>)>) -> Vec<T> {
        let w = self.width;
        let mut pixels = vec![T::default(); w as usize * self.height as usize];
        for (t, px) in tiles {
            let ((x0, y0), (x1, _)) = self.bounds(t);
            let tw = (x1 - x0) as usize;
            for (i, p) in px.into_iter().enumerate() {
                let (x, y) = (x0 + (i % tw) as u32, y0 + (i / tw) as u32);
                pixels[(y * w + x) as usize] = p;
            }
        }
        pixels
    }
}
