//! An image and its exact derivative along the rigid motion of one object
//! (`penumbra render --derivative OBJECT:AXIS`, docs/derivatives.md): the analytic image of
//! [`RenderContext::render_full`], each camera sample shaded by the same stages, with the rate
//! of its radiance from the visible polygons they found (`shading::shade_with_rate`).
//!
//! A pixel is *masked* where the derivative of its value is not the mean of its samples'
//! rates, or not a slope at all: its samples see more than one face (primary visibility and
//! faceted normals are steps), a sample's face changes within the finite-difference step
//! [`FD_STEP`] (found by casting the sample's ray into the scene moved by ±`FD_STEP`), the LTC
//! lookup crosses a table node within the step (where the interpolated table's rate jumps),
//! an edge of a visible polygon had no support though it may move, or the point's rates are
//! degenerate. Masked pixels keep their computed value and are counted by reason.

use super::{Image, RenderContext, RenderSettings, RenderStats, SampleGrid, render_tiles};
use crate::Choice;
use crate::figure::font::{Align, TextStyle, draw_text};
use crate::scene::Camera;
use crate::shading::derivative::{Axis, FD_STEP, Motion, PointMotion};
use crate::shading::{Method, NoRecorder, ShadingScratch, shade_with_rate};
use glam::DVec3;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use web_time::Instant;

/// Why pixels were masked, counted once per pixel under the first reason that applies (in
/// this order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct MaskCounts {
    /// Pixels masked in all.
    pub pixels: u64,
    /// Samples of the pixel see more than one face (object and plane).
    pub several_faces: u64,
    /// A sample's face changes within the finite-difference step.
    pub face_changes: u64,
    /// A sample's rates are degenerate (a grazing camera ray; the view along a turning normal).
    pub degenerate: u64,
    /// An edge of a visible polygon had no support though it may move.
    pub unsupported: u64,
    /// A sample's LTC lookup crosses a table node within the step.
    pub table_nodes: u64,
}

/// A render with its derivative.
#[derive(Clone, Debug)]
pub struct DerivativeOutput {
    pub image: Image,
    /// `d image / dθ`, per scene unit (translations) or per radian (`ry`).
    pub derivative: Image,
    /// 1 (in every channel) where the pixel is masked, 0 elsewhere.
    pub mask: Image,
    pub masked: MaskCounts,
    pub stats: RenderStats,
}

#[derive(Clone, Copy, Default)]
struct PixelRate {
    value: DVec3,
    rate: DVec3,
    /// 0: not masked; else 1 + the index of the reason in [`MaskCounts`]'s order.
    reason: u8,
}

impl RenderContext {
    /// The motion of scene object `object` along `axis`, rotations about the centre of its
    /// bounding box (as `penumbra edit` turns it).
    pub fn motion(&self, object: usize, axis: Axis) -> crate::Result<Motion> {
        let pivot = crate::scene::edit::EditHistory::new(&self.scene).pivot(object)?;
        Ok(Motion {
            object: object as u32,
            axis,
            pivot,
        })
    }

    /// This context with `motion`'s object moved to θ = `theta`.
    pub fn moved_by(&self, motion: &Motion, theta: f64) -> crate::Result<RenderContext> {
        let mut scene = (*self.scene).clone();
        let rigid = motion.at(theta);
        let index = motion.object as usize;
        let mut history = crate::scene::edit::EditHistory::new(&scene);
        history.edit(&mut scene, index, rigid)?;
        self.with_moved_object(index, Arc::new(scene))
    }

    /// The analytic image seen by `camera` and its derivative along `motion` (module docs).
    /// Only `--method analytic` has one; a scene with an environment light is refused, since
    /// the environment's derivative is not computed.
    pub fn render_derivative(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        motion: &Motion,
        cancel: Option<&AtomicBool>,
    ) -> crate::Result<DerivativeOutput> {
        let setup = self.derivative_setup(settings, motion)?;
        self.render_derivative_level(camera, settings, &setup, 1, cancel)
    }

    /// Why this context has no derivative for `method`, if it has none: the one place that
    /// says what the derivative covers (`--method analytic`, and an environment only with
    /// `--env-method analytic`).
    pub fn derivative_refusal(&self, method: super::RenderMethod) -> crate::Result<()> {
        if method.analytic() != Some(Method::Analytic) {
            return Err(format!(
                "a derivative is computed with --method analytic only, not {}",
                method.name()
            )
            .into());
        }
        if let Some(env) = &self.environment
            && env.settings.method != crate::environment::EnvMethod::Analytic
        {
            return Err(format!(
                "a derivative of the environment light's term is computed with --env-method \
                 analytic only, not {}",
                env.settings.method.name()
            )
            .into());
        }
        Ok(())
    }

