//! Conical ray culling (002 Sect. 3.3–3.4): the cones around the bounding spheres of dynamic
//! objects seen from a shading point (Eq. 4), merged per point (Alg. 1, Eq. 5), and the test
//! of Alg. 2 lines 6–11 that decides whether a ray is traced and how far.
//!
//! Culling must never change the result, only the work: a ray that would first hit a dynamic
//! object has its direction inside that object's cone and its hit closer than the cone's
//! height. Two choices keep that true in floating point:
//! * the axis points from the shading point *toward* the sphere (002 writes `p − c`, the
//!   direction a ray arrives from; the test `arccos(ω·d) < ψ` needs `c − p`);
//! * each sphere is widened by a relative margin before its cone is built, so that a ray
//!   grazing the sphere (and a mesh vertex on it) is inside its cone despite rounding in
//!   `cos ψ` and in the ray–triangle test.

use crate::math::angle_between;
use glam::DVec3;

/// Relative widening of a bounding sphere before its cone is built (see the module doc).
const SPHERE_MARGIN: f64 = 1e-7;

/// A bounding sphere of a dynamic object, `S = (c, r)` in 002's notation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub centre: DVec3,
    pub radius: f64,
}

// The cone itself is a plain value of directions (the recorder keeps it): `geometry::spherical::cone`.
pub(crate) use crate::geometry::spherical::cone::Cone;

/// The cone of Eq. 4 for sphere `s` at point `p` with normal `n`, or `None` when the sphere
/// lies entirely behind the tangent plane (Alg. 1 line 4: it cannot occlude anything).
pub(crate) fn cone_of_sphere(p: DVec3, n: DVec3, s: &BoundingSphere) -> Option<Cone> {
    let r = s.radius * (1.0 + SPHERE_MARGIN) + f64::MIN_POSITIVE;
    let to_centre = s.centre - p;
    let dist = to_centre.length();
    if dist < r {
        // Alg. 1 lines 6–8: inside the sphere every direction may hit the object.
        return Some(Cone {
            axis: n,
            height: dist + r,
            half_angle: std::f64::consts::FRAC_PI_2,
            cos_half_angle: 0.0,
        });
    }
    // Alg. 1 line 4: the sphere reaches above the tangent plane, (c − p)·n > −r.
    if to_centre.dot(n) <= -r {
        return None;
    }
    let sin = r / dist;
    Some(Cone {
        axis: to_centre / dist,
        height: dist + r,
        half_angle: sin.asin(),
        cos_half_angle: (1.0 - sin * sin).max(0.0).sqrt(),
    })
}

/// 002 Alg. 1: constructs the cones of `spheres` at `p` and merges each new cone into an
/// earlier one that contains it, or replaces an earlier one it contains (Eq. 5); `out` is
/// cleared first. Merging keeps every direction of both cones inside the result and the
/// larger height, so it never loses a ray that could hit a dynamic object.
pub fn construct_and_merge_cones(
    p: DVec3,
    n: DVec3,
    spheres: &[BoundingSphere],
    out: &mut Vec<Cone>,
) {
    out.clear();
    for s in spheres {
        let Some(cone) = cone_of_sphere(p, n, s) else {
            continue;
        };
        merge_cone(cone, out);
    }
}

/// Lines 12–29 of Alg. 1 for one new cone.
pub(crate) fn merge_cone(cone: Cone, cones: &mut Vec<Cone>) {
    for c in cones.iter_mut() {
        let apart = if c.is_hemisphere() || cone.is_hemisphere() {
            0.0
        } else {
            angle_between(c.axis, cone.axis)
        };
        // Lines 14–18: the new cone lies inside C_i.
        if c.is_hemisphere() || apart + cone.half_angle < c.half_angle {
            c.height = c.height.max(cone.height);
            return;
        }
        // Lines 19–25: C_i lies inside the new cone: C_i takes its axis and angle.
        if cone.is_hemisphere() || apart + c.half_angle < cone.half_angle {
            c.axis = cone.axis;
            c.half_angle = cone.half_angle;
            c.cos_half_angle = cone.cos_half_angle;
            c.height = c.height.max(cone.height);
            return;
        }
    }
    cones.push(cone);
}

/// Alg. 2 lines 4–11: `Some(length)` when `dir` lies in at least one cone (the ray is traced,
/// up to the largest height among the cones containing it), `None` when it is culled.
#[inline]
pub fn ray_extent(cones: &[Cone], dir: DVec3) -> Option<f64> {
    let mut max_len: Option<f64> = None;
    for c in cones {
        if c.contains(dir) {
            max_len = Some(max_len.map_or(c.height, |m: f64| m.max(c.height)));
        }
    }
    max_len
}

