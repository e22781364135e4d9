//! The geometric predicates of the set difference, all on homogeneous points.
//!
//! A homogeneous point h = (x, y, w), w ≥ 0, is used through its direction ĥ = h/|h| (a point of
//! the closed upper unit hemisphere; never divided by w). A segment of the projection plane is
//! the great-circle arc between its endpoints, and the oriented line through a and b is the
//! plane with normal n = a × b: `orient(a, b, p) = p · (a × b)` is positive when p lies to the
//! left of a → b, with the same sign as the planar orientation when every w > 0 and its exact
//! limit when a point lies on the horizon (w = 0). With unit vectors the normalised
//! determinant p̂ · n̂ is the sine of p's angular distance to the line, which is what every
//! tolerance below is compared with.

use crate::geometry::orient;
use glam::DVec3;

/// Unit normal of the line (great circle) through a and b, oriented so that `p · n > 0` when p
/// lies to the left of a → b. Zero for coincident or antipodal points.
///
/// Computed as a × (b − a) (= a × b): for a short edge b − a is exact (Sterbenz) and the cross
/// product keeps full relative precision, while a × b directly would lose it to cancellation —
/// for an edge of 1e-9 rad its normal would be off by ~1e-7 rad, far above the tolerances.
#[inline]
pub(super) fn unit_normal(a: DVec3, b: DVec3) -> DVec3 {
    a.cross(b - a).normalize_or_zero()
}

/// Whether two unit directions are the same point: sin(angle) < `eps` (the point tolerance
/// [`EPS_POINT`](super::EPS_POINT), or [`COLLAPSE_RADIUS`](super::COLLAPSE_RADIUS) when
/// loading) on the same side.
#[inline]
pub(super) fn coincident(p: DVec3, q: DVec3, eps: f64) -> bool {
    p.dot(q) > 0.0 && p.cross(q).length_squared() < eps * eps
}

/// Whether a unit direction whose signed distance (sine) to a line is `side` lies on it: below
/// `eps`, the line tolerance [`EPS_LINE`](super::EPS_LINE).
#[inline]
pub(super) fn on_line(side: f64, eps: f64) -> bool {
    side.abs() < eps
}

/// Arc coordinates of p relative to the arc a → b with unit normal n: (u, v) with
/// u = (a × p) · n and v = (p × b) · n, the sines of the angles a–p and p–b for p on the arc.
/// Both are positive exactly when p projects strictly inside the arc, and u / (u + v) is the
/// homogeneous parameter t of p = (1 − t)·a + t·b, monotone along the arc.
#[inline]
pub(super) fn arc_coordinates(a: DVec3, b: DVec3, n: DVec3, p: DVec3) -> (f64, f64) {
    (a.cross(p).dot(n), p.cross(b).dot(n))
}

/// The parameter t of [`arc_coordinates`], falling back to `fallback` when undefined.
#[inline]
pub(super) fn arc_parameter(a: DVec3, b: DVec3, n: DVec3, p: DVec3, fallback: f64) -> f64 {
    let (u, v) = arc_coordinates(a, b, n, p);
    if u + v > 0.0 { u / (u + v) } else { fallback }
}

/// Whether signed distances have strictly opposite signs (zero is neither).
#[inline]
pub(super) fn opposite(s: f64, t: f64) -> bool {
    (s < 0.0 && t > 0.0) || (s > 0.0 && t < 0.0)
}

/// Tangent at x of an arc leaving x along the great circle with normal n (walked so that the
/// circle's left side is n's side): n × x. Only the component orthogonal to x matters to
/// `orient(x, ·, ·)`, so tangents can be compared with [`orient`] directly; they are computed
/// from the edge normal, not from a second point, so they stay accurate when the next vertex is
/// very close to x.
#[inline]
pub(super) fn tangent(n: DVec3, x: DVec3) -> DVec3 {
    n.cross(x)
}

/// Whether the tangent `d` at x lies strictly inside the sector swept counter-clockwise from
/// `from` to `to` (the interior of a polygon at a vertex x whose boundary leaves along `from`
/// and arrives from `to`: the interior is to the left).
#[inline]
pub(super) fn in_sector(x: DVec3, from: DVec3, to: DVec3, d: DVec3) -> bool {
    let lo = orient(x, from, d) > 0.0;
    let hi = orient(x, d, to) > 0.0;
    if orient(x, from, to) > 0.0 {
        lo && hi
    } else {
        // Reflex or straight angle: everything but the complementary convex sector.
        lo || hi
    }
}

