//! The environment light's share of an image (paper 002), added to the area lights' image.
//!
//! 002 Sect. 4 renders in four passes; here they are, with the work of each timed:
//!
//! 1. **G-buffer**: the camera rays' first hits and `E_static` per sub-pixel position: the
//!    unshadowed irradiance of Eq. 7, or, when static objects reach the hemisphere, the
//!    irradiance they leave (diffuse PRT with shadows, Eq. 6; computed exactly here by the
//!    polygon integral over the static-visible region, see `shading::environment_occlusion`).
//! 2. **Occlusion**: `E_occluded` by the method: exact (`analytic`), rays in merged cones
//!    (`rt`, 002 Alg. 1–2), every ray (`rt-unculled`), ambient occlusion (`rtao`); or, for
//!    the `reference`, E itself by Monte Carlo of the map with shadow rays.
//! 3. **Filter**: `rt`'s E_occluded through the 5×5 cross-bilateral filter.
//! 4. **Composition**: `ρ/π · max(E_static − E_occluded, 0)` (Eq. 2–3); camera rays that
//!    miss everything see the map.
//!
//! Passes 1–2 run fused per pixel (no G-buffer of every sub-pixel sample is kept); their
//! times are the CPU time of each part, scaled to the wall time of the fused pass.

use super::{Image, RenderContext, subpixel_rays};
use crate::accel::Ray;
use crate::environment::prt::{PrtReport, PrtSettings, TransferField, transferred_irradiance};
use crate::environment::{
    BoundingSphere, Cone, EnvMethod, EnvironmentLight, HemisphereSamples,
    construct_and_merge_cones, cross_bilateral_5x5, pixel_rotation, ray_extent,
};
use crate::math::{Frame, Pcg32};
use crate::raster::gbuffer::{GBuffer, Surface};
use crate::scene::camera::CameraBasis;
use crate::shading::{
    EnvironmentOccluders, EnvironmentPass, EnvironmentSample, NoRecorder, RayOutcome, Recorder,
    ShadingPoint, ShadingScratch, environment_integrals, shadowed_irradiance,
};
use glam::DVec3;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use web_time::Instant;

/// Which parts of conical ray culling `rt` uses (002 Table 1's three columns).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Culling {
    /// Every ray traced to infinity.
    None,
    /// Rays outside every cone are not traced (traced to infinity otherwise).
    Direction,
    /// Direction culling, and each traced ray stops at the largest cone height.
    DirectionAndLength,
}

/// How the environment term is rendered.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentSettings {
    pub method: EnvMethod,
    /// Rays per camera ray (`rt`, `rt-unculled`, `rtao`, `reference`).
    pub spp: u32,
    pub seed: u64,
    /// `rt`: culling (by default what the method's name says).
    pub culling: Culling,
    /// `rt`: the 5×5 cross-bilateral filter on E_occluded (002 Sect. 4); off for the
    /// unfiltered images of 002 Fig. 7d.
    pub filter: bool,
    /// Cluster each point's merged cones into at most this many (002 Sect. 6's open
    /// problem; `environment::cones::cluster_cones`). `None`: 002's merging alone.
    pub max_cones: Option<usize>,
    /// How `E_static` is found on static surfaces by the methods that read it from the
    /// G-buffer pass (`rt`, `rt-unculled`, `rtao`, `unshadowed`). `analytic` finds the exact
    /// value on its way, the `reference` needs none.
    #[serde(default)]
    pub static_term: StaticTerm,
}

crate::choice! {
    /// How the methods of 002 obtain `E_static` (002 Eq. 6); `penumbra render --env-static`.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum StaticTerm {
        /// 002 as published: diffuse PRT, transfer vectors precomputed by ray casting on the
        /// static surfaces and interpolated (`environment::prt`). Points the field does not
        /// cover (dynamic objects, back sides) take the exact value.
        Prt = "prt",
        /// The exact polygon integral over what the static objects leave, at every point.
        Exact = "exact",
    }
    default = Prt;
}

impl EnvironmentSettings {
    /// The settings a scene's environment asks for: its method and rays, or the defaults
    /// (`EnvironmentSpec::method_or_default`, `spp_or_default`).
    pub(crate) fn for_spec(
        spec: &crate::scene::environment_spec::EnvironmentSpec,
        seed: u64,
    ) -> Self {
        Self::new(spec.method_or_default(), spec.spp_or_default(), seed)
    }

