//! Monte Carlo sums of the shadowed and unshadowed direct lighting at one shading point, from
//! the *same* samples (003 Eq. 15, 21, 22):
//!
//! ```text
//! S_N = 1/N Σ R(ωn) L(ωn) V(ωn) / p(ωn)        U_N = 1/N Σ R(ωn) L(ωn) / p(ωn)
//! ```
//!
//! Every estimator of the paper is built from these two sums and the analytic U
//! (see `estimators.rs`). Sampling is one-sample multiple importance sampling with the balance
//! heuristic (Veach and Guibas 1995) over the light strategy (a light chosen with probability
//! P_l ∝ luminance × Ω_l, then a direction uniform in its spherical triangles) and the BRDF
//! strategy (cosine-weighted diffuse or GGX visible normals). The contribution of light l at ω
//! is divided by
//!
//! ```text
//! p_l(ω) = q_L P_l / Ω_l + q_B p_B(ω)
//! ```
//!
//! which is the balance heuristic written for one sample: the light strategy draws (l, ω), the
//! BRDF strategy draws ω and contributes to every light that covers ω, so each light's integral
//! is estimated without bias. For a light sampled face by face, the pair (face, ω) is the
//! sample and only the face seen first from x has a non-zero integrand, so the same formula
//! holds with Ω_l the sum of the face solid angles.

use super::AreaLights;
use super::light_set::{LightSet, SILHOUETTE};
use crate::accel::Bvh;
use crate::accel::Ray;
use crate::math::{Frame, Pcg32};
use crate::scene::Material;
use crate::scene::Scene;
use crate::shading::PreparedScene;
use crate::shading::brdf::{BrdfSampler, eval_cos};
use crate::shading::{PreparedObject, ShadingPoint};
use glam::DVec3;

crate::choice! {
    /// How light samples are drawn.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum LightSampling {
        /// Uniform in the solid angle of each light's triangulated silhouette (or faces), with MIS
        /// against BRDF sampling.
        SolidAngle = "solid-angle",
        /// Uniform over each light's area (the baseline of 001 Sect. 3.6); light samples only.
        Area = "area",
    }
    default = SolidAngle;
}

/// What the estimators read of a prepared scene: the renderer's context lends it
/// (`render::RenderContext::sampled`), so that this layer needs nothing of the renderer.
#[derive(Clone, Copy)]
pub struct SampledScene<'a> {
    pub scene: &'a Scene,
    pub prepared: &'a PreparedScene,
    pub bvh: &'a Bvh,
    pub area_lights: &'a AreaLights,
}

/// Sums over the samples of one shading point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleSums {
    /// Σ R L V / p.
    pub s: DVec3,
    /// Σ R L / p.
    pub u: DVec3,
    /// Σ (R L V / p)², for the standard error of S_N.
    pub s_sq: DVec3,
    pub n: u32,
}

impl SampleSums {
    /// S_N, Eq. 21 divided by N.
    pub(crate) fn s_n(&self) -> DVec3 {
        if self.n == 0 {
            DVec3::ZERO
        } else {
            self.s / self.n as f64
        }
    }

    /// U_N, Eq. 22 divided by N.
    pub(crate) fn u_n(&self) -> DVec3 {
        if self.n == 0 {
            DVec3::ZERO
        } else {
            self.u / self.n as f64
        }
    }

    /// Sample variance of S_N's mean (per channel).
    pub(crate) fn s_variance_of_mean(&self) -> DVec3 {
        if self.n < 2 {
            return DVec3::ZERO;
        }
        let n = self.n as f64;
        let m = self.s / n;
        ((self.s_sq / n - m * m) * (n / (n - 1.0))).max(DVec3::ZERO) / n
    }
}

/// Reused per-thread buffers.
#[derive(Default)]
pub struct EstimatorScratch {
    pub lights: LightSet,
}

/// Relative ray offset: shadow rays start and stop this fraction of their length away from
/// their end points (the shading point's own face is excluded by identity, not by distance).
const RAY_EPS: f64 = 1e-9;

/// Draws `spp` samples at `sp` and returns the sums of S_N and U_N.
#[allow(clippy::too_many_arguments)]
pub fn direct_samples(
    ctx: &SampledScene,
    sp: &ShadingPoint,
    material: &Material,
    spp: u32,
    sampling: LightSampling,
    rng: &mut Pcg32,
    scratch: &mut EstimatorScratch,
) -> SampleSums {
    let frame = Frame::from_normal_and_view(sp.normal, sp.view);
    match sampling {
        LightSampling::SolidAngle => {
            solid_angle_samples(ctx, sp, &frame, material, spp, rng, scratch)
        }
        LightSampling::Area => area_samples(ctx, sp, &frame, material, spp, rng),
    }
}

