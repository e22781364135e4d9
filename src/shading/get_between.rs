//! `GetBetween` (000 Alg. 1 line 7, Sect. 3.5): the occluders that can hide part of a light
//! from a shading point.
//!
//! 000 culls with a five-sided frustum against bounding spheres. Here each object is bounded
//! by a sphere, which subtends a cap on the unit sphere at `x`; an occluder is kept when
//! * its sphere reaches above the tangent plane of `x`,
//! * its cap overlaps the light's cap (the exact test for two spheres' cones, tighter than a
//!   frustum around the light),
//! * it is not entirely farther than the light, and
//! * `x` lies on the occluder's side of their precomputed separating plane (otherwise the
//!   occluder is behind the light wherever they overlap, and subtracting it would be wrong).

use super::{PreparedScene, ShadingPoint};
use glam::DVec3;

/// The cap a sphere (centre `c`, radius `r`) subtends from `x`: unit direction to its centre,
/// sine and cosine of its angular radius, distance to its centre; `None` when `x` is inside the
/// sphere (it then covers every direction).
#[inline]
fn cap(x: DVec3, c: DVec3, r: f64) -> Option<(DVec3, f64, f64, f64)> {
    let d = c - x;
    let dist = d.length();
    if dist <= r {
        return None;
    }
    let sin = r / dist;
    Some((d / dist, sin, (1.0 - sin * sin).sqrt(), dist))
}

/// Fills `out` with indices into `scene.occluders` of the occluders that may hide part of light
/// `l` (index into `scene.lights`) from `sp`. `self_occluding` keeps the light's own mesh (the
/// per-face path of a non-convex light, where its faces hide each other).
pub(crate) fn get_between(
    scene: &PreparedScene,
    l: usize,
    sp: &ShadingPoint,
    self_occluding: bool,
    out: &mut Vec<u32>,
) {
    out.clear();
    let x = sp.position;
    let light_id = scene.lights[l].0;
    let light = &scene.objects[light_id as usize];
    let light_cap = cap(x, light.poly.center, light.poly.radius);
    for (oi, &o) in scene.occluders.iter().enumerate() {
        let occ = &scene.objects[o as usize];
        if o == light_id {
            if self_occluding {
                out.push(oi as u32);
            }
            continue;
        }
        // A convex or flat mesh cannot shadow a point on itself.
        if occ.path.is_simple() && sp.object == Some(occ.object) {
            continue;
        }
        let (c, r) = (occ.poly.center, occ.poly.radius);
        // Entirely below the tangent plane: clipped away anyway.
        if sp.normal.dot(c - x) < -r {
            continue;
        }
        if let (Some((dl, sl, cl, distl)), Some((dn, sn, cn, distn))) = (light_cap, cap(x, c, r)) {
            // Entirely farther than the farthest point of the light.
            if distn - r > distl + light.poly.radius {
                continue;
            }
            // Caps that do not overlap: the angle between the centres exceeds the sum of the
            // angular radii. Both radii are in [0, π/2], so the sum is in [0, π] where cos
            // decreases: the test is cos(angle) < cos(θl + θn) = cl·cn − sl·sn, no trigonometry.
            // The margin keeps rounding on the side of keeping the occluder.
            let cos_sum = cl * cn - sl * sn;
            if dl.dot(dn) < cos_sum - 1e-12 {
                continue;
            }
        }
        if scene
            .separation(l, oi)
            .is_some_and(|plane| plane.eval(x) <= 0.0)
        {
            continue;
        }
        out.push(oi as u32);
    }
}
