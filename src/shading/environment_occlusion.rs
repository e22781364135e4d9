//! The environment's visible region at a shading point, by the stages of 000 Alg. 1
//! (silhouette → horizon clip → projection → set difference), for 002's E_occluded computed
//! exactly.
//!
//! The environment is at infinity, behind every object, so what matters at a point is the
//! union of the occluders' outlines on the hemisphere, without depth. With S the static and D
//! the dynamic objects, V_s = H ∖ ∪S the hemisphere the static objects leave and
//! V_a = V_s ∖ ∪D what every object leaves:
//!
//! * `I_s = ∫_{V_s} L cos` (what diffuse PRT with shadows holds, 002 Eq. 6);
//! * `I_a = ∫_{V_a} L cos` (the true irradiance);
//! * `E_occluded = I_s − I_a`, so that `E = E_static − E_occluded` (002 Eq. 3) is exact.
//!
//! Both are sums over the occluders' own outlines, each minus what came before it
//! ([`union_integrals`]), so that the subjects of the set differences are small polygons
//! (most differences end at the disjoint test) and never the whole hemisphere, whose edges on
//! the horizon would coincide with those of every occluder standing on the tangent plane. A
//! mesh taken face by face (a non-convex mesh at a point on itself) contributes face by face.
//! Every stage is the area lights' own: `subtract_occluder` with no light piece (no depth cut,
//! no window), `face_polygon`, `clip_to_horizon`, the projection.
//!
//! (002's rays count a direction as occluded when its *first* hit is dynamic; where a dynamic
//! object stands in front of a static one, that direction is subtracted a second time from a
//! PRT term that never held it. `I_s − I_a` counts it once. Without static objects the two
//! definitions agree; docs/environment.md.)

use super::analytic::{
    PointContext, ShadingScratch, environment_faces, load_occluder, project_face, subtract_face,
    subtract_occluder,
};
use super::recorder::{EnvironmentSide, Recorder};
use super::{Method, PreparedScene, ShadingPoint};
use crate::geometry::{ProjectionPlane, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;

/// The occluders of the environment, split as 002 splits objects: indices into
/// `PreparedScene::occluders`.
#[derive(Clone, Debug, Default)]
pub struct EnvironmentOccluders {
    pub statics: Vec<u32>,
    pub dynamics: Vec<u32>,
}

impl EnvironmentOccluders {
    /// Splits the scene's occluders by `is_static(scene object index)`.
    pub fn new(scene: &PreparedScene, is_static: impl Fn(u32) -> bool) -> Self {
        let mut out = EnvironmentOccluders::default();
        for (oi, &o) in scene.occluders.iter().enumerate() {
            let object = scene.objects[o as usize].object;
            if is_static(object) {
                out.statics.push(oi as u32);
            } else {
                out.dynamics.push(oi as u32);
            }
        }
        out
    }
}

/// What [`environment_integrals`] found at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvironmentIntegrals {
    /// `I_s`, or `None` when no static object reaches the hemisphere (then `I_s` is the
    /// unshadowed irradiance, 002 Eq. 7).
    pub static_visible: Option<DVec3>,
    /// `I_s − I_a` (zero when no dynamic object hides anything).
    pub occluded: DVec3,
    /// Set differences performed.
    pub set_differences: u32,
    /// With rates ([`environment_integrals_with_rates`]): `dI_s/dθ` (zero when no static
    /// object reaches the hemisphere) and `d(I_s − I_a)/dθ`.
    pub static_rate: DVec3,
    pub occluded_rate: DVec3,
    /// With rates, the rate of the unshadowed irradiance (002 Eq. 7): not zero only where the
    /// frame turns.
    pub unshadowed_rate: DVec3,
}

/// What the environment's derivative needs at a point: the motion there, and the radiance
/// `L(ω)` of the integrand at a direction of the shading frame (the environment's SH, which
/// the shading layer does not know).
pub struct EnvironmentRates<'a> {
    pub point: &'a super::derivative::PointMotion,
    pub radiance: &'a dyn Fn(DVec3) -> DVec3,
    /// `∫_P (d/dθ L(F ω)) cos θ dω` over a region `P` of the shading frame F: the area term
    /// where the frame turns (`ry` of the object the point lies on), since the radiance seen at
    /// a fixed direction of a turning frame changes; `None` where the frame does not turn.
    pub turning: Option<&'a dyn Fn(&SphericalPolygon) -> DVec3>,
}

/// The shadowed irradiance `E = E_static − E_occluded` (002 Eq. 6), the value every caller
/// shades with (the renderer, its recording, and the stress test that checks it). The two
/// terms are integrals over nested regions, so their difference is nonnegative up to the
/// rounding of the set differences: a few ulps below zero are rounding and clamp to zero; a
/// real negative would be a bug, which the stress test looks for in the raw difference.
#[inline]
pub fn shadowed_irradiance(e_static: DVec3, e_occluded: DVec3) -> DVec3 {
    (e_static - e_occluded).max(DVec3::ZERO)
}