    /// Whether this render filters E_occluded: a method the filter applies to
    /// (`EnvMethod::is_filterable`) with the filter on.
    pub(crate) fn filters(&self) -> bool {
        self.method.is_filterable() && self.filter
    }

    /// The settings `method` implies: culling per its name, the filter on for `rt`.
    pub fn new(method: EnvMethod, spp: u32, seed: u64) -> Self {
        EnvironmentSettings {
            method,
            spp,
            seed,
            culling: match method {
                EnvMethod::RtUnculled => Culling::None,
                _ => Culling::DirectionAndLength,
            },
            filter: method.is_filterable(),
            max_cones: None,
            static_term: StaticTerm::Prt,
        }
    }
}

/// An environment light attached to a scene ready to render.
pub struct SceneEnvironment {
    pub light: Arc<EnvironmentLight>,
    pub settings: EnvironmentSettings,
    /// The occluders split into static and dynamic (002 Sect. 3.2).
    pub occluders: EnvironmentOccluders,
    /// Bounding spheres of the dynamic occluders: the cones of 002 Eq. 4.
    pub spheres: Vec<BoundingSphere>,
    /// The rays of `rt`, `rt-unculled` and `rtao`.
    pub samples: HemisphereSamples,
    /// The precomputed transfer of the static surfaces, when the method reads `E_static` from
    /// it (see [`StaticTerm`]), and what it cost.
    pub transfer: Option<Arc<TransferField>>,
    pub transfer_report: Option<PrtReport>,
    /// Smallest ray parameter of a shadow ray (self-intersection), relative to the scene.
    t_min: f64,
}

impl SceneEnvironment {
    /// The environment `light` rendered as `settings` say. `transfer`: a transfer field already
    /// computed for this scene (with what it cost), used instead of reading or computing one.
    pub fn new(
        ctx: &RenderContext,
        light: Arc<EnvironmentLight>,
        settings: EnvironmentSettings,
        transfer: Option<(Arc<TransferField>, PrtReport)>,
    ) -> Self {
        let scene = &ctx.scene;
        let occluders =
            EnvironmentOccluders::new(&ctx.prepared, |o| scene.objects[o as usize].flags.is_static);
        let spheres = occluders
            .dynamics
            .iter()
            .map(|&oi| {
                let obj = &ctx.prepared.objects[ctx.prepared.occluders[oi as usize] as usize];
                BoundingSphere {
                    centre: obj.poly.center,
                    radius: obj.poly.radius,
                }
            })
            .collect();
        let extent = ctx
            .bvh
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-300));
        let reads_static = !matches!(settings.method, EnvMethod::Analytic | EnvMethod::Reference);
        let (transfer, transfer_report) = if reads_static
            && settings.static_term == StaticTerm::Prt
            && !occluders.statics.is_empty()
        {
            let (field, report) = transfer.unwrap_or_else(|| {
                let (field, report) = TransferField::cached_or_computed(
                    scene,
                    &ctx.bvh,
                    PrtSettings::default(),
                    ctx.prepared.cache.as_ref(),
                );
                (Arc::new(field), report)
            });
            (Some(field), Some(report))
        } else {
            (None, None)
        };
        SceneEnvironment {
            light,
            settings,
            occluders,
            spheres,
            samples: HemisphereSamples::new(settings.spp.max(1)),
            transfer,
            transfer_report,
            t_min: 1e-9 * extent,
        }
    }
}

/// Work and time of the environment passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentStats {
    /// Seconds per pass (002 Table 1): G-buffer, occlusion (ray tracing or the exact
    /// integral), filter, composition.
    pub gbuffer_seconds: f64,
    pub occlusion_seconds: f64,
    pub filter_seconds: f64,
    pub composition_seconds: f64,
    /// Rays the method could trace, and those it traced (after culling).
    pub rays_total: u64,
    pub rays_traced: u64,
    /// Merged cones, summed over sub-pixel samples (`rt`), and the samples that had any.
    pub cones: u64,
    pub samples: u64,
    /// Set differences of the exact method.
    pub set_differences: u64,
}

/// Per-pixel results of the fused passes 1–2.
#[derive(Clone, Copy, Debug, Default)]
struct EnvPixel {
    /// Mean over the sub-pixel samples of ρ/π · max(E_static − E_occluded, 0) (unfiltered).
    radiance: DVec3,
    /// Mean of ρ/π · E_static.
    base: DVec3,
    /// Mean of E_occluded, and of ρ/π (for the filtered composition).
    occluded: DVec3,
    albedo: DVec3,
    /// The map seen by camera rays that miss, averaged over the pixel.
    background: DVec3,
    /// Per-channel squared standard error of `radiance` (the reference).
    variance: DVec3,
    surface: Option<Surface>,
    cones: u32,
    rays_traced: u32,
    rays_total: u32,
    set_differences: u32,
    nanos_gbuffer: u64,
    nanos_occlusion: u64,
}