    /// What every level of a derivative along `motion` shares: the checks of
    /// [`RenderContext::render_derivative`] (an error names what is refused) and the scene
    /// moved by ±[`FD_STEP`], which the masks cast the samples' rays into.
    pub fn derivative_setup(
        &self,
        settings: &RenderSettings,
        motion: &Motion,
    ) -> crate::Result<DerivativeSetup> {
        self.derivative_refusal(settings.method)?;
        if motion.object as usize >= self.scene.objects.len() {
            return Err(format!("no object {} in the scene", motion.object).into());
        }
        Ok(DerivativeSetup {
            motion: *motion,
            plus: Arc::new(self.moved_by(motion, FD_STEP)?),
            minus: Arc::new(self.moved_by(motion, -FD_STEP)?),
            reach: self.moving_reach(motion),
        })
    }

    /// One level of a progressive derivative (`render::sample_grid`): at `stride` 1 every
    /// sample of every pixel ([`RenderContext::render_derivative`]), at a stride s > 1 sample
    /// 0 of every s-th pixel each way, an image ⌈w/s⌉ × ⌈h/s⌉ whose pixels are the full
    /// image's samples, shaded and masked by the same per-sample work. `Err("cancelled")`
    /// once `cancel` is set.
    pub fn render_derivative_level(
        &self,
        camera: &Camera,
        settings: &RenderSettings,
        setup: &DerivativeSetup,
        stride: u32,
        cancel: Option<&AtomicBool>,
    ) -> crate::Result<DerivativeOutput> {
        let basis = camera.basis()?;
        let (w, h, aa) = (settings.width, settings.height, settings.aa);
        if w == 0 || h == 0 || aa == 0 || stride == 0 {
            return Err("image size and --aa must be positive".into());
        }
        let start = Instant::now();
        let grid = SampleGrid {
            stride,
            ..SampleGrid::full(w, h, aa)
        };
        let (gw, gh) = grid.size();
        let inv = 1.0 / grid.samples() as f64;
        let pixels = render_tiles(gw, gh, cancel, ShadingScratch::default, |scratch, x, y| {
            let mut out = PixelRate::default();
            let mut first: Option<(u32, DVec3, f64)> = None;
            for ray in grid.rays(&basis, x, y) {
                let sample = self.sample_rate(setup, &ray, &mut first, scratch);
                let (emitted, shaded, rate, reason) = sample;
                // In the order the one-shot derivative always summed them.
                out.value += emitted;
                out.value += shaded;
                out.rate += rate;
                if reason != 0 && (out.reason == 0 || reason < out.reason) {
                    out.reason = reason;
                }
            }
            out.value *= inv;
            out.rate *= inv;
            out
        });
        let Some(pixels) = pixels else {
            return Err("cancelled".into());
        };
        let image = |f: &dyn Fn(&PixelRate) -> DVec3| Image {
            width: gw,
            height: gh,
            pixels: pixels.iter().map(f).collect(),
        };
        let mut masked = MaskCounts::default();
        for p in &pixels {
            let count = match p.reason {
                0 => continue,
                1 => &mut masked.several_faces,
                2 => &mut masked.face_changes,
                3 => &mut masked.degenerate,
                4 => &mut masked.unsupported,
                _ => &mut masked.table_nodes,
            };
            *count += 1;
            masked.pixels += 1;
        }
        let seconds = start.elapsed().as_secs_f64();
        Ok(DerivativeOutput {
            image: image(&|p| p.value),
            derivative: image(&|p| p.rate),
            mask: image(&|p| DVec3::splat(if p.reason > 0 { 1.0 } else { 0.0 })),
            masked,
            stats: RenderStats {
                seconds,
                pixels_per_second: (gw * gh) as f64 / seconds.max(1e-12),
                ..RenderStats::default()
            },
        })
    }

