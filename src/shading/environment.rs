//! The environment's visible region at a shading point, by the stages of 000 Alg. 1
//! (silhouette → horizon clip → projection → set difference), for 002's E_occluded computed
//! exactly.
//!
//! The environment is at infinity, behind every object, so its "light polygon" is the whole
//! upper hemisphere: four points on the horizon, which the projection sends to the line at
//! infinity (the whole plane). The occluders are subtracted from it by the same
//! `subtract_occluder` the area lights use, with no depth cut and no window. Static objects
//! are subtracted first, then dynamic ones, and the region is integrated after each group:
//!
//! * `I_s = ∫_{V_s} L cos`, V_s = the hemisphere minus the static objects (what diffuse PRT
//!   with shadows holds, 002 Eq. 6);
//! * `I_a = ∫_{V_a} L cos`, V_a = V_s minus the dynamic objects (the true irradiance);
//! * `E_occluded = I_s − I_a`, so that `E = E_static − E_occluded` (002 Eq. 3) is exact.
//!
//! (002's rays count a direction as occluded when its *first* hit is dynamic; where a dynamic
//! object stands in front of a static one, that direction is subtracted a second time from a
//! PRT term that never held it. `I_s − I_a` counts it once. Without static objects the two
//! definitions agree; docs/environment.md.)

use super::analytic::{PointContext, ShadingScratch, subtract_occluder};
use super::recorder::Recorder;
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
pub fn hemisphere_polygon(out: &mut SphericalPolygon) {
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
    scratch.begin_point(scene);
    let ctx = PointContext::for_environment(scene, sp);
    hemisphere_polygon(&mut scratch.light_clip);
    ProjectionPlane::NORMAL.project(&scratch.light_clip, &mut scratch.visible);
    let before = scratch.stats.set_differences;

    let mut out = EnvironmentIntegrals::default();
    let static_touched = subtract_group(&ctx, &occluders.statics, scratch, rec);
    let visible_integral = |scratch: &mut ShadingScratch| {
        ProjectionPlane::NORMAL.reproject(&scratch.visible, &mut scratch.visible_sph);
        integrate(&ctx.frame, &scratch.visible_sph)
    };
    if static_touched {
        out.static_visible = Some(visible_integral(scratch));
    }
    if pass == EnvironmentPass::Occluded {
        let dynamic_touched = subtract_group(&ctx, &occluders.dynamics, scratch, rec);
        if dynamic_touched {
            let i_a = visible_integral(scratch);
            let i_s = match out.static_visible {
                Some(i_s) => i_s,
                None => {
                    hemisphere_polygon(&mut scratch.visible_sph);
                    integrate(&ctx.frame, &scratch.visible_sph)
                }
            };
            out.occluded = i_s - i_a;
        }
    }
    out.set_differences = scratch.stats.set_differences - before;
    out
}

/// Subtracts the occluders `group` (indices into `scene.occluders`) that reach above the
/// tangent plane from `scratch.visible`; returns whether the visible region changed.
fn subtract_group<R: Recorder>(
    ctx: &PointContext,
    group: &[u32],
    scratch: &mut ShadingScratch,
    rec: &mut R,
) -> bool {
    let (scene, sp) = (ctx.scene, ctx.sp);
    let mut touched = false;
    for &oi in group {
        if scratch.visible.is_empty() {
            break;
        }
        let occ = &scene.objects[scene.occluders[oi as usize] as usize];
        // A convex or flat mesh cannot hide anything from a point on itself.
        if occ.simple && sp.object == Some(occ.object) {
            continue;
        }
        // Entirely below the tangent plane: clipped away anyway.
        if sp.normal.dot(occ.poly.center - sp.position) < -occ.poly.radius {
            continue;
        }
        let (differences, vertices) = (
            scratch.stats.set_differences,
            scratch.visible.vertex_count(),
        );
        subtract_occluder(ctx, oi as usize, None, scratch, rec);
        touched |= scratch.stats.set_differences != differences
            || scratch.visible.vertex_count() != vertices;
    }
    touched
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
            },
            method: Method::Analytic,
        }
    }
}