/// Class of the clockwise angle from `b` to `u` about x: 0 for (0, π), 1 for π, 2 for (π, 2π),
/// 3 for 0 (the same direction, a spike, tried last).
#[inline]
fn clockwise_class(x: DVec3, b: DVec3, u: DVec3) -> u8 {
    let o = orient(x, b, u);
    if o < 0.0 {
        0
    } else if o > 0.0 {
        2
    } else if b.dot(u) < 0.0 {
        1
    } else {
        3
    }
}

/// Whether `u1` is met before `u2` when turning clockwise about x from the tangent `b`.
#[inline]
pub(super) fn clockwise_before(x: DVec3, b: DVec3, u1: DVec3, u2: DVec3) -> bool {
    let c1 = clockwise_class(x, b, u1);
    let c2 = clockwise_class(x, b, u2);
    if c1 != c2 {
        c1 < c2
    } else if c1 == 0 || c1 == 2 {
        orient(x, u1, u2) < 0.0
    } else {
        false
    }
}

/// The ray of the winding-number test from the unit direction p: the arc leaving p radially,
/// away from the zenith, to the horizon point r = (p.x, p.y, 0) (the gnomonic ray from p away
/// from the origin, closed at infinity), continued below the horizon, where no edge lies.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ray {
    /// p = p.z·ẑ + (p.x, p.y, 0): `pz` = p.z and `rr` = p.x² + p.y² (0 at the zenith).
    pz: f64,
    rr: f64,
    /// The horizon point (p.x, p.y, 0), or +x when p is the zenith.
    r: DVec3,
    /// Normal p × r of the ray's great circle (a meridian).
    m: DVec3,
}

impl Ray {
    /// The ray from the unit direction p, or `None` when p is within `eps` (the line tolerance)
    /// of the horizon: such a point is inside no region of the closed upper hemisphere unless
    /// it lies on its boundary, which callers have excluded.
    #[inline]
    pub(super) fn new(p: DVec3, eps: f64) -> Option<Ray> {
        if p.z <= eps {
            return None;
        }
        let r = if p.x == 0.0 && p.y == 0.0 {
            DVec3::X
        } else {
            DVec3::new(p.x, p.y, 0.0)
        };
        Some(Ray {
            pz: p.z,
            rr: p.x * p.x + p.y * p.y,
            r,
            m: p.cross(r),
        })
    }