    /// One camera sample of a derivative: the radiance it sees emitted and shaded, its rate,
    /// and the first reason (in
    /// [`MaskCounts`]' order, 1-based; 0 for none) that masks its pixel. `first` is the face
    /// the pixel's first sample saw (the samples after it compare theirs with it).
    fn sample_rate(
        &self,
        setup: &DerivativeSetup,
        ray: &crate::accel::Ray,
        first: &mut Option<(u32, DVec3, f64)>,
        scratch: &mut ShadingScratch,
    ) -> (DVec3, DVec3, DVec3, u8) {
        let mut reason = 0u8;
        let mut flag = |r: u8| {
            if reason == 0 || r < reason {
                reason = r;
            }
        };
        let hit = self.primary_hit(ray);
        let key = |c: &RenderContext| c.primary_hit(ray).map(|h| (h.point.object, h.point.face));
        let here = hit.as_ref().map(|h| (h.point.object, h.point.face));
        // A ray can change face within the step only where it passes the moving object's
        // bounding sphere grown by the step's largest displacement.
        if setup.reach.is_none_or(|(c, r)| ray_meets_ball(ray, c, r))
            && (key(&setup.plus) != here || key(&setup.minus) != here)
        {
            flag(2);
        }
        let Some(hit) = hit else {
            // A sample that sees nothing steps against one that sees a face, not against
            // another that sees nothing.
            let nothing = (u32::MAX, DVec3::ZERO, 0.0);
            if first.is_some_and(|f| f != nothing) {
                flag(1);
            }
            first.get_or_insert(nothing);
            // The environment seen past the scene does not move.
            let sky = self
                .environment
                .as_ref()
                .map_or(DVec3::ZERO, |env| env.light.radiance(ray.dir.normalize()));
            return (sky, DVec3::ZERO, DVec3::ZERO, reason);
        };
        let p = &hit.point;
        let face = (
            p.object.unwrap_or(u32::MAX),
            p.normal,
            p.normal.dot(p.position),
        );
        match *first {
            None => *first = Some(face),
            Some(f) => {
                let scale = p.position.abs().max_element().max(1.0);
                if f.0 != face.0
                    || f.1.dot(face.1) < 1.0 - 1e-12
                    || (f.2 - face.2).abs() > 1e-9 * scale
                {
                    flag(1);
                }
            }
        }
        let (mut shaded, mut rate) = (DVec3::ZERO, DVec3::ZERO);
        if hit.receiver {
            let pm = PointMotion::at(&setup.motion, p, ray.dir);
            if pm.degenerate {
                flag(3);
            }
            let material = &self.prepared.materials[p.object.unwrap_or(0) as usize];
            let (l, r) = shade_with_rate(
                &self.prepared,
                p,
                material,
                Method::Analytic,
                &pm,
                scratch,
                &mut NoRecorder,
            );
            let notes = scratch.rate_notes();
            if notes.unsupported > 0 {
                flag(4);
            }
            if notes.near_table_node {
                flag(5);
            }
            shaded = l;
            rate = r;
            if let Some(env) = self.environment_term_rate(p, &pm, scratch) {
                if env.unsupported {
                    flag(4);
                }
                shaded += env.radiance;
                rate += env.rate;
            }
        }
        (hit.emitted, shaded, rate, reason)
    }
}

/// The environment's term at a camera sample with a derivative: its radiance `ρ/π · E`, its
/// rate, and what masks it.
pub(crate) struct EnvironmentTermRate {
    pub radiance: DVec3,
    pub rate: DVec3,
    pub unsupported: bool,
}

impl RenderContext {
    /// The environment's term at `p` and its rate ([`EnvironmentTermRate`]), `None` without an
    /// environment: what the derivative's sample and the probe add to the area lights'.
    pub(crate) fn environment_term_rate(
        &self,
        p: &crate::shading::ShadingPoint,
        pm: &PointMotion,
        scratch: &mut ShadingScratch,
    ) -> Option<EnvironmentTermRate> {
        let env = self.environment.as_ref()?;
        let (e, de) = self.environment_rate(env, p, pm, scratch);
        let kd = self.prepared.materials[p.object.unwrap_or(0) as usize].kd;
        let rho_pi = kd / std::f64::consts::PI;
        Some(EnvironmentTermRate {
            radiance: rho_pi * e,
            rate: rho_pi * de,
            unsupported: scratch.rate_notes().unsupported > 0,
        })
    }