#[allow(clippy::too_many_arguments)]
fn solid_angle_samples(
    ctx: &SampledScene,
    sp: &ShadingPoint,
    frame: &Frame,
    material: &Material,
    spp: u32,
    rng: &mut Pcg32,
    scratch: &mut EstimatorScratch,
) -> SampleSums {
    let mut sums = SampleSums {
        n: spp,
        ..SampleSums::default()
    };
    let lights = &mut scratch.lights;
    lights.build(ctx.prepared, sp, frame);
    if lights.is_empty() {
        return sums; // nothing above the horizon: S = U = 0 exactly
    }
    let v = frame.to_local(sp.view);
    let brdf = BrdfSampler::new(material);
    // Half of the samples of a purely specular material follow the BRDF; a Lambertian one is
    // sampled by solid angle only (the cosine varies little over a light).
    let q_b = 0.5 * brdf.specular_probability;
    let q_l = 1.0 - q_b;
    let x = sp.position;
    let t_min_unit = RAY_EPS * (1.0 + x.abs().max_element());

    for _ in 0..spp {
        let mut value = DVec3::ZERO;
        let mut unshadowed = DVec3::ZERO;
        if rng.next_f64() >= q_b {
            // Light strategy.
            let Some(r) = lights.pick_run(rng.next_f64()) else {
                continue;
            };
            let (w, face) = lights.sample(r, rng.next_f64(), rng.next_f64(), rng.next_f64());
            let run = lights.runs[r];
            let f = run.radiance * eval_cos(material, v, w);
            if f != DVec3::ZERO {
                let p = q_l * run.probability / run.solid_angle + q_b * brdf.pdf(v, w);
                let contribution = f / p;
                let wd = frame.to_world(w);
                let light = &ctx.prepared.objects[ctx.prepared.lights[run.light].0 as usize];
                if let Some(t) = distance_to_light(light, face, x, wd) {
                    let ray = Ray {
                        origin: x,
                        dir: wd * t,
                    };
                    let (blocked, self_visible) = light_sample_visibility(
                        ctx,
                        sp,
                        &ray,
                        run.object,
                        face,
                        run.self_occluding,
                    );
                    if self_visible {
                        unshadowed = contribution;
                    }
                    if !blocked {
                        value = contribution;
                    }
                }
            }
        } else {
            // BRDF strategy.
            let w = brdf.sample(v, rng.next_f64(), rng.next_f64(), rng.next_f64());
            if w.z > 0.0 {
                let fr = eval_cos(material, v, w);
                let pb = q_b * brdf.pdf(v, w);
                // Which lights cover ω (at most 64 tracked for the shadowed pass).
                let mut covering = 0u64;
                for (r, run) in lights.runs.iter().enumerate() {
                    if run.probability > 0.0 && lights.covers(r, w) {
                        let p = q_l * run.probability / run.solid_angle + pb;
                        unshadowed += run.radiance * fr / p;
                        if r < 64 {
                            covering |= 1 << r;
                        }
                    }
                }
                if covering != 0 {
                    value =
                        trace_brdf_ray(ctx, sp, lights, covering, frame.to_world(w), t_min_unit)
                            .map_or(DVec3::ZERO, |r| {
                                let run = &lights.runs[r];
                                run.radiance * fr / (q_l * run.probability / run.solid_angle + pb)
                            });
                }
            }
        }
        sums.s += value;
        sums.u += unshadowed;
        sums.s_sq += value * value;
    }
    sums
}

