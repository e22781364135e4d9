//! Progressive rendering for an interactive viewport: the same renderer at 1/8, 1/4, 1/2 and
//! full resolution (a first image in milliseconds), then, for the stochastic methods, more
//! passes with new seeds averaged into the buffers. The analytic methods' levels are
//! interlaced (`super::sample_grid`): each finer level takes over the coarser one's samples,
//! so all of them together cost one full image. Each step is handed to `emit` as soon as it
//! is done; `cancel` stops the work between tiles.

use super::environment_passes::render_environment;
use super::stochastic::{
    StochasticBuffers, compose, compose_cancellable, render_buffers, render_buffers_with,
};
use super::{Coarser, RenderContext, RenderMethod, RenderOutput, RenderSettings, slicing};
use crate::scene::Camera;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::Instant;

/// One step of a progressive render.
#[derive(Clone, Debug)]
pub struct ProgressiveFrame {
    /// The image is `1/scale` of the target size in each direction.
    pub scale: u32,
    /// Passes averaged so far (stochastic methods at full resolution), else 1.
    pub passes: u32,
    /// Samples per camera ray in the image so far.
    pub spp: u32,
    /// Camera rays per pixel of the image (1 in an interlaced preview, else `aa`²).
    pub camera_samples: u32,
    pub output: RenderOutput,
    /// Seconds since the render started.
    pub elapsed: f64,
    /// No more steps will follow.
    pub finished: bool,
    /// False when `output` holds only the stochastic buffers and the estimator (the denoiser)
    /// is still to be applied with [`ProgressiveFrame::compose`].
    pub composed: bool,
}

impl ProgressiveFrame {
    /// Applies the estimator of `method` if it was deferred (see `defer_denoise`).
    pub fn compose(&mut self, method: RenderMethod) {
        self.compose_cancellable(method, None)
    }

    /// [`ProgressiveFrame::compose`] that gives up once `cancel` is set (the frame is then
    /// incomplete and must not be shown).
    pub(crate) fn compose_cancellable(
        &mut self,
        method: RenderMethod,
        cancel: Option<&AtomicBool>,
    ) {
        if self.composed {
            return;
        }
        if let Some(buffers) = self.output.buffers.take() {
            let mut out = compose_cancellable(method, &buffers, cancel);
            out.buffers = Some(buffers);
            out.stats = self.output.stats;
            // The environment's term, rendered beside the buffers, adds to the composed image.
            if let Some(e) = self.output.environment.take() {
                out.add_environment(e);
            }
            self.output = out;
        }
        self.composed = true;
    }
}

/// Levels at least this coarse are previews: one sample per camera ray for the stochastic
/// methods.
pub const PREVIEW_SCALE: u32 = 4;

/// Coarse-to-fine scales for a `width`×`height` target: 8, 4, 2, 1, skipping those that would
/// leave fewer than 32 pixels across.
pub(crate) fn scales(width: u32, height: u32) -> Vec<u32> {
    let mut v: Vec<u32> = [8, 4, 2]
        .into_iter()
        .filter(|&s| width / s >= 32 && height / s >= 32)
        .collect();
    v.push(1);
    v
}

/// Renders progressively until `max_passes` passes (stochastic methods) or the full-resolution
/// image (deterministic ones), or until `cancel` is set. Returns the last frame emitted.
pub fn render_progressive(
    ctx: &RenderContext,
    camera: &Camera,
    settings: &RenderSettings,
    max_passes: u32,
    cancel: &AtomicBool,
    emit: impl FnMut(&ProgressiveFrame),
) -> crate::Result<Option<ProgressiveFrame>> {
    render_progressive_with(ctx, camera, settings, max_passes, cancel, false, emit)
}