    /// Contribution of the edge a → b to the winding number about p: ±1 when the arc crosses
    /// the ray (+1 from right to left, i.e. p to the left of a → b), 0 otherwise.
    ///
    /// A vertex v counts as "above" the ray's great circle when v · m > 0 (the half-open rule,
    /// which makes vertices and edges lying on the circle count consistently). An arc with one
    /// end above and one not meets the circle once, at X = a·|b·m| + b·|a·m| (the positive
    /// combination of a and b on it), and is counted when X lies on the ray: on p's side of the
    /// zenith and farther from it than p.
    ///
    /// Locating X on the ray, rather than testing on which side of the line a → b the point p
    /// lies, is what keeps the test exact when p is on (or within rounding of) the *line* of an
    /// edge but far from the edge itself. That is the normal case in scenes of boxes: a
    /// vertical edge seen from a floor point is a meridian, so is the ray, and the vertex of an
    /// earlier occluder above it lies on the same meridian. `orient(a, b, p)` is then rounding
    /// noise and decided the containment of the whole loop at random; the position of X along
    /// the ray is as accurate as X itself, and is ambiguous only when X is within rounding of p,
    /// i.e. when p lies on the boundary, which callers exclude.
    #[inline]
    pub(super) fn winding_contribution(&self, a: DVec3, b: DVec3) -> i32 {
        let (sa, sb) = (a.dot(self.m), b.dot(self.m));
        let above_a = sa > 0.0;
        if above_a == (sb > 0.0) {
            return 0;
        }
        let x = a * sb.abs() + b * sa.abs();
        // On the circle, x ∝ x.z·ẑ + q·r / |r|² with q = x · r: on p's side of the zenith when
        // q > 0, and farther from it than p = p.z·ẑ + r when x.z / q < p.z / |r|², here
        // multiplied by q·|r|² (no division or square root; at the zenith |r|² = 0 and every
        // x with q > 0 is farther).
        let q = x.dot(self.r);
        if q > 0.0 && x.z * self.rr < self.pz * q {
            if above_a { -1 } else { 1 }
        } else {
            0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h(x: f64, y: f64, w: f64) -> DVec3 {
        DVec3::new(x, y, w).normalize()
    }

    #[test]
    fn sector_of_a_convex_and_a_reflex_corner() {
        // Corner at the origin of the plane, boundary arriving from the north and leaving east:
        // the interior, left of the boundary, is the north-east quadrant (counter-clockwise
        // from east to north).
        let x = h(0.0, 0.0, 1.0);
        let east = tangent(unit_normal(x, h(1.0, 0.0, 1.0)), x);
        let north = tangent(unit_normal(x, h(0.0, 1.0, 1.0)), x);
        let ne = tangent(unit_normal(x, h(1.0, 1.0, 1.0)), x);
        let sw = tangent(unit_normal(x, h(-1.0, -1.0, 1.0)), x);
        assert!(in_sector(x, east, north, ne));
        assert!(!in_sector(x, east, north, sw));
        // Reflex: leaving north, arriving from the east.
        assert!(!in_sector(x, north, east, ne));
        assert!(in_sector(x, north, east, sw));
    }

    #[test]
    fn clockwise_order_about_a_point() {
        let x = h(0.0, 0.0, 1.0);
        let dir = |dx: f64, dy: f64| tangent(unit_normal(x, h(dx, dy, 1.0)), x);
        let west = dir(-1.0, 0.0);
        // Clockwise from west: north-west, north, east, south.
        assert!(clockwise_before(x, west, dir(-1.0, 1.0), dir(0.0, 1.0)));
        assert!(clockwise_before(x, west, dir(0.0, 1.0), dir(1.0, 0.0)));
        assert!(clockwise_before(x, west, dir(1.0, 0.0), dir(0.0, -1.0)));
        assert!(!clockwise_before(x, west, dir(0.0, -1.0), dir(-1.0, 1.0)));
    }

    #[test]
    fn winding_counts_horizon_edges() {
        // The quadrant x, y > 0 of the plane: zenith, +x at infinity, +y at infinity.
        let lp = [DVec3::Z, DVec3::X, DVec3::Y];
        let wind = |p: DVec3| {
            let ray = Ray::new(p, 1e-12).unwrap();
            (0..3)
                .map(|i| ray.winding_contribution(lp[i], lp[(i + 1) % 3]))
                .sum::<i32>()
        };
        assert_eq!(wind(h(0.5, 0.5, 1.0)), 1);
        assert_eq!(wind(h(5.0, 0.1, 1.0)), 1);
        assert_eq!(wind(h(-0.5, 0.5, 1.0)), 0);
        assert_eq!(wind(h(0.5, -0.5, 1.0)), 0);
        assert_eq!(wind(h(-1.0, -1.0, 1.0)), 0);
        // The zenith itself (its ray runs along +x).
        let square = [
            h(-1.0, -1.0, 1.0),
            h(1.0, -1.0, 1.0),
            h(1.0, 1.0, 1.0),
            h(-1.0, 1.0, 1.0),
        ];
        for (dx, expected) in [(0.0, 1), (1.5, 0), (-1.5, 0)] {
            let shifted = square.map(|v| h(v.x / v.z + dx, v.y / v.z, 1.0));
            let ray = Ray::new(DVec3::Z, 1e-12).unwrap();
            let w: i32 = (0..4)
                .map(|i| ray.winding_contribution(shifted[i], shifted[(i + 1) % 4]))
                .sum();
            assert_eq!(w, expected, "square shifted by {dx}");
        }
    }

    #[test]
    fn winding_along_the_meridian_of_an_edge() {
        // A box resting on the floor seen from a floor point: its vertical edge is a meridian,
        // and the test point above it lies on the same meridian (outside the region), so the
        // ray runs along the edge and p is on the edge's line.
        let sph = |az: f64, el: f64| {
            let (az, el) = (az.to_radians(), el.to_radians());
            DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin())
        };
        for k in 0..3600 {
            let az = k as f64 * 0.1 + 0.0123;
            let lp = [
                sph(az, 0.0),
                sph(az + 15.0, 0.0),
                sph(az + 15.0, 40.0),
                sph(az, 40.0),
            ];
            let wind = |p: DVec3| {
                let ray = Ray::new(p, 1e-12).unwrap();
                (0..4)
                    .map(|i| ray.winding_contribution(lp[i], lp[(i + 1) % 4]))
                    .sum::<i32>()
            };
            assert_eq!(wind(sph(az, 60.0)), 0, "above the edge, azimuth {az}");
            assert_eq!(wind(sph(az + 7.0, 20.0)), 1, "inside, azimuth {az}");
            assert_eq!(wind(sph(az - 7.0, 20.0)), 0, "beside, azimuth {az}");
        }
    }
}
