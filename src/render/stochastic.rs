//! The stochastic methods of `penumbra render`: per pixel the emitted radiance, the analytic
//! unshadowed U (the same `shade` as the analytic renderer, `Method::Unshadowed`), the sums
//! S_N and U_N of the same samples, the variance of S_N and a G-buffer at the pixel centre;
//! then the estimator of the method, per pixel or (denoised methods) over the whole image.

use super::{
    Image, RenderContext, RenderMethod, RenderOutput, RenderSettings, render_tiles, subpixel_rays,
};
use crate::accel::Ray;
use crate::denoise::{
    DenoiseSettings, GBuffer, ratio_bilateral_cancellable, ratio_denoised_cancellable,
};
use crate::math::Pcg32;
use crate::scene::camera::CameraBasis;
use crate::shading::{
    CorrectionSampling, Method, NoRecorder, ShadingScratch, analytic_exact_pixel, shade,
    shade_corrected,
};
use crate::stochastic::{Estimator, EstimatorScratch, combine, direct_samples};
use glam::DVec3;
use std::sync::atomic::AtomicBool;

/// Per-pixel images of a stochastic render (averages over the pixel's camera rays).
#[derive(Clone, Debug, Default)]
pub struct StochasticBuffers {
    /// Radiance emitted toward the eye (lights seen directly).
    pub emitted: Image,
    /// Analytic unshadowed illumination U (zero when the method does not need it); for
    /// `analytic-exact`, the LTC image (exact visibility) whose correction is in `s_n`.
    pub u: Image,
    /// U holds a sampled estimate (`exact_u`): passes average it like S_N instead of keeping
    /// the first pass's.
    pub u_sampled: bool,
    /// S_N and U_N (003 Eq. 21, 22 divided by N).
    pub s_n: Image,
    pub u_n: Image,
    /// Variance of the pixel's S_N (of the mean over all its samples).
    pub s_variance: Image,
    /// Primary hit at the pixel centre: position, normal toward the viewer, world size of one
    /// pixel there, and whether it is a receiver (false: background or not shaded); what the
    /// denoiser's joint-bilateral weights read.
    pub gbuffer: GBuffer,
}

/// Width (standard deviation, pixels) of the fixed bilateral filter of `ratio-bilateral`:
/// 003 Fig. 7 uses a σ = 4-pixel Gaussian for its robustness comparison.
pub(crate) const BILATERAL_SIGMA_PX: f64 = 4.0;

#[derive(Clone, Default)]
struct PixelValues {
    emitted: DVec3,
    u: DVec3,
    s_n: DVec3,
    u_n: DVec3,
    s_var: DVec3,
    position: DVec3,
    normal: DVec3,
    footprint: f64,
    valid: bool,
}

#[derive(Default)]
struct Scratch {
    shading: ShadingScratch,
    estimator: EstimatorScratch,
}

/// Whether the method needs the analytic U.
fn needs_u(method: RenderMethod) -> bool {
    !matches!(method, RenderMethod::Mc | RenderMethod::Reference)
}

/// Renders the per-pixel buffers of a stochastic method; `None` if `cancel` was set.
pub(crate) fn render_buffers(
    ctx: &RenderContext,
    basis: &CameraBasis,
    settings: &RenderSettings,
    cancel: Option<&AtomicBool>,
) -> Option<StochasticBuffers> {
    render_buffers_with(ctx, basis, settings, cancel, needs_u(settings.method))
}