/// 002 Sect. 6 leaves the many-cone case open: with ten objects the cones rarely merge and
/// every ray is tested against each. This clusters the cones into at most `max_cones` by
/// repeatedly replacing the pair whose enclosing cone is narrowest by that enclosing cone
/// (its height the larger of the two). The enclosing cone contains both, so culling stays
/// conservative; fewer, wider cones trade tests per ray for rays traced.
pub(crate) fn cluster_cones(cones: &mut Vec<Cone>, max_cones: usize) {
    let max_cones = max_cones.max(1);
    while cones.len() > max_cones {
        let mut best = (0usize, 1usize, f64::INFINITY, None);
        for i in 0..cones.len() {
            for j in i + 1..cones.len() {
                let e = enclosing_cone(&cones[i], &cones[j]);
                if e.half_angle < best.2 {
                    best = (i, j, e.half_angle, Some(e));
                }
            }
        }
        let (i, j, _, e) = best;
        let Some(e) = e else { return };
        cones[i] = e;
        cones.swap_remove(j);
    }
}

/// The narrowest cone with the same apex containing cones `a` and `b`.
pub(crate) fn enclosing_cone(a: &Cone, b: &Cone) -> Cone {
    if a.is_hemisphere() || b.is_hemisphere() {
        let h = if a.is_hemisphere() { a } else { b };
        return Cone {
            height: a.height.max(b.height),
            ..*h
        };
    }
    let apart = angle_between(a.axis, b.axis);
    if apart + b.half_angle <= a.half_angle {
        return Cone {
            height: a.height.max(b.height),
            ..*a
        };
    }
    if apart + a.half_angle <= b.half_angle {
        return Cone {
            height: a.height.max(b.height),
            ..*b
        };
    }
    let half = 0.5 * (apart + a.half_angle + b.half_angle);
    if half >= std::f64::consts::PI {
        // Cones almost opposite: only the whole sphere contains both; a cone of angle π.
        return Cone {
            axis: a.axis,
            height: a.height.max(b.height),
            half_angle: std::f64::consts::PI,
            cos_half_angle: -1.0,
        };
    }
    // Rotate a's axis toward b's by (half − ψ_a): the new axis sits so that the cone reaches
    // a's far edge and b's far edge exactly.
    let t = half - a.half_angle;
    let perp = (b.axis - a.axis * a.axis.dot(b.axis)).normalize_or_zero();
    let axis = if perp == DVec3::ZERO {
        a.axis
    } else {
        (a.axis * t.cos() + perp * t.sin()).normalize()
    };
    // Widen by a hair so that rounding in the rotation cannot exclude a boundary direction.
    let half = (half * (1.0 + 1e-12) + 1e-15).min(std::f64::consts::PI);
    Cone {
        axis,
        height: a.height.max(b.height),
        half_angle: half,
        cos_half_angle: half.cos(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    fn random_cone(rng: &mut Pcg32) -> Cone {
        let half = rng.range(0.01, 1.4);
        Cone {
            axis: rng.unit_vector(),
            height: rng.range(1.0, 5.0),
            half_angle: half,
            cos_half_angle: half.cos(),
        }
    }

    #[test]
    fn merged_and_enclosing_cones_contain_both_inputs() {
        let mut rng = Pcg32::new(3, 1);
        for _ in 0..2000 {
            let (a, b) = (random_cone(&mut rng), random_cone(&mut rng));
            let e = enclosing_cone(&a, &b);
            let mut merged = vec![a];
            merge_cone(b, &mut merged);
            for _ in 0..200 {
                let d = rng.unit_vector();
                for c in [&a, &b] {
                    if c.contains(d) {
                        assert!(e.contains(d), "enclosing cone lost a direction");
                        assert!(e.height >= c.height);
                        assert!(
                            ray_extent(&merged, d).is_some_and(|h| h >= c.height),
                            "merging lost a direction"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_ray_toward_any_point_of_the_sphere_is_inside_its_cone_and_height() {
        let mut rng = Pcg32::new(9, 2);
        for _ in 0..5000 {
            let p = DVec3::ZERO;
            let n = DVec3::Y;
            let s = BoundingSphere {
                centre: rng.unit_vector() * rng.range(0.5, 10.0),
                radius: rng.range(0.01, 3.0),
            };
            let Some(cone) = cone_of_sphere(p, n, &s) else {
                // Behind the tangent plane: no point of the sphere is above it.
                assert!(s.centre.dot(n) <= -s.radius * (1.0 - 1e-12));
                continue;
            };
            // Points on the sphere's surface, tangency included.
            let q = s.centre + rng.unit_vector() * s.radius;
            let w = q - p;
            let d = w.normalize();
            if d.dot(n) <= 0.0 {
                continue;
            }
            assert!(cone.contains(d), "direction to a sphere point culled");
            assert!(w.length() <= cone.height);
        }
    }
}
