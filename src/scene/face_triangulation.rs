//! Triangulating a planar polygon that is not convex *inside itself*: the fan from its first
//! vertex, which `Mesh::triangles` and every convex-face test assume, folds outside a
//! non-convex polygon (an L-shaped or star-shaped cap, a letter's outline) and covers area
//! the face does not have.
//!
//! Ear clipping in the polygon's plane (Meisters' two-ears theorem: a simple polygon of more
//! than three vertices has two non-overlapping ears, so clipping one at a time always
//! succeeds). Of the ears available, the one whose triangle is the least thin is clipped
//! first, which keeps slivers out of the per-triangle method and the BVH. A polygon with no
//! ear is not simple (it crosses itself); it is left to the caller.

use crate::math::Frame;
use glam::{DVec2, DVec3};

/// The triangles (indices into `pts`, counter-clockwise like the polygon) of a planar simple
/// polygon, or `None` when it has no ear at some step (it is not simple). `slack` is the area
/// (twice the triangle area, in the polygon's units squared) below which a corner counts as
/// straight rather than convex: the rounding of the input (see `precision`).
pub fn ear_clip(pts: &[DVec3], slack: f64) -> Option<Vec<[usize; 3]>> {
    let m = pts.len();
    if m < 3 {
        return None;
    }
    if m == 3 {
        return Some(vec![[0, 1, 2]]);
    }
    let n = super::shapes::polygon_area_vector(pts).try_normalize()?;
    let frame = Frame::from_z(n);
    let o = pts[0];
    // In the plane, with the polygon counter-clockwise (Newell's normal is its front).
    let p: Vec<DVec2> = pts
        .iter()
        .map(|&q| DVec2::new(frame.x.dot(q - o), frame.y.dot(q - o)))
        .collect();
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let mut ring: Vec<usize> = (0..m).collect();
    let mut out = Vec::with_capacity(m - 2);
    while ring.len() > 3 {
        let k = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..k {
            let (a, b, c) = (ring[(i + k - 1) % k], ring[i], ring[(i + 1) % k]);
            let twice_area = cross(p[a], p[b], p[c]);
            if twice_area <= slack {
                continue; // reflex or straight: not an ear
            }
            // No other remaining vertex inside the triangle or on its boundary (a vertex at
            // the same position as a corner, as in a polygon touching itself, is the corner).
            let blocked = ring.iter().any(|&j| {
                if j == a || j == b || j == c || [a, b, c].iter().any(|&t| p[t] == p[j]) {
                    return false;
                }
                cross(p[a], p[b], p[j]) >= -slack
                    && cross(p[b], p[c], p[j]) >= -slack
                    && cross(p[c], p[a], p[j]) >= -slack
            });
            if blocked {
                continue;
            }
            // Thinness: area over the sum of squared sides (largest for an equilateral).
            let sides = (p[b] - p[a]).length_squared()
                + (p[c] - p[b]).length_squared()
                + (p[a] - p[c]).length_squared();
            let quality = twice_area / sides.max(f64::MIN_POSITIVE);
            if best.is_none_or(|(q, _)| quality > q) {
                best = Some((quality, i));
            }
        }
        let (_, i) = best?;
        let k = ring.len();
        out.push([ring[(i + k - 1) % k], ring[i], ring[(i + 1) % k]]);
        ring.remove(i);
    }
    // The last triangle, unless what is left is a straight line (collinear vertices).
    if cross(p[ring[0]], p[ring[1]], p[ring[2]]) > slack {
        out.push([ring[0], ring[1], ring[2]]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(pts: &[DVec3]) -> f64 {
        super::super::shapes::polygon_area_vector(pts).length()
    }

    /// The triangles tile the polygon: their areas add up to its area, every one is
    /// counter-clockwise about the polygon's normal, and sampled points of the polygon lie in
    /// exactly one triangle (points outside it in none).
    fn check_tiling(pts: &[DVec3]) {
        let tris = ear_clip(pts, 1e-12).expect("a simple polygon has ears");
        assert_eq!(tris.len(), pts.len() - 2);
        let n = super::super::shapes::polygon_area_vector(pts).normalize();
        let mut sum = 0.0;
        for t in &tris {
            let tp = [pts[t[0]], pts[t[1]], pts[t[2]]];
            let a = super::super::shapes::polygon_area_vector(&tp);
            assert!(a.dot(n) > 0.0, "triangle {t:?} is counter-clockwise");
            sum += a.length();
        }
        assert!(
            (sum - area(pts)).abs() <= 1e-12 * area(pts),
            "{sum} vs {}",
            area(pts)
        );
        // Even-odd containment in the polygon (2D, in its plane) against the triangle count.
        let f = Frame::from_z(n);
        let q: Vec<DVec2> = pts
            .iter()
            .map(|&v| DVec2::new(f.x.dot(v), f.y.dot(v)))
            .collect();
        let (lo, hi) = q
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let mut rng = crate::math::Pcg32::new(5, pts.len() as u64);
        for _ in 0..2000 {
            let x = DVec2::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y));
            let mut inside = false;
            for i in 0..q.len() {
                let (a, b) = (q[i], q[(i + 1) % q.len()]);
                if (a.y > x.y) != (b.y > x.y) && x.x < a.x + (x.y - a.y) / (b.y - a.y) * (b.x - a.x)
                {
                    inside = !inside;
                }
            }
            let covering = tris
                .iter()
                .filter(|t| {
                    let (a, b, c) = (q[t[0]], q[t[1]], q[t[2]]);
                    (b - a).perp_dot(x - a) > 0.0
                        && (c - b).perp_dot(x - b) > 0.0
                        && (a - c).perp_dot(x - c) > 0.0
                })
                .count();
            assert_eq!(covering, inside as usize, "point {x}");
        }
    }

    #[test]
    fn non_convex_polygons_are_tiled_inside_themselves() {
        // An L in a tilted plane, a star, a comb, and a convex polygon.
        let tilt =
            |v: DVec2| DVec3::new(v.x, 0.3 * v.x + 0.5 * v.y, v.y) + DVec3::new(3.0, -2.0, 1.0);
        let outline = |pts: &[(f64, f64)]| -> Vec<DVec3> {
            pts.iter().map(|&(x, y)| tilt(DVec2::new(x, y))).collect()
        };
        let around = |n: usize, r: &dyn Fn(usize) -> f64| -> Vec<DVec3> {
            (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    tilt(DVec2::new(r(k) * a.cos(), r(k) * a.sin()))
                })
                .collect()
        };
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ];
        check_tiling(&outline(&l));
        check_tiling(&around(14, &|k| if k % 2 == 0 { 1.0 } else { 0.35 }));
        let comb = [
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 3.0),
            (4.0, 3.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ];
        check_tiling(&outline(&comb));
        let hexagon = around(6, &|_| 1.0);
        check_tiling(&hexagon);
    }

    #[test]
    fn a_figure_eight_has_no_triangulation() {
        // Its two lobes cancel: no plane orientation, no ears to trust.
        let eight = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        assert!(ear_clip(&eight, 1e-12).is_none());
    }
}