    /// The environment's irradiance at `p` as `--env-method analytic` shades it
    /// (`E = E_static − E_occluded`, 002 Eq. 6) and its rate along the motion.
    fn environment_rate(
        &self,
        env: &super::environment_passes::SceneEnvironment,
        p: &crate::shading::ShadingPoint,
        pm: &PointMotion,
        scratch: &mut ShadingScratch,
    ) -> (DVec3, DVec3) {
        use crate::shading::{EnvironmentRates, shadowed_irradiance};
        let frame = crate::math::Frame::from_normal_and_view(p.normal, p.view);
        let radiance = |local: DVec3| env.light.sh.eval(frame.to_world(local));
        // The frame's angular velocity, ½ Σ eᵢ × ėᵢ (ėᵢ = Ω × eᵢ), in its own coordinates:
        // the radiance at a fixed local direction turns with it (`Quadratic::rotation_rate`).
        let f = &pm.frame_rate;
        let omega = 0.5 * (frame.x.cross(f.x) + frame.y.cross(f.y) + frame.z.cross(f.z));
        let rate_of_radiance = env
            .light
            .sh
            .local_quadratic(frame.world_to_local())
            .rotation_rate(frame.to_local(omega));
        let turning = |poly: &crate::geometry::SphericalPolygon| {
            let m = crate::environment::PolygonMoments::of_loops(poly.loops(), DVec3::Z);
            crate::environment::cosine_weighted_integral_local(&rate_of_radiance, &m)
        };
        let rates = EnvironmentRates {
            point: pm,
            radiance: &radiance,
            turning: (omega != DVec3::ZERO).then_some(&turning as _),
        };
        let t = super::environment_passes::analytic_terms(
            self,
            env,
            p,
            Some(&rates),
            scratch,
            &mut NoRecorder,
        );
        (shadowed_irradiance(t.e_static, t.occluded), t.rate)
    }
}

/// What the levels of one derivative share ([`RenderContext::derivative_setup`]): the motion,
/// and the scene moved by ±[`FD_STEP`] along it.
#[derive(Clone)]
pub struct DerivativeSetup {
    pub motion: Motion,
    plus: Arc<RenderContext>,
    minus: Arc<RenderContext>,
    /// A ball holding the moving object within the step (`moving_reach`).
    reach: Option<(DVec3, f64)>,
}

/// A derivative as a progressive frame carries it (`RenderOutput::derivative`): the motion,
/// the rate image and the mask at the frame's resolution, and the masked pixels by reason.
#[derive(Clone, Debug)]
pub struct DerivativeImages {
    pub motion: Motion,
    pub derivative: Image,
    pub mask: Image,
    pub masked: MaskCounts,
}