/// Visibility of a light sample along `ray` (the sample at t = 1): `blocked` when an occluder
/// other than the shading point's own face and the sampled light face (the whole light for a
/// silhouette fan, [`SILHOUETTE`]) lies in between, which zeroes S; and `self_visible` unless
/// another face of the same (self-occluding) light hides the sample, which zeroes U too. The
/// second ray is cast only when the first was blocked.
fn light_sample_visibility(
    ctx: &SampledScene,
    sp: &ShadingPoint,
    ray: &Ray,
    light_object: u32,
    face: u32,
    self_occluding: bool,
) -> (bool, bool) {
    let objects = &ctx.scene.objects;
    let own = |o: u32, f: u32| Some(o) == sp.object && Some(f) == sp.face;
    let blocked = ctx.bvh.occluded(ray, RAY_EPS, 1.0 - RAY_EPS, |o, f| {
        objects[o as usize].flags.occluder
            && !own(o, f)
            && if face == SILHOUETTE {
                o != light_object
            } else {
                !(o == light_object && f == face)
            }
    });
    let self_visible = !blocked
        || !self_occluding
        || !ctx.bvh.occluded(ray, RAY_EPS, 1.0 - RAY_EPS, |o, f| {
            o == light_object && f != face && objects[o as usize].flags.occluder
        });
    (blocked, self_visible)
}

/// The light run whose front face a BRDF ray from `sp` along `wd` reaches first, if that light
/// covers the direction. Lights that do not occlude are looked through (their emission still
/// counts when they are the first light reached).
fn trace_brdf_ray(
    ctx: &SampledScene,
    sp: &ShadingPoint,
    lights: &LightSet,
    covering: u64,
    wd: DVec3,
    t_min: f64,
) -> Option<usize> {
    let objects = &ctx.scene.objects;
    let ray = Ray {
        origin: sp.position,
        dir: wd,
    };
    let hit = ctx
        .bvh
        .intersect_accept(&ray, t_min, f64::INFINITY, |o, f| {
            let flags = &objects[o as usize].flags;
            (flags.occluder || flags.light) && !(Some(o) == sp.object && Some(f) == sp.face)
        })?;
    if hit.geometric_normal.dot(wd) >= 0.0 {
        return None; // the back of a face
    }
    let r = lights.runs.iter().position(|r| r.object == hit.object)?;
    (r < 64 && covering & (1 << r) != 0).then_some(r)
}

/// Distance along the unit direction `wd` from `x` to the light: for the silhouette of a convex
/// light, the ray's entry into the convex body (the last plane it crosses inward); for one face,
/// the face's plane.
#[inline]
fn distance_to_light(light: &PreparedObject, face: u32, x: DVec3, wd: DVec3) -> Option<f64> {
    let t = if face == SILHOUETTE {
        let mut t = f64::NEG_INFINITY;
        for pl in &light.poly.face_planes {
            let d = pl.n.dot(wd);
            if d < 0.0 {
                t = t.max(-pl.eval(x) / d);
            }
        }
        t
    } else {
        let pl = &light.poly.face_planes[face as usize];
        let d = pl.n.dot(wd);
        if d >= 0.0 {
            return None;
        }
        -pl.eval(x) / d
    };
    (t > 0.0 && t.is_finite()).then_some(t)
}

/// Area sampling (no MIS): a light chosen ∝ luminance × area, a point uniform on its surface,
/// converted to solid angle with the geometry term r² / cosθ_y (001 Eq. 3.19).
fn area_samples(
    ctx: &SampledScene,
    sp: &ShadingPoint,
    frame: &Frame,
    material: &Material,
    spp: u32,
    rng: &mut Pcg32,
) -> SampleSums {
    let mut sums = SampleSums {
        n: spp,
        ..SampleSums::default()
    };
    let area = ctx.area_lights;
    let v = frame.to_local(sp.view);
    let x = sp.position;
    for _ in 0..spp {
        let Some((k, prob)) = area.pick(rng.next_f64()) else {
            return sums;
        };
        let light = &area.lights[k];
        let (y, ny, face) = light.sample(rng);
        let d = y - x;
        let r2 = d.length_squared();
        if r2 == 0.0 {
            continue;
        }
        let wd = d / r2.sqrt();
        let cos_y = -ny.dot(wd);
        let w = frame.to_local(wd);
        if cos_y <= 0.0 || w.z <= 0.0 || (Some(light.object) == sp.object && Some(face) == sp.face)
        {
            continue;
        }
        let contribution =
            light.radiance * eval_cos(material, v, w) * (light.area * cos_y / (r2 * prob));
        let ray = Ray { origin: x, dir: d };
        let (blocked, self_visible) =
            light_sample_visibility(ctx, sp, &ray, light.object, face, area.self_occluding[k]);
        if self_visible {
            sums.u += contribution;
        }
        if !blocked {
            sums.s += contribution;
            sums.s_sq += contribution * contribution;
        }
    }
    sums
}