/// What the environment pass produced.
#[derive(Clone, Debug, Default)]
pub struct EnvironmentOutput {
    pub image: Image,
    /// Per-pixel standard error (`reference` only).
    pub stderr: Option<Image>,
    /// E_occluded averaged per pixel, before and after the filter (the workbench's AOVs).
    pub occluded: Image,
    pub occluded_filtered: Option<Image>,
    /// Merged cones per pixel (002 Fig. 8), averaged over its sub-pixel samples.
    pub cones: Vec<f32>,
    pub stats: EnvironmentStats,
}

/// Per-thread buffers.
#[derive(Default)]
struct EnvScratch {
    shading: ShadingScratch,
    cones: Vec<Cone>,
}

/// Renders the environment term of the image seen through `basis`: passes 1–4 of the module
/// doc. `None` when cancelled.
pub(crate) fn render_environment(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    basis: &CameraBasis,
    width: u32,
    height: u32,
    aa: u32,
    cancel: Option<&AtomicBool>,
) -> Option<EnvironmentOutput> {
    let start = Instant::now();
    let nanos_g = AtomicU64::new(0);
    let nanos_o = AtomicU64::new(0);
    let pixels = super::render_tiles(width, height, cancel, EnvScratch::default, |s, x, y| {
        let px = shade_pixel(ctx, env, basis, x, y, width, height, aa, s, &mut NoRecorder);
        nanos_g.fetch_add(px.nanos_gbuffer, Ordering::Relaxed);
        nanos_o.fetch_add(px.nanos_occlusion, Ordering::Relaxed);
        px
    })?;
    let fused = start.elapsed().as_secs_f64();
    let (ng, no) = (
        nanos_g.load(Ordering::Relaxed) as f64,
        nanos_o.load(Ordering::Relaxed) as f64,
    );
    let share = if ng + no > 0.0 { ng / (ng + no) } else { 0.5 };
    let mut stats = EnvironmentStats {
        gbuffer_seconds: fused * share,
        occlusion_seconds: fused * (1.0 - share),
        ..Default::default()
    };
    for p in &pixels {
        stats.rays_total += p.rays_total as u64;
        stats.rays_traced += p.rays_traced as u64;
        stats.cones += p.cones as u64;
        stats.set_differences += p.set_differences as u64;
    }
    stats.samples = pixels.len() as u64 * u64::from(aa * aa);
    let image_of = |f: &dyn Fn(&EnvPixel) -> DVec3| Image {
        width,
        height,
        pixels: pixels.iter().map(f).collect(),
    };
    let occluded = image_of(&|p| p.occluded);
    let cones = pixels
        .iter()
        .map(|p| p.cones as f32 / (aa * aa) as f32)
        .collect();

    let t_filter = Instant::now();
    let filtered = env.settings.filters().then(|| {
        let g = GBuffer::from_fn(width, height, |x, y| {
            pixels[(y * width + x) as usize].surface
        });
        cross_bilateral_5x5(&occluded, &g)
    });
    stats.filter_seconds = t_filter.elapsed().as_secs_f64();

    let t_compose = Instant::now();
    let image = match &filtered {
        Some(f) => Image {
            width,
            height,
            pixels: pixels
                .iter()
                .zip(&f.pixels)
                .map(|(p, &occ)| p.background + (p.base - p.albedo * occ).max(DVec3::ZERO))
                .collect(),
        },
        None => image_of(&|p| p.background + p.radiance),
    };
    stats.composition_seconds = t_compose.elapsed().as_secs_f64();
    let stderr = (env.settings.method == EnvMethod::Reference).then(|| {
        image_of(&|p| {
            DVec3::new(
                p.variance.x.sqrt(),
                p.variance.y.sqrt(),
                p.variance.z.sqrt(),
            )
        })
    });
    Some(EnvironmentOutput {
        image,
        stderr,
        occluded,
        occluded_filtered: filtered,
        cones,
        stats,
    })
}

