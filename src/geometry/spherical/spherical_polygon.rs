use crate::geometry::PolygonLoops;
use glam::DVec3;
use std::ops::{Deref, DerefMut};

/// Orientation of three directions: the sign of det(a, b, c) = a · (b × c).
///
/// For points on the unit sphere it is positive when a → b → c turns counter-clockwise seen
/// from outside the sphere; for homogeneous points of the plane (w > 0) it is the planar
/// orientation of (a/w, b/w, c/w) scaled by the positive factor w_a·w_b·w_c.
#[inline]
pub fn orient(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    a.dot(b.cross(c))
}

/// Solid angle of the spherical triangle (a, b, c) of unit vectors, positive when
/// counter-clockwise seen from outside (Van Oosterom and Strackee 1983).
#[inline]
pub fn solid_angle_of_triangle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    2.0 * orient(a, b - a, c - a).atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

/// A region of the unit sphere bounded by closed loops of great-circle arcs (each arc shorter
/// than π), stored in a shading frame whose z axis is the surface normal.
///
/// Orientation convention (used by every stage): a loop bounding a filled region is
/// **positively oriented**, i.e. counter-clockwise seen from outside the sphere, so that
/// det(a, b, c) > 0 for a small convex triangle a → b → c and the Baum et al. edge integral of the
/// loop is positive. Holes are negatively oriented. Seen from the shading point (the centre), a
/// positive loop turns clockwise: the silhouette stage reverses the counter-clockwise winding of
/// front faces accordingly.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SphericalPolygon(pub PolygonLoops);

impl Deref for SphericalPolygon {
    type Target = PolygonLoops;
    fn deref(&self) -> &PolygonLoops {
        &self.0
    }
}

impl DerefMut for SphericalPolygon {
    fn deref_mut(&mut self) -> &mut PolygonLoops {
        &mut self.0
    }
}

impl SphericalPolygon {
    pub fn new() -> Self {
        Self::default()
    }

    /// Signed solid angle of the region (steradians), summed loop by loop as fans of spherical
    /// triangles about the reference direction `c` with the formula of Van Oosterom and
    /// Strackee (1983): tan(Ω/2) = det(c, a, b) / (1 + c·a + a·b + b·c).
    ///
    /// Exact for regions inside the open hemisphere around `c` (every triangle of the fan is
    /// then smaller than a hemisphere); horizon-clipped polygons satisfy this for c = +z.
    pub fn signed_solid_angle_about(&self, c: DVec3) -> f64 {
        let mut total = 0.0;
        for lp in self.loops() {
            let n = lp.len();
            for i in 0..n {
                let a = lp[i];
                let b = lp[(i + 1) % n];
                let det = orient(c, a, b);
                let den = 1.0 + c.dot(a) + a.dot(b) + b.dot(c);
                total += 2.0 * det.atan2(den);
            }
        }
        total
    }

    /// Signed solid angle about the mean direction of the vertices (+z when the mean vanishes);
    /// see [`SphericalPolygon::signed_solid_angle_about`] for when it is exact.
    pub fn signed_solid_angle(&self) -> f64 {
        let sum: DVec3 = self.vertices().iter().copied().sum();
        let c = sum.try_normalize().unwrap_or(DVec3::Z);
        self.signed_solid_angle_about(c)
    }

    /// Whether the unit direction `v` lies in the region or within the angle `tol` of its
    /// boundary: on an arc (to within `tol`), or with a winding number of the loops about `v`
    /// of at least one (filled loops count +1, holes −1). The winding number sums the signed
    /// angles at `v` between the tangent directions to the ends of each arc, which is exact for
    /// arcs shorter than π not passing through `v` or `−v`.
    pub fn contains_within(&self, v: DVec3, tol: f64) -> bool {
        // Near the boundary first: those tests are products, the winding number takes an
        // atan2 per arc, and the points asked about (a visible polygon's vertices, by the
        // invariant) mostly lie on the boundary.
        let near_boundary = self.loops().any(|lp| {
            let n = lp.len();
            (0..n).any(|i| {
                let (a, b) = (lp[i], lp[(i + 1) % n]);
                let m = a.cross(b);
                near_arc_start(a, b, m, m.length().max(f64::MIN_POSITIVE), v, tol)
            })
        });
        if near_boundary {
            return true;
        }
        let mut turn = 0.0;
        for lp in self.loops() {
            let n = lp.len();
            for i in 0..n {
                let (a, b) = (lp[i], lp[(i + 1) % n]);
                let pa = a - v * v.dot(a);
                let pb = b - v * v.dot(b);
                turn += v.dot(pa.cross(pb)).atan2(pa.dot(pb));
            }
        }
        turn > std::f64::consts::PI
    }
}

/// The edges `(p_i, p_{i+1})` of a closed loop, the last one back to the first (no modulo per
/// step: these loops are walked per shading point).
#[inline]
pub(crate) fn edges_of(lp: &[DVec3]) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
    lp.iter()
        .zip(lp.iter().skip(1).chain(lp.first()))
        .map(|(&p, &q)| (p, q))
}

/// The turn [`orient`]`(p_{i−1}, p_i, p_{i+1})` at every vertex of a closed loop, in order.
#[inline]
pub(crate) fn turns(lp: &[DVec3]) -> impl Iterator<Item = f64> + '_ {
    lp.last()
        .into_iter()
        .chain(lp.iter())
        .zip(lp.iter().zip(lp.iter().skip(1).chain(lp.first())))
        .map(|(&a, (&b, &c))| orient(a, b, c))
}