/// [`render_buffers`], computing the analytic U only if `with_u` (it is deterministic, so the
/// later passes of a progressive render take it from the first; U is then left at zero).
pub(crate) fn render_buffers_with(
    ctx: &RenderContext,
    basis: &CameraBasis,
    settings: &RenderSettings,
    cancel: Option<&AtomicBool>,
    with_u: bool,
) -> Option<StochasticBuffers> {
    let (w, h, aa) = (settings.width, settings.height, settings.aa);
    let k = (aa * aa) as f64;
    let values = render_tiles(w, h, cancel, Scratch::default, |scratch, x, y| {
        let mut rng = Pcg32::new(settings.seed, y as u64 * w as u64 + x as u64);
        let mut px = PixelValues::default();
        // With an odd `aa` the middle sub-pixel ray is the pixel-centre ray: its hit is the
        // G-buffer's (no second traversal).
        let centre_index = (aa % 2 == 1).then_some((aa * aa) / 2);
        let mut centre_hit = None;
        for (i, ray) in subpixel_rays(basis, x, y, aa, w, h).enumerate() {
            let hit = ctx.primary_hit(&ray);
            if Some(i as u32) == centre_index {
                centre_hit = Some(hit);
            }
            let Some(hit) = hit else {
                continue;
            };
            px.emitted += hit.emitted;
            if !hit.receiver {
                continue;
            }
            let material = &ctx.prepared.materials[hit.point.object.unwrap_or(0) as usize];
            // Each camera ray its own stream of correction samples.
            let correction = CorrectionSampling {
                samples: settings.spp,
                seed: settings.seed,
                stream: (y as u64 * w as u64 + x as u64) * (aa * aa) as u64 + i as u64,
            };
            if settings.method == RenderMethod::AnalyticExact {
                // The LTC image in U, its correction in S_N: no shadow ray.
                let c = shade_corrected(
                    &ctx.prepared,
                    &hit.point,
                    material,
                    Method::Analytic,
                    &correction,
                    &mut scratch.shading,
                    &mut NoRecorder,
                );
                px.u += c.ltc;
                px.s_n += c.correction;
                px.s_var += c.variance;
                continue;
            }
            if settings.exact_u && with_u {
                px.u += shade_corrected(
                    &ctx.prepared,
                    &hit.point,
                    material,
                    Method::Unshadowed,
                    &correction,
                    &mut scratch.shading,
                    &mut NoRecorder,
                )
                .total();
            } else if with_u {
                px.u += shade(
                    &ctx.prepared,
                    &hit.point,
                    material,
                    Method::Unshadowed,
                    &mut scratch.shading,
                    &mut NoRecorder,
                );
            }
            let sums = direct_samples(
                &ctx.sampled(),
                &hit.point,
                material,
                settings.spp,
                settings.light_sampling,
                &mut rng,
                &mut scratch.estimator,
            );
            px.s_n += sums.s_n();
            px.u_n += sums.u_n();
            px.s_var += sums.s_variance_of_mean();
        }
        px.emitted /= k;
        px.u /= k;
        px.s_n /= k;
        px.u_n /= k;
        px.s_var /= k * k;
        // G-buffer at the pixel centre, with the size of one pixel at the hit.
        let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
        let d0 = basis.direction(cx, cy, w, h);
        let hit = centre_hit.unwrap_or_else(|| {
            ctx.primary_hit(&Ray {
                origin: basis.eye,
                dir: d0,
            })
        });
        if let Some(hit) = hit {
            let d1 = basis.direction(cx + 1.0, cy, w, h);
            let dist = (hit.point.position - basis.eye).length();
            px.position = hit.point.position;
            px.normal = hit.point.normal;
            px.footprint = dist * (d1 - d0).length();
            px.valid = hit.receiver;
        }
        px
    })?;
    let image = |f: &dyn Fn(&PixelValues) -> DVec3| Image {
        width: w,
        height: h,
        pixels: values.iter().map(f).collect(),
    };
    Some(StochasticBuffers {
        u_sampled: settings.exact_u && needs_u(settings.method),
        emitted: image(&|p| p.emitted),
        u: image(&|p| p.u),
        s_n: image(&|p| p.s_n),
        u_n: image(&|p| p.u_n),
        s_variance: image(&|p| p.s_var),
        gbuffer: GBuffer {
            width: w,
            height: h,
            position: values.iter().map(|p| p.position).collect(),
            normal: values.iter().map(|p| p.normal).collect(),
            footprint: values.iter().map(|p| p.footprint).collect(),
            valid: values.iter().map(|p| p.valid).collect(),
        },
    })
}

/// Renders a stochastic method: the buffers, then its estimator.
pub fn render(
    ctx: &RenderContext,
    basis: &CameraBasis,
    settings: &RenderSettings,
    cancel: Option<&AtomicBool>,
) -> RenderOutput {
    let Some(buffers) = render_buffers(ctx, basis, settings, cancel) else {
        // Cancelled: the result is discarded; skip the (uninterruptible) denoiser.
        return RenderOutput {
            image: Image::new(settings.width, settings.height),
            ..RenderOutput::default()
        };
    };
    let mut out = compose(settings.method, &buffers);
    out.buffers = Some(std::sync::Arc::new(buffers));
    out
}

/// Applies the estimator of `method` to the buffers: per pixel, or over the whole image for the
/// denoised methods. Progressive rendering calls it again on buffers averaged over passes.
pub(crate) fn compose(method: RenderMethod, buffers: &StochasticBuffers) -> RenderOutput {
    compose_cancellable(method, buffers, None)
}