impl RenderContext {
    /// A ball that holds the moving object at every θ within ±`FD_STEP` (with a margin), or
    /// `None` when the object has no bounds.
    fn moving_reach(&self, motion: &Motion) -> Option<(DVec3, f64)> {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &self
            .scene
            .objects
            .get(motion.object as usize)?
            .mesh
            .positions
        {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if lo.x > hi.x || lo.x.is_nan() {
            return None;
        }
        let centre = 0.5 * (lo + hi);
        let radius = 0.5 * (hi - lo).length();
        let speed = match motion.axis {
            Axis::Ry => (centre - motion.pivot).length() + radius,
            _ => 1.0,
        };
        let scale = centre.abs().max_element().max(radius).max(1.0);
        Some((centre, radius + 2.0 * FD_STEP * speed + 1e-9 * scale))
    }
}

/// Whether the ray (from its origin on) passes within `r` of `c`.
fn ray_meets_ball(ray: &crate::accel::Ray, c: DVec3, r: f64) -> bool {
    let d = ray.dir.normalize_or_zero();
    let oc = c - ray.origin;
    let t = oc.dot(d).max(0.0);
    (oc - d * t).length_squared() <= r * r
}

/// The derivative `OBJECT:AXIS` names in `ctx`'s scene: an object's index or unique name,
/// and one of [`Axis::names`].
pub fn parse_motion(ctx: &RenderContext, spec: &str) -> crate::Result<Motion> {
    let (object, axis) = spec.rsplit_once(':').ok_or_else(|| {
        crate::Error::from(format!(
            "--derivative takes OBJECT:AXIS with AXIS one of {}, got '{spec}'",
            Axis::names().collect::<Vec<_>>().join(", ")
        ))
    })?;
    let axis = Axis::named(axis).ok_or_else(|| {
        crate::Error::from(format!(
            "--derivative: no axis '{axis}' (one of {})",
            Axis::names().collect::<Vec<_>>().join(", ")
        ))
    })?;
    let index = crate::scene::edit::resolve_object(&ctx.scene, object)?;
    ctx.motion(index, axis)
}

/// The derivative's luminance as a PNG in a diverging colour map (blue below zero, white at
/// zero, red above), symmetric about zero up to the 99th percentile of its magnitude over the
/// unmasked pixels, masked pixels grey, with a colour bar labelled in the image's units per
/// `unit`.
pub fn write_derivative_png(
    derivative: &Image,
    mask: &Image,
    unit: &str,
    path: &Path,
) -> crate::Result<()> {
    use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};
    let (w, h) = (derivative.width, derivative.height);
    let lum: Vec<f64> = derivative
        .pixels
        .iter()
        .map(|&c| crate::raster::luminance(c))
        .collect();
    let top = derivative_scale(derivative, mask);
    let colour = |v: f64| diverging_colour(v, top);
    let bar = 110u32;
    let mut pm = Pixmap::new(w + bar, h.max(120)).ok_or_else(|| crate::Error::from("pixmap"))?;
    pm.fill(Color::WHITE);
    {
        let data = pm.data_mut();
        let stride = (w + bar) as usize * 4;
        for y in 0..h as usize {
            for x in 0..w as usize {
                let i = y * w as usize + x;
                let c = if mask.pixels[i].x != 0.0 {
                    MASKED_GREY
                } else {
                    colour(lum[i])
                };
                let o = y * stride + x * 4;
                data[o..o + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
            }
        }
    }
    let (bx, by, bh) = (w as f32 + 12.0, 16.0f32, h.max(120) as f32 - 40.0);
    let steps = 64;
    for s in 0..steps {
        let f = s as f64 / (steps - 1) as f64;
        let c = colour(top * (1.0 - 2.0 * f));
        let mut paint = Paint::default();
        paint.set_color(Color::from_rgba8(c[0], c[1], c[2], 255));
        let y = by + bh * s as f32 / steps as f32;
        if let Some(r) = Rect::from_xywh(bx, y, 16.0, bh / steps as f32 + 0.5) {
            pm.fill_rect(r, &paint, Transform::identity(), None);
        }
    }
    let ink = [0u8, 0, 0];
    let style = TextStyle::new(11.0, ink).align(Align::Left);
    for (f, v) in [(0.0f32, top), (0.5, 0.0), (1.0, -top)] {
        draw_text(
            &mut pm,
            &format!("{v:+.3e}"),
            bx + 20.0,
            by + bh * f + 4.0,
            &style,
        );
    }
    draw_text(&mut pm, &format!("per {unit}"), bx, by + bh + 18.0, &style);
    let bytes = crate::figure::plot::pixmap_png_bytes(&pm)?;
    std::fs::write(path, bytes).map_err(|e| crate::Error::from(format!("{}: {e}", path.display())))
}

/// The colour of a masked pixel in a derivative's picture.
pub const MASKED_GREY: [u8; 3] = [128, 128, 128];

/// The scale of a derivative's diverging colour map: the 99th percentile of the magnitude of
/// its luminance over the unmasked pixels (1 when there is none), so that a few pixels of
/// extreme rate (along a shadow's edge) do not wash the rest out.
pub fn derivative_scale(derivative: &Image, mask: &Image) -> f64 {
    let mut mags: Vec<f64> = derivative
        .pixels
        .iter()
        .zip(&mask.pixels)
        .map(|(&c, m)| (crate::raster::luminance(c), m))
        .filter(|(v, m)| m.x == 0.0 && v.is_finite())
        .map(|(v, _)| v.abs())
        .collect();
    mags.sort_by(f64::total_cmp);
    mags.get((mags.len() as f64 * 0.99) as usize)
        .or(mags.last())
        .copied()
        .filter(|&t| t > 0.0)
        .unwrap_or(1.0)
}

/// The diverging colour map of a derivative: blue below zero, white at zero, red above,
/// saturated at ±`top` (the PNG of `penumbra render --derivative` and the workbench's
/// derivative AOV).
pub fn diverging_colour(v: f64, top: f64) -> [u8; 3] {
    let t = if v.is_finite() {
        (v / top).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (r, g, b) = if t >= 0.0 {
        (1.0, 1.0 - t, 1.0 - t)
    } else {
        (1.0 + t, 1.0 + t, 1.0)
    };
    let q = |x: f64| (x * 255.0).round() as u8;
    [q(r * 0.98 + 0.02 * g), q(g), q(b)]
}