/// The environment term of pixel (x, y) of an `--aa 1` render before the filter, shaded by
/// the renderer's own passes 1–2 with `rec` attached (the workbench's probe): bit for bit
/// the render's pixel for every method but filtered `rt`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn environment_pixel<R: Recorder>(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    basis: &CameraBasis,
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    rec: &mut R,
) -> DVec3 {
    let p = shade_pixel(
        ctx,
        env,
        basis,
        x,
        y,
        width,
        height,
        1,
        &mut EnvScratch::default(),
        rec,
    );
    p.background + p.radiance
}

/// Passes 1–2 for pixel (x, y).
#[allow(clippy::too_many_arguments)]
fn shade_pixel<R: Recorder>(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    basis: &CameraBasis,
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    aa: u32,
    s: &mut EnvScratch,
    rec: &mut R,
) -> EnvPixel {
    let mut px = EnvPixel::default();
    let k = (aa * aa) as f64;
    let pixel_index = u64::from(y) * u64::from(width) + u64::from(x);
    for (sub, ray) in subpixel_rays(basis, x, y, aa, width, height).enumerate() {
        let t0 = Instant::now();
        let Some(hit) = ctx.primary_hit(&ray) else {
            px.background += env.light.radiance(ray.dir.normalize());
            px.nanos_gbuffer += t0.elapsed().as_nanos() as u64;
            continue;
        };
        if sub == 0 {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let d0 = basis.direction(cx, cy, width, height);
            let d1 = basis.direction(cx + 1.0, cy, width, height);
            let dist = (hit.point.position - basis.eye).length();
            px.surface = hit.receiver.then_some(Surface {
                position: hit.point.position,
                normal: hit.point.normal,
                footprint: dist * (d1 - d0).length(),
            });
        }
        if !hit.receiver {
            px.nanos_gbuffer += t0.elapsed().as_nanos() as u64;
            continue;
        }
        let sp = hit.point;
        let object = sp.object.unwrap_or(0) as usize;
        let rho_pi = ctx.prepared.materials[object].kd / std::f64::consts::PI;
        let stream = pixel_index * u64::from(aa * aa) + sub as u64;
        // The exact method finds E_static on its way (the static objects are subtracted
        // first), the reference needs none; the others read it from the G-buffer pass.
        let e_static = match env.settings.method {
            EnvMethod::Analytic | EnvMethod::Reference => DVec3::ZERO,
            _ => static_irradiance(ctx, env, &sp, &mut s.shading),
        };
        let t1 = Instant::now();
        px.nanos_gbuffer += (t1 - t0).as_nanos() as u64;

        let (e_static, e_occluded) = match env.settings.method {
            EnvMethod::Unshadowed => (e_static, DVec3::ZERO),
            EnvMethod::Analytic => {
                let t = analytic_terms(ctx, env, &sp, None, &mut s.shading, rec);
                px.set_differences += t.set_differences;
                (t.e_static, t.occluded)
            }
            EnvMethod::Rt | EnvMethod::RtUnculled => (
                e_static,
                rt_occluded(ctx, env, &sp, stream, &mut s.cones, &mut px, rec),
            ),
            EnvMethod::Rtao => (
                e_static,
                e_static * (1.0 - ambient_visibility(ctx, env, &sp, stream, &mut px)),
            ),
            EnvMethod::Reference => {
                let (mean, var) = reference_irradiance(ctx, env, &sp, stream);
                if R::ENABLED {
                    rec.environment_sample(&EnvironmentSample {
                        method: env.settings.method,
                        unshadowed: env.light.irradiance(sp.normal),
                        e_static: None,
                        occluded: None,
                        irradiance: mean,
                        stderr: Some(var.map(f64::sqrt)),
                        albedo_over_pi: rho_pi,
                        radiance: rho_pi * mean,
                    });
                }
                px.radiance += rho_pi * mean / k;
                px.variance += rho_pi * rho_pi * var / (k * k);
                px.nanos_occlusion += t1.elapsed().as_nanos() as u64;
                continue;
            }
        };
        px.nanos_occlusion += t1.elapsed().as_nanos() as u64;
        if R::ENABLED {
            let e = shadowed_irradiance(e_static, e_occluded);
            rec.environment_sample(&EnvironmentSample {
                method: env.settings.method,
                unshadowed: env.light.irradiance(sp.normal),
                e_static: Some(e_static),
                occluded: Some(e_occluded),
                irradiance: e,
                stderr: None,
                albedo_over_pi: rho_pi,
                radiance: rho_pi * e,
            });
        }
        px.radiance += rho_pi * shadowed_irradiance(e_static, e_occluded) / k;
        px.base += rho_pi * e_static / k;
        px.occluded += e_occluded / k;
        px.albedo += rho_pi / k;
    }
    px.background /= k;
    px
}