/// [`SphericalPolygon::contains_within`]'s boundary test for the arc a → b, whose normal
/// `m = a × b` has length `len`: `v` lies on the arc to within the angle `tol`, or within
/// `tol` of its start `a`.
#[inline]
pub(crate) fn near_arc_start(a: DVec3, b: DVec3, m: DVec3, len: f64, v: DVec3, tol: f64) -> bool {
    let on_circle = m.dot(v).abs() <= tol * len;
    on_circle && a.cross(v).dot(m) >= 0.0 && v.cross(b).dot(m) >= 0.0
        || v.distance_squared(a) <= tol * tol
}

/// The convex loop `subject` (unit directions) clipped to the half-spaces `d·n ≥ 0` of `normals`
/// (Sutherland–Hodgman, each plane through the centre, so each side is a great circle), into
/// `out`: empty when fewer than three points are left. Crossings are taken on the chords and
/// normalised, so they lie on both circles up to rounding. A vertex on a side's circle is kept
/// and not crossed again, and no point repeats its predecessor (within 1e-12): the set
/// difference wants no repeated vertices. Bound: one pass per plane, at most two points per
/// vertex. `tmp` is scratch.
pub(crate) fn clip_loop_to_half_spaces(
    subject: &[DVec3],
    normals: &[DVec3],
    out: &mut Vec<DVec3>,
    tmp: &mut Vec<DVec3>,
) {
    let push_distinct = |buf: &mut Vec<DVec3>, v: DVec3| {
        if buf.last().is_none_or(|&l| (l - v).length_squared() > 1e-24) {
            buf.push(v);
        }
    };
    out.clear();
    out.extend_from_slice(subject);
    for (pass, &n) in normals.iter().enumerate() {
        // A loop wholly inside the half-space is kept as it is: after the first pass it has no
        // repeated neighbours left to drop, so the pass would copy it unchanged.
        if pass > 0 && out.iter().all(|&p| n.dot(p) >= 0.0) {
            continue;
        }
        tmp.clear();
        let k = out.len();
        let Some(&first) = out.first() else {
            break;
        };
        let (mut p, mut dp) = (first, n.dot(first));
        for j in 0..k {
            let q = if j + 1 == k { first } else { out[j + 1] };
            let dq = n.dot(q);
            if dp >= 0.0 {
                push_distinct(tmp, p);
            }
            if (dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0) {
                let t = dp / (dp - dq);
                if let Some(v) = (p + t * (q - p)).try_normalize() {
                    push_distinct(tmp, v);
                }
            }
            (p, dp) = (q, dq);
        }
        while tmp.len() > 1 && (tmp[0] - tmp[tmp.len() - 1]).length_squared() <= 1e-24 {
            tmp.pop();
        }
        std::mem::swap(out, tmp);
        if out.is_empty() {
            break;
        }
    }
    if out.len() < 3 {
        out.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_util::contains;
    use crate::math::Pcg32;

    #[test]
    fn solid_angle_matches_monte_carlo() {
        let mut rng = Pcg32::new(11, 3);
        for case in 0..20 {
            // A random convex-ish star polygon around a random direction, inside a hemisphere.
            let c = rng.unit_vector();
            let f = crate::math::Frame::from_z(c);
            let n = 3 + rng.below(6) as usize;
            let spread = rng.range(0.05, 1.2);
            let mut poly = SphericalPolygon::new();
            // Star-shaped about c (angle gaps below π), hence positively oriented.
            let angles: Vec<f64> = (0..n)
                .map(|k| (k as f64 + 0.8 * rng.next_f64()) * std::f64::consts::TAU / n as f64)
                .collect();
            poly.push_loop(angles.iter().map(|&a| {
                let r = spread * rng.range(0.3, 1.0);
                f.to_world(DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize())
            }));
            let exact = poly.signed_solid_angle();
            let samples = 200_000;
            let mut hits = 0u32;
            for _ in 0..samples {
                if contains(&poly, rng.unit_vector(), -c) {
                    hits += 1;
                }
            }
            let p = hits as f64 / samples as f64;
            let mc = 4.0 * std::f64::consts::PI * p;
            let sigma = 4.0 * std::f64::consts::PI * (p * (1.0 - p) / samples as f64).sqrt();
            assert!(
                (exact - mc).abs() <= 4.5 * sigma + 1e-12,
                "case {case}: exact {exact} vs MC {mc} ± {sigma}"
            );
        }
    }

    /// `contains_within` against the Monte Carlo oracle's even-odd `contains` on a polygon
    /// with a hole, and on the boundary: its vertices and the midpoints of its arcs.
    #[test]
    fn containment_with_a_hole_and_on_the_boundary() {
        let ring = |r: f64, n: usize, ccw: bool| -> Vec<DVec3> {
            (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    let a = if ccw { a } else { -a };
                    DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize()
                })
                .collect()
        };
        let mut poly = SphericalPolygon::new();
        poly.push_loop(ring(0.8, 7, true));
        poly.push_loop(ring(0.3, 5, false));
        let mut rng = Pcg32::new(4, 9);
        for _ in 0..5000 {
            let v = rng.unit_vector();
            assert_eq!(
                poly.contains_within(v, 1e-12),
                contains(&poly, v, -DVec3::Z),
                "{v}"
            );
        }
        for lp in poly.loops() {
            for i in 0..lp.len() {
                let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
                assert!(poly.contains_within(a, 1e-12));
                assert!(poly.contains_within((a + b).normalize(), 1e-12));
            }
        }
    }

    #[test]
    fn reversing_a_loop_negates_its_solid_angle() {
        let mut poly = SphericalPolygon::new();
        poly.push_loop([DVec3::X, DVec3::Y, DVec3::Z]);
        // One octant: 4π / 8.
        assert!((poly.signed_solid_angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-14);
        poly.reverse_loops();
        assert!((poly.signed_solid_angle() + std::f64::consts::FRAC_PI_2).abs() < 1e-14);
    }
}