/// How far [`environment_integrals`] goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvironmentPass {
    /// Only the static objects: `I_s` (the G-buffer pass of `rt` needs no more).
    StaticOnly,
    /// Static, then dynamic objects: `I_s` and `E_occluded`.
    Occluded,
}

/// The upper hemisphere in the shading frame as a spherical polygon: four horizon points,
/// counter-clockwise seen from above.
pub(crate) fn hemisphere_polygon(out: &mut SphericalPolygon) {
    out.clear();
    out.push_loop([DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y]);
}

/// The integrals of the environment's visible region at `sp` (see the module doc).
/// `integrate(frame, polygon)` returns ∫ L(ω) cos θ dω over a spherical polygon given in the
/// local `frame` (z = normal): the SH closed form, kept out of the geometry.
pub fn environment_integrals<R: Recorder>(
    scene: &PreparedScene,
    occluders: &EnvironmentOccluders,
    sp: &ShadingPoint,
    pass: EnvironmentPass,
    integrate: &impl Fn(&Frame, &SphericalPolygon) -> DVec3,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> EnvironmentIntegrals {
    environment_integrals_with_rates(scene, occluders, sp, pass, integrate, None, scratch, rec)
}

/// [`environment_integrals`] and, with `rates`, their derivatives along the motion
/// (docs/derivatives.md, "The environment"): each term's region changes by the Reynolds
/// transport theorem with the integrand `L(ω) cos θ`, along the same polygons the values
/// integrate. The point's frame must not turn (`ry` of the object the point lies on is the
/// caller's to refuse).
#[allow(clippy::too_many_arguments)]
pub fn environment_integrals_with_rates<R: Recorder>(
    scene: &PreparedScene,
    occluders: &EnvironmentOccluders,
    sp: &ShadingPoint,
    pass: EnvironmentPass,
    integrate: &impl Fn(&Frame, &SphericalPolygon) -> DVec3,
    rates: Option<&EnvironmentRates>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> EnvironmentIntegrals {
    scratch.begin_point(scene);
    let ctx = PointContext::for_environment(scene, sp);
    let before = scratch.stats.set_differences;
    if let Some(r) = rates {
        scratch.derivative.begin_point(scene.objects.len());
        let all = occluders
            .statics
            .iter()
            .chain(&occluders.dynamics)
            .map(|&oi| scene.occluders[oi as usize]);
        super::derivative::begin_piece(
            &mut scratch.derivative,
            scene,
            r.point,
            sp.position,
            all,
            None,
        );
    }
    let mut out = union_integrals(&ctx, occluders, pass, integrate, rates, scratch, rec);
    scratch.end_point();
    out.set_differences = scratch.stats.set_differences - before;
    out
}

/// Whether occluder `oi` can hide anything from the point: it reaches above the tangent
/// plane, and it is not a convex or flat mesh the point lies on.
fn reaches_hemisphere(ctx: &PointContext, oi: u32) -> bool {
    let (scene, sp) = (ctx.scene, ctx.sp);
    let occ = &scene.objects[scene.occluders[oi as usize] as usize];
    !(occ.path.is_simple() && sp.object == Some(occ.object))
        && sp.normal.dot(occ.poly.center - sp.position) >= -occ.poly.radius
}

/// The integrals as sums over the occluders' own outlines, each minus what came before it:
///
/// * ∫_{∪S} = Σ_k ∫ (S_k ∖ S_<k), and I_s = I_hemisphere − ∫_{∪S};
/// * E_occluded = ∫_{(∪D) ∖ (∪S)} = Σ_i ∫ (D_i ∖ (∪S ∪ D_<i)), since
///   V_s ∖ V_a = (H ∖ ∪S) ∖ (H ∖ (∪S ∪ ∪D)) = (∪D) ∖ (∪S).
///
/// The subjects are the outlines, small polygons that rarely overlap, instead of the whole
/// plane with holes: most differences end at the disjoint test. An occluder with no single
/// outline at the point (taken face by face) gives one term per face, each minus the faces
/// before it.
fn union_integrals<R: Recorder>(
    ctx: &PointContext,
    occluders: &EnvironmentOccluders,
    pass: EnvironmentPass,
    integrate: &impl Fn(&Frame, &SphericalPolygon) -> DVec3,
    rates: Option<&EnvironmentRates>,
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> EnvironmentIntegrals {
    let mut out = EnvironmentIntegrals::default();
    // The rate of the region in `visible_sph`, by the same edges the value integrates.
    let rate_of = |scratch: &mut ShadingScratch| -> DVec3 {
        let Some(r) = rates else {
            return DVec3::ZERO;
        };
        let region = std::mem::take(&mut scratch.visible_sph);
        let mut rate = super::derivative::region_rate_with(
            &mut scratch.derivative,
            r.point,
            ctx.sp.position,
            &ctx.frame,
            &region,
            r.radiance,
        );
        if let Some(turning) = r.turning {
            rate += turning(&region);
        }
        scratch.visible_sph = region;
        rate
    };
    // Subtracts `before` (whole occluders: statics first, then earlier dynamics) and the
    // faces `own_before` of occluder `own` from the loaded region and integrates the rest.
    let finish = |before: [&[u32]; 2],
                  own: Option<(usize, usize)>,
                  scratch: &mut ShadingScratch,
                  rec: &mut R|
     -> Option<(DVec3, DVec3)> {
        'subtract: for group in before {
            for &oj in group {
                if scratch.visible.is_empty() {
                    break 'subtract;
                }
                if reaches_hemisphere(ctx, oj) {
                    subtract_occluder(ctx, oj as usize, None, scratch, rec);
                }
            }
        }
        if let Some((oi, n)) = own {
            for k in 0..n {
                if scratch.visible.is_empty() {
                    break;
                }
                let g = scratch.env_faces[k] as usize;
                subtract_face(ctx, oi, g, scratch, rec);
            }
        }
        if scratch.visible.is_empty() {
            return None;
        }
        ProjectionPlane::NORMAL.reproject(&scratch.visible, &mut scratch.visible_sph);
        let value = integrate(&ctx.frame, &scratch.visible_sph);
        Some((value, rate_of(scratch)))
    };
    // ∫ (occluder oi ∖ before): its outline as one term, or, taken face by face, one term per
    // face minus the faces before it. Each term goes to the recorder as it is integrated.
    let mut terms = |side: EnvironmentSide,
                     oi: u32,
                     before: [&[u32]; 2],
                     scratch: &mut ShadingScratch|
     -> Option<(DVec3, DVec3)> {
        let mut sum: Option<(DVec3, DVec3)> = None;
        if load_occluder(ctx, oi as usize, scratch, rec) {
            if !scratch.visible.is_empty()
                && let Some((i, r)) = finish(before, None, scratch, rec)
            {
                rec.environment_term(side, oi as usize, &scratch.visible_sph, i);
                sum = Some((i, r));
            }
            return sum;
        }
        environment_faces(ctx, oi as usize, scratch);
        for k in 0..scratch.env_faces.len() {
            let g = scratch.env_faces[k] as usize;
            project_face(ctx, oi as usize, g, scratch, rec);
            if scratch.occ_plane.is_empty() {
                continue;
            }
            std::mem::swap(&mut scratch.visible, &mut scratch.occ_plane);
            if let Some((i, r)) = finish(before, Some((oi as usize, k)), scratch, rec) {
                rec.environment_term(side, oi as usize, &scratch.visible_sph, i);
                let s = sum.get_or_insert((DVec3::ZERO, DVec3::ZERO));
                s.0 += i;
                s.1 += r;
            }
        }
        sum
    };
    let statics = &occluders.statics;
    let mut static_union: Option<DVec3> = None;
    let mut static_rate = DVec3::ZERO;
    for (k, &oi) in statics.iter().enumerate() {
        if reaches_hemisphere(ctx, oi)
            && let Some((i, r)) = terms(EnvironmentSide::Static, oi, [&statics[..k], &[]], scratch)
        {
            *static_union.get_or_insert(DVec3::ZERO) += i;
            static_rate += r;
        }
    }
    let hemisphere = |scratch: &mut ShadingScratch| {
        hemisphere_polygon(&mut scratch.visible_sph);
        integrate(&ctx.frame, &scratch.visible_sph)
    };
    // The hemisphere does not move in the shading frame; where the frame turns, the radiance
    // over it changes.
    if let Some(turning) = rates.and_then(|r| r.turning) {
        hemisphere_polygon(&mut scratch.visible_sph);
        out.unshadowed_rate = turning(&scratch.visible_sph);
    }
    if let Some(u) = static_union {
        out.static_visible = Some(hemisphere(scratch) - u);
        out.static_rate = out.unshadowed_rate - static_rate;
    }
    if pass == EnvironmentPass::Occluded {
        let dynamics = &occluders.dynamics;
        for (k, &oi) in dynamics.iter().enumerate() {
            if reaches_hemisphere(ctx, oi)
                && let Some((i, r)) = terms(
                    EnvironmentSide::Dynamic,
                    oi,
                    [statics, &dynamics[..k]],
                    scratch,
                )
            {
                out.occluded += i;
                out.occluded_rate += r;
            }
        }
    }
    out
}

impl<'a> PointContext<'a> {
    /// The context of the environment passes: the shading frame of `sp` (the same frame as the
    /// area lights'), the analytic method, no BRDF lobes (002 is diffuse).
    pub(super) fn for_environment(scene: &'a PreparedScene, sp: &'a ShadingPoint) -> Self {
        PointContext {
            scene,
            sp,
            frame: Frame::from_normal_and_view(sp.normal, sp.view),
            lobes: super::analytic::Lobes {
                kd: DVec3::ZERO,
                specular: None,
                glossy: None,
            },
            method: Method::Analytic,
            correction: None,
            rates: None,
        }
    }
}