/// [`render_progressive`], optionally leaving the whole-image denoiser of the denoised methods
/// to the caller (`defer_denoise`): frames then come with `composed == false`, and the render
/// loop never blocks on the denoiser, so a cancelled render stops within one tile.
pub fn render_progressive_with(
    ctx: &RenderContext,
    camera: &Camera,
    settings: &RenderSettings,
    max_passes: u32,
    cancel: &AtomicBool,
    defer_denoise: bool,
    mut emit: impl FnMut(&ProgressiveFrame),
) -> crate::Result<Option<ProgressiveFrame>> {
    let denoised = matches!(
        settings.method,
        RenderMethod::RatioDenoised | RenderMethod::RatioBilateral
    );
    let defer = defer_denoise && denoised;
    let start = Instant::now();
    let stop = || cancel.load(Ordering::Relaxed);
    let mut last = None;
    let all = scales(settings.width, settings.height);
    for (k, &scale) in all.iter().enumerate() {
        if stop() {
            return Ok(last);
        }
        // The coarsest previews of a stochastic method take one sample per camera ray: what
        // matters there is how soon the new view appears (the status bar shows the spp).
        // analytic-exact previews are the LTC image (no correction sample): the LTC first,
        // then passes converging to GGX.
        let spp = if scale >= PREVIEW_SCALE {
            u32::from(settings.method != RenderMethod::AnalyticExact)
        } else {
            settings.spp
        };
        let s = RenderSettings {
            width: (settings.width / scale).max(1),
            height: (settings.height / scale).max(1),
            spp,
            ..*settings
        };
        // An interlaced level is described by the full image's size and its stride.
        let s_level = RenderSettings { spp, ..*settings };
        // Coarse levels are small enough to denoise at once: only full resolution is deferred.
        let defer_level = defer && scale == 1;
        // A step of its own: a sliced render (the browser's) does each level once, and skips
        // it once a finer level is done (`None`).
        let Some(output) = slicing::step(|| -> crate::Result<Option<RenderOutput>> {
            if !defer_level {
                // The analytic methods' levels are interlaced: each takes over the samples
                // of the coarser one before it (`super::sample_grid`).
                let coarser = last.as_ref().map(|f: &ProgressiveFrame| Coarser {
                    stride: f.scale,
                    output: &f.output,
                });
                let level = ctx.render_level(camera, &s_level, scale, coarser, Some(cancel));
                return level
                    .unwrap_or_else(|| ctx.render_full(camera, &s, Some(cancel)))
                    .map(Some);
            }
            let basis = camera.basis()?;
            let Some(buffers) = render_buffers(ctx, &basis, &s, Some(cancel)) else {
                return Ok(None);
            };
            // The environment's term is added when the frame is composed.
            let environment = match &ctx.environment {
                Some(env) => {
                    let Some(e) =
                        render_environment(ctx, env, &basis, s.width, s.height, s.aa, Some(cancel))
                    else {
                        return Ok(None);
                    };
                    Some(e)
                }
                None => None,
            };
            Ok(Some(RenderOutput {
                buffers: Some(Arc::new(buffers)),
                environment,
                ..RenderOutput::default()
            }))
        }) else {
            continue;
        };
        let Some(output) = output? else {
            return Ok(last);
        };
        if stop() {
            return Ok(last);
        }
        let full = k + 1 == all.len();
        let interlaced_preview = scale > 1 && ctx.interlaces(settings);
        let frame = ProgressiveFrame {
            scale,
            passes: 1,
            spp: s.spp,
            camera_samples: if interlaced_preview {
                1
            } else {
                settings.aa * settings.aa
            },
            output,
            elapsed: start.elapsed().as_secs_f64(),
            finished: full && (!settings.method.is_stochastic() || max_passes <= 1),
            composed: !defer_level,
        };
        emit(&frame);
        last = Some(frame);
    }
    if !settings.method.is_stochastic() || max_passes <= 1 {
        return Ok(last);
    }
    let basis = camera.basis()?;
    let Some(mut acc): Option<Arc<StochasticBuffers>> =
        last.as_ref().and_then(|f| f.output.buffers.clone())
    else {
        return Ok(last);
    };
    // The environment's term does not change from pass to pass (its rays depend on the
    // environment's own seed, not the pass's): the first pass's is added to every later one.
    let environment = last.as_ref().and_then(|f| f.output.environment.clone());
    for pass in 1..max_passes {
        if stop() {
            break;
        }
        let s = RenderSettings {
            seed: settings.seed.wrapping_add(pass as u64 * 0x9e37_79b9),
            ..*settings
        };
        // The pass's sums and its image (if it shows one), as one step: a sliced render
        // (the browser's) does each pass once, and skips it once a later pass is done.
        let Some(pass_result) = slicing::step(|| {
            // U is deterministic: the first pass computed it, the others take it from there.
            // (A sampled U, `exact_u`, is averaged like S_N instead.)
            let mut next = render_buffers_with(ctx, &basis, &s, Some(cancel), s.exact_u)?;
            next.accumulate_onto(&acc, pass);
            let acc = Arc::new(next);
            // Denoising the whole image cannot be interrupted: unless the caller takes it
            // over, compose the denoised methods only after passes 2, 4, 8, … and the last,
            // so that a change of view rarely waits for it (the other estimators are per
            // pixel and cheap).
            let last_pass = pass + 1 == max_passes;
            if denoised && !defer && !(pass + 1).is_power_of_two() && !last_pass {
                return Some((acc, None));
            }
            let output = if defer {
                RenderOutput {
                    buffers: Some(acc.clone()),
                    environment: environment.clone(),
                    ..RenderOutput::default()
                }
            } else {
                let mut output = compose(settings.method, &acc);
                output.buffers = Some(acc.clone());
                if let Some(e) = &environment {
                    output.add_environment(e.clone());
                }
                output
            };
            Some((acc, Some(output)))
        }) else {
            continue;
        };
        let Some((summed, output)) = pass_result else {
            break;
        };
        acc = summed;
        let Some(output) = output else {
            continue;
        };
        let frame = ProgressiveFrame {
            scale: 1,
            passes: pass + 1,
            spp: settings.spp * (pass + 1),
            camera_samples: settings.aa * settings.aa,
            output,
            elapsed: start.elapsed().as_secs_f64(),
            finished: pass + 1 == max_passes,
            composed: !defer,
        };
        emit(&frame);
        last = Some(frame);
    }
    Ok(last)
}