/// What `--env-method analytic` finds at a point: `E_static` and `E_occluded` (002 Eq. 6,
/// computed exactly), with `rates` the rate of `E = E_static − E_occluded`, and the set
/// differences it took. The one composition of the renderer's pass and of the derivative's.
pub(crate) struct AnalyticTerms {
    pub e_static: DVec3,
    pub occluded: DVec3,
    pub rate: DVec3,
    pub set_differences: u32,
}

/// [`AnalyticTerms`] at `sp`.
pub(crate) fn analytic_terms<R: Recorder>(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    sp: &ShadingPoint,
    rates: Option<&crate::shading::EnvironmentRates>,
    scratch: &mut crate::shading::ShadingScratch,
    rec: &mut R,
) -> AnalyticTerms {
    let r = crate::shading::environment_integrals_with_rates(
        &ctx.prepared,
        &env.occluders,
        sp,
        EnvironmentPass::Occluded,
        &|frame: &Frame, poly| env.light.integrate(frame, poly),
        rates,
        scratch,
        rec,
    );
    // Without a static object over the hemisphere, E_static is the unshadowed irradiance,
    // which moves only with the normal.
    let (e_static, static_rate) = match r.static_visible {
        Some(v) => (v, r.static_rate),
        None => (env.light.irradiance(sp.normal), r.unshadowed_rate),
    };
    AnalyticTerms {
        e_static,
        occluded: r.occluded,
        rate: static_rate - r.occluded_rate,
        set_differences: r.set_differences,
    }
}

/// E_static at `sp`: the irradiance the static objects leave (Eq. 6): from the precomputed
/// transfer where it covers the point, else exact; Eq. 7 when no static object reaches the
/// hemisphere.
fn static_irradiance(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    sp: &ShadingPoint,
    scratch: &mut ShadingScratch,
) -> DVec3 {
    let unshadowed = || env.light.irradiance(sp.normal);
    if env.occluders.statics.is_empty() {
        return unshadowed();
    }
    if let (Some(field), Some(o), Some(f)) = (&env.transfer, sp.object, sp.face)
        && let Some(t) = field.transfer(o, f, sp.position, sp.normal)
    {
        return transferred_irradiance(&env.light.sh, &t);
    }
    environment_integrals(
        &ctx.prepared,
        &env.occluders,
        sp,
        EnvironmentPass::StaticOnly,
        &|frame: &Frame, poly| env.light.integrate(frame, poly),
        scratch,
        &mut NoRecorder,
    )
    .static_visible
    .unwrap_or_else(unshadowed)
}

/// Whether the ray from `sp` may be blocked by scene object `o` (face `f`): occluders only,
/// and never the face the point lies on.
#[inline]
fn blocks(ctx: &RenderContext, sp: &ShadingPoint, o: u32, f: u32) -> bool {
    ctx.scene.objects[o as usize].flags.occluder && !(Some(o) == sp.object && Some(f) == sp.face)
}