/// [`compose`] whose denoiser stops early once `cancel` is set (the output is then incomplete
/// and must be discarded).
pub(crate) fn compose_cancellable(
    method: RenderMethod,
    buffers: &StochasticBuffers,
    cancel: Option<&AtomicBool>,
) -> RenderOutput {
    let (w, h) = (buffers.emitted.width, buffers.emitted.height);
    let per_pixel = |e: Estimator| {
        let pixels = (0..buffers.emitted.pixels.len())
            .map(|i| {
                buffers.emitted.pixels[i]
                    + combine(
                        e,
                        buffers.u.pixels[i],
                        buffers.s_n.pixels[i],
                        buffers.u_n.pixels[i],
                    )
            })
            .collect();
        Image {
            width: w,
            height: h,
            pixels,
        }
    };
    let mut out = RenderOutput::default();
    // The per-pixel standard error of S_N (the reference's, and analytic-exact's correction's).
    let s_stderr = || Image {
        width: w,
        height: h,
        pixels: buffers
            .s_variance
            .pixels
            .iter()
            .map(|v| v.map(f64::sqrt))
            .collect(),
    };
    match method {
        RenderMethod::Mc => out.image = per_pixel(Estimator::FullStochastic),
        RenderMethod::Reference => {
            out.image = per_pixel(Estimator::FullStochastic);
            out.stderr = Some(s_stderr());
        }
        RenderMethod::AnalyticExact => {
            out.image = Image {
                width: w,
                height: h,
                pixels: (0..buffers.u.pixels.len())
                    .map(|i| {
                        analytic_exact_pixel(
                            buffers.emitted.pixels[i],
                            buffers.u.pixels[i],
                            buffers.s_n.pixels[i],
                        )
                    })
                    .collect(),
            };
            out.stderr = Some(s_stderr());
        }
        RenderMethod::ControlVariate => out.image = per_pixel(Estimator::ControlVariate),
        RenderMethod::Ratio => out.image = per_pixel(Estimator::Ratio),
        RenderMethod::RatioGray => out.image = per_pixel(Estimator::RatioGray),
        RenderMethod::RatioDenoised | RenderMethod::RatioBilateral => {
            let g = &buffers.gbuffer;
            let denoise = DenoiseSettings::default();
            let (shading, aovs) = if method == RenderMethod::RatioDenoised {
                ratio_denoised_cancellable(
                    &buffers.u,
                    &buffers.s_n,
                    &buffers.u_n,
                    g,
                    &denoise,
                    cancel,
                )
            } else {
                ratio_bilateral_cancellable(
                    &buffers.u,
                    &buffers.s_n,
                    &buffers.u_n,
                    g,
                    BILATERAL_SIGMA_PX,
                    &denoise,
                    cancel,
                )
            };
            let mut image = shading;
            for (p, e) in image.pixels.iter_mut().zip(&buffers.emitted.pixels) {
                *p += *e;
            }
            out.image = image;
            out.denoise = Some(aovs);
        }
        // Deterministic methods have no stochastic buffers: show U (what they would be shaded
        // with, unshadowed) rather than fail.
        RenderMethod::Analytic | RenderMethod::PerTriangle | RenderMethod::Unshadowed => {
            out.image = Image {
                width: w,
                height: h,
                pixels: (0..buffers.u.pixels.len())
                    .map(|i| buffers.emitted.pixels[i] + buffers.u.pixels[i])
                    .collect(),
            };
        }
    }
    out
}

impl StochasticBuffers {
    /// Folds `next` (another pass with an independent seed and the same sample count) into
    /// `self`, which holds the mean of `passes` passes: S_N, U_N become the mean over all
    /// passes, the variance of S_N that of the mean.
    /// Makes this pass, the (k+1)-th, the running mean of all passes so far, `previous` being
    /// the mean of the first k: S_N, U_N and their variance are averaged; U is taken from
    /// `previous` (deterministic: computed by the first pass only). The fresh pass is turned
    /// into the accumulator, so no buffer of the previous frame (still shown) is copied but U.
    pub(crate) fn accumulate_onto(&mut self, previous: &StochasticBuffers, passes: u32) {
        let k = passes as f64;
        let mean = |a: &mut Image, prev: &Image| {
            for (x, p) in a.pixels.iter_mut().zip(&prev.pixels) {
                *x = (*p * k + *x) / (k + 1.0);
            }
        };
        mean(&mut self.s_n, &previous.s_n);
        mean(&mut self.u_n, &previous.u_n);
        if self.u_sampled {
            mean(&mut self.u, &previous.u);
        }
        // Var(mean of k+1 passes) = (k² Var_k + Var_1) / (k+1)².
        for (x, p) in self
            .s_variance
            .pixels
            .iter_mut()
            .zip(&previous.s_variance.pixels)
        {
            *x = (*p * (k * k) + *x) / ((k + 1.0) * (k + 1.0));
        }
        if !self.u_sampled {
            self.u.pixels.clone_from(&previous.u.pixels);
        }
    }
}