/// A progressive render of the analytic image's derivative along `motion`
/// ([`RenderContext::render_derivative`]): the levels of [`render_progressive`] at strides 8,
/// 4, 2 and 1 (`RenderContext::render_derivative_level`), each frame's output holding the
/// image and, in `derivative`, the rate and its mask. What the derivative refuses (a method
/// other than `analytic`, an environment light) is an error before any frame.
pub fn render_progressive_derivative(
    ctx: &RenderContext,
    camera: &Camera,
    settings: &RenderSettings,
    motion: &crate::shading::derivative::Motion,
    cancel: &AtomicBool,
    mut emit: impl FnMut(&ProgressiveFrame),
) -> crate::Result<Option<ProgressiveFrame>> {
    let start = Instant::now();
    let stop = || cancel.load(Ordering::Relaxed);
    // The scene moved by ±FD_STEP, once for every level (a sliced render keeps it).
    let Some(setup) = slicing::step(|| ctx.derivative_setup(settings, motion)) else {
        return Ok(None);
    };
    let setup = setup?;
    let mut last = None;
    let all = scales(settings.width, settings.height);
    for (k, &scale) in all.iter().enumerate() {
        if stop() {
            return Ok(last);
        }
        let Some(level) = slicing::step(|| {
            ctx.render_derivative_level(camera, settings, &setup, scale, Some(cancel))
        }) else {
            continue;
        };
        if stop() {
            return Ok(last);
        }
        let out = level?;
        let full = k + 1 == all.len();
        let frame = ProgressiveFrame {
            scale,
            passes: 1,
            spp: settings.spp,
            camera_samples: if full { settings.aa * settings.aa } else { 1 },
            output: RenderOutput {
                image: out.image,
                derivative: Some(super::derivative::DerivativeImages {
                    motion: *motion,
                    derivative: out.derivative,
                    mask: out.mask,
                    masked: out.masked,
                }),
                stats: out.stats,
                ..RenderOutput::default()
            },
            elapsed: start.elapsed().as_secs_f64(),
            finished: full,
            composed: true,
        };
        emit(&frame);
        last = Some(frame);
    }
    Ok(last)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::SampleGrid;
    use crate::scene::scene_file;
    use crate::shading::NoRecorder;

    #[test]
    fn coarse_to_fine_ends_with_the_full_render() {
        let scene = scene_file::load_embedded("fig4").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let settings = RenderSettings {
            width: 128,
            height: 96,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let mut seen = Vec::new();
        let last = render_progressive(&ctx, &cam, &settings, 1, &cancel, |f| {
            seen.push((f.scale, f.output.image.width))
        })
        .unwrap()
        .unwrap();
        assert_eq!(seen, vec![(2, 64), (1, 128)]);
        let direct = ctx.render(&cam, &settings, None).unwrap().0;
        assert_eq!(last.output.image.pixels, direct.pixels);
        assert!(last.finished);
    }

    /// The analytic levels are interlaced: each preview pixel is sample 0 of a full pixel,
    /// computed along that sample's own camera ray (checked against shading that ray alone),
    /// and the last level, which takes those samples over, is the one-shot render bit for bit.
    /// Sizes that the strides do not divide and `--aa 2` included.
    #[test]
    fn interlaced_levels_are_samples_of_the_full_render() {
        let scene = scene_file::load_embedded("fig4").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let basis = cam.basis().unwrap();
        for (width, height, aa) in [(263, 197, 1), (131, 130, 2)] {
            let settings = RenderSettings {
                width,
                height,
                aa,
                ..RenderSettings::default()
            };
            let cancel = AtomicBool::new(false);
            let mut levels = Vec::new();
            let last = render_progressive(&ctx, &cam, &settings, 1, &cancel, |f| {
                levels.push((f.scale, f.output.image.clone()))
            })
            .unwrap()
            .unwrap();
            assert!(levels.len() >= 2, "{levels:?}");
            let mut scratch = crate::shading::ShadingScratch::default();
            for (scale, image) in &levels[..levels.len() - 1] {
                let grid = SampleGrid {
                    stride: *scale,
                    ..SampleGrid::full(width, height, aa)
                };
                assert_eq!((image.width, image.height), grid.size());
                let mut lit = 0;
                for (i, j) in [
                    (0, 0),
                    (image.width / 2, image.height / 2),
                    (image.width - 1, 7),
                ] {
                    let ray = grid.rays(&basis, i, j).next().unwrap();
                    let alone = ctx.radiance(
                        &ray,
                        crate::shading::Method::Analytic,
                        &mut scratch,
                        &mut NoRecorder,
                    );
                    let shown = image.pixels[(j * image.width + i) as usize];
                    assert!(
                        (alone - shown).abs().max_element() <= 1e-12 * alone.length().max(1e-300)
                    );
                    lit += (alone.max_element() > 0.0) as u32;
                }
                assert!(lit > 0);
            }
            let direct = ctx.render_full(&cam, &settings, None).unwrap();
            assert_eq!(last.output.image.pixels, direct.image.pixels);
            assert_eq!(last.output.violations, direct.violations);
            assert_eq!(last.output.fallbacks, direct.fallbacks);
        }
    }

    /// The derivative's levels are samples of the full derivative: each preview pixel is
    /// sample 0 of a full pixel at `--aa 1`, the same per-sample work on the same camera ray
    /// (rate, value and mask), and the last level is `render_derivative` bit for bit.
    #[test]
    fn derivative_levels_are_samples_of_the_full_derivative() {
        use crate::shading::derivative::Axis;
        let scene = scene_file::load_embedded("default").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let sphere = scene
            .objects
            .iter()
            .position(|o| o.name == "sphere")
            .unwrap();
        let motion = ctx.motion(sphere, Axis::Tx).unwrap();
        let settings = RenderSettings {
            width: 136,
            height: 130,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let mut levels = Vec::new();
        let last = render_progressive_derivative(&ctx, &cam, &settings, &motion, &cancel, |f| {
            levels.push((f.scale, f.output.clone()))
        })
        .unwrap()
        .unwrap();
        assert_eq!(
            levels.iter().map(|l| l.0).collect::<Vec<_>>(),
            vec![4, 2, 1]
        );
        let direct = ctx
            .render_derivative(&cam, &settings, &motion, None)
            .unwrap();
        let d = last.output.derivative.as_ref().expect("a derivative");
        assert_eq!(d.derivative.pixels, direct.derivative.pixels);
        assert_eq!(d.mask.pixels, direct.mask.pixels);
        assert_eq!(last.output.image.pixels, direct.image.pixels);
        assert!(d.derivative.pixels.iter().any(|p| p.x > 0.0));
        assert!(d.derivative.pixels.iter().any(|p| p.x < 0.0));
        for (scale, out) in &levels[..2] {
            let preview = out.derivative.as_ref().unwrap();
            let (w, h) = (
                settings.width.div_ceil(*scale),
                settings.height.div_ceil(*scale),
            );
            assert_eq!(
                (preview.derivative.width, preview.derivative.height),
                (w, h)
            );
            for j in 0..h {
                for i in 0..w {
                    let full = ((j * scale) * settings.width + i * scale) as usize;
                    let here = (j * w + i) as usize;
                    let (a, b) = (
                        preview.derivative.pixels[here],
                        direct.derivative.pixels[full],
                    );
                    assert!(
                        (a - b).abs().max_element() <= 1e-12 * b.abs().max_element().max(1e-300),
                        "({i}, {j}) at 1/{scale}: {a} against {b}"
                    );
                    assert_eq!(preview.mask.pixels[here], direct.mask.pixels[full]);
                }
            }
        }
        // The plain image's progressive render carries no derivative.
        let plain = render_progressive(&ctx, &cam, &settings, 1, &cancel, |_| {})
            .unwrap()
            .unwrap();
        assert!(plain.output.derivative.is_none());
    }

    /// Deferring the denoiser changes nothing but who runs it: composing a deferred frame gives
    /// the same image, bit for bit.
    #[test]
    fn deferred_denoising_composes_to_the_same_image() {
        let scene = scene_file::load_embedded("default").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let settings = RenderSettings {
            width: 64,
            height: 48,
            method: RenderMethod::RatioDenoised,
            spp: 2,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let direct = render_progressive(&ctx, &cam, &settings, 4, &cancel, |_| {})
            .unwrap()
            .unwrap();
        let mut deferred = render_progressive_with(&ctx, &cam, &settings, 4, &cancel, true, |f| {
            assert_eq!(f.composed, f.scale > 1)
        })
        .unwrap()
        .unwrap();
        deferred.compose(settings.method);
        assert_eq!(deferred.output.image.pixels, direct.output.image.pixels);
    }

    /// Later passes take U from the first (it is deterministic) instead of computing it again:
    /// after several passes U is still, bit for bit, the U of a one-shot render, and a
    /// cancelled render returns at once with nothing assembled.
    #[test]
    fn later_passes_keep_the_first_pass_u() {
        let scene = scene_file::load_embedded("default").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let settings = RenderSettings {
            width: 40,
            height: 30,
            method: RenderMethod::Ratio,
            spp: 2,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let last = render_progressive(&ctx, &cam, &settings, 5, &cancel, |_| {})
            .unwrap()
            .unwrap();
        assert_eq!(last.passes, 5);
        let one_shot = ctx.render_full(&cam, &settings, None).unwrap();
        let (a, b) = (last.output.buffers.unwrap(), one_shot.buffers.unwrap());
        assert!(a.u.pixels.iter().any(|p| p.max_element() > 0.0));
        assert_eq!(a.u.pixels, b.u.pixels);

        cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        let basis = cam.basis().unwrap();
        assert!(render_buffers(&ctx, &basis, &settings, Some(&cancel)).is_none());
    }

    /// Averaging passes with independent seeds is the same estimator with more samples: the
    /// MSE against the analytic image (exact on this Lambertian scene) falls by about the
    /// number of passes.
    #[test]
    fn passes_average_like_more_samples() {
        let scene = scene_file::load_embedded("chair").unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let base = RenderSettings {
            width: 48,
            height: 36,
            ..RenderSettings::default()
        };
        let exact = ctx.render(&cam, &base, None).unwrap().0;
        let settings = RenderSettings {
            method: RenderMethod::Mc,
            spp: 4,
            ..base
        };
        let cancel = AtomicBool::new(false);
        let mut mse = Vec::new();
        render_progressive(&ctx, &cam, &settings, 16, &cancel, |f| {
            if f.scale == 1 {
                let e: f64 = f
                    .output
                    .image
                    .pixels
                    .iter()
                    .zip(&exact.pixels)
                    .map(|(a, b)| (*a - *b).length_squared())
                    .sum();
                mse.push((f.passes, e));
            }
        })
        .unwrap();
        let (p1, e1) = mse[0];
        let (p16, e16) = *mse.last().unwrap();
        assert_eq!((p1, p16), (1, 16));
        let gain = e1 / e16;
        assert!(
            (8.0..32.0).contains(&gain),
            "MSE fell by {gain} over 16 passes"
        );
    }
}