/// 002 Alg. 1–2 at one sub-pixel sample: cones, culling, rays; E_occluded = π/N Σ L_SH(ω)
/// over the rays whose first hit is a dynamic object (Eq. 8). `rec` receives the cones and
/// every ray, in the shading frame of the area lights (`Frame::from_normal_and_view`).
#[allow(clippy::too_many_arguments)]
fn rt_occluded<R: Recorder>(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    sp: &ShadingPoint,
    stream: u64,
    cones: &mut Vec<Cone>,
    px: &mut EnvPixel,
    rec: &mut R,
) -> DVec3 {
    let culling = env.settings.culling;
    construct_and_merge_cones(sp.position, sp.normal, &env.spheres, cones);
    if let Some(max) = env.settings.max_cones {
        crate::environment::cones::cluster_cones(cones, max);
    }
    // The recording's frame, and the cones of Eq. 4 before merging (for the view only).
    let shading = R::ENABLED.then(|| Frame::from_normal_and_view(sp.normal, sp.view));
    if let Some(f) = &shading {
        let local = |c: &Cone| Cone {
            axis: f.to_local(c.axis),
            ..*c
        };
        let eq4: Vec<Cone> = env
            .spheres
            .iter()
            .filter_map(|s| crate::environment::cones::cone_of_sphere(sp.position, sp.normal, s))
            .map(|c| local(&c))
            .collect();
        let merged: Vec<Cone> = cones.iter().map(local).collect();
        rec.environment_cones(&eq4, &merged);
    }
    px.cones += cones.len() as u32;
    let n = env.samples.len();
    px.rays_total += n as u32;
    // The rays' frame and rotation (a sine and a cosine) are found only when a ray can be
    // traced or the culled rays are recorded: many points have no cone at all.
    let directions = || {
        (
            Frame::from_z(sp.normal),
            pixel_rotation(env.settings.seed, stream),
        )
    };
    if culling != Culling::None && cones.is_empty() {
        if let Some(f) = &shading {
            let (frame, rot) = directions();
            for i in 0..n {
                let dir = frame.to_world(env.samples.rotated(i, rot));
                rec.environment_ray(f.to_local(dir), RayOutcome::Culled);
            }
        }
        return DVec3::ZERO;
    }
    let (frame, rot) = directions();
    let mut sum = DVec3::ZERO;
    for i in 0..n {
        let dir = frame.to_world(env.samples.rotated(i, rot));
        let t_max = match culling {
            Culling::None => f64::INFINITY,
            Culling::Direction | Culling::DirectionAndLength => match ray_extent(cones, dir) {
                None => {
                    if let Some(f) = &shading {
                        rec.environment_ray(f.to_local(dir), RayOutcome::Culled);
                    }
                    continue;
                }
                Some(h) if culling == Culling::DirectionAndLength => h,
                Some(_) => f64::INFINITY,
            },
        };
        px.rays_traced += 1;
        let ray = Ray {
            origin: sp.position,
            dir,
        };
        let hit = ctx
            .bvh
            .intersect_accept(&ray, env.t_min, t_max, |o, f| blocks(ctx, sp, o, f));
        if let Some(f) = &shading {
            let outcome = match hit {
                None => RayOutcome::Escaped,
                Some(h) if ctx.scene.objects[h.object as usize].flags.is_static => {
                    RayOutcome::Static
                }
                Some(_) => RayOutcome::Dynamic,
            };
            rec.environment_ray(f.to_local(dir), outcome);
        }
        if let Some(h) = hit
            && !ctx.scene.objects[h.object as usize].flags.is_static
        {
            sum += env.light.sh_radiance(dir);
        }
    }
    sum * env.samples.weight()
}

/// The fraction of cosine-weighted rays that escape every occluder (RTAO, unbounded).
fn ambient_visibility(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    sp: &ShadingPoint,
    stream: u64,
    px: &mut EnvPixel,
) -> f64 {
    let frame = Frame::from_z(sp.normal);
    let rot = pixel_rotation(env.settings.seed, stream);
    let n = env.samples.len();
    px.rays_total += n as u32;
    px.rays_traced += n as u32;
    let mut open = 0usize;
    for i in 0..n {
        let ray = Ray {
            origin: sp.position,
            dir: frame.to_world(env.samples.rotated(i, rot)),
        };
        if !ctx
            .bvh
            .occluded(&ray, env.t_min, f64::INFINITY, |o, f| blocks(ctx, sp, o, f))
        {
            open += 1;
        }
    }
    open as f64 / n.max(1) as f64
}

/// The reference: E = ∫ L_map(ω) V(ω) cos θ dω by Monte Carlo with the map's importance
/// sampler and a shadow ray per sample; returns the mean and the variance of the mean.
fn reference_irradiance(
    ctx: &RenderContext,
    env: &SceneEnvironment,
    sp: &ShadingPoint,
    stream: u64,
) -> (DVec3, DVec3) {
    let mut rng = Pcg32::new(env.settings.seed, stream);
    let n = env.settings.spp.max(1);
    let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..n {
        let (dir, radiance, pdf) = env.light.sample(rng.next_f64(), rng.next_f64());
        let cos = sp.normal.dot(dir);
        if cos <= 0.0 || pdf <= 0.0 {
            continue;
        }
        let ray = Ray {
            origin: sp.position,
            dir,
        };
        if ctx
            .bvh
            .occluded(&ray, env.t_min, f64::INFINITY, |o, f| blocks(ctx, sp, o, f))
        {
            continue;
        }
        let v = radiance * (cos / pdf);
        sum += v;
        sum2 += v * v;
    }
    let nf = n as f64;
    let mean = sum / nf;
    let var = ((sum2 / nf - mean * mean) / (nf - 1.0).max(1.0)).max(DVec3::ZERO);
    (mean, var)
}
