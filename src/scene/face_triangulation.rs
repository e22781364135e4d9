//! The one surface every method sees (docs/scenes.md, "The surface of a face"): which loaded
//! faces stay polygons and which are split into triangles, and how.
//!
//! The analytic method, the per-triangle method and the ray-cast oracle must agree on the
//! surface a face stands for. A planar convex polygon is one surface however it is fanned, so
//! it stays one face (a quad light stays one face, which the silhouette stages prefer). Every
//! other face is split here, once, when it is loaded, and the triangles replace it in
//! `Mesh::faces`:
//!
//! * a face **not planar** beyond the rounding of the digits it was written with (a subdivided
//!   quad): its spherical image folds into a bow tie where a point sees it nearly edge-on, and
//!   no single plane decides which side of it a point is on;
//! * a planar face **not convex** (an L-shaped cap, a letter's outline): a fan from its first
//!   vertex folds outside it;
//! * a face that **touches itself** (a hole bridged by a keyhole slit: a vertex visited twice).
//!
//! The triangles come from ear clipping in the plane of Newell's normal (Meisters' two-ears
//! theorem: a simple polygon of more than three vertices has two non-overlapping ears, so
//! clipping one at a time always succeeds). Of the ears available, the one whose triangle is
//! the least thin is clipped first, which keeps slivers out of the per-triangle method and the
//! BVH. A face with no ear at some step (its projection crosses itself) is fanned from its
//! first vertex, with a warning: a defined surface, if not the one its author meant.

use super::precision::{planarity_tolerance, plane_deviation};
use crate::math::Frame;
use glam::{DVec2, DVec3};

/// Why a face was split into triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Split {
    /// Not planar: a vertex `off` from the face's plane, where the rounding of the input
    /// explains `tolerance`.
    NonPlanar { off: f64, tolerance: f64 },
    /// Planar but not convex.
    NonConvex,
    /// It visits a position twice: a hole bridged by a keyhole slit, or a face pinched at a
    /// vertex.
    Keyhole,
}

/// What a loaded face becomes (see the module's documentation).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum FaceSurface {
    /// Planar up to its rounding and convex: kept as one polygon.
    Polygon,
    /// Split into these triangles (indices into the face's vertices, counter-clockwise like
    /// the face); `fanned` when ear clipping found no ear and the face was fanned from its first
    /// vertex instead.
    Triangles {
        tris: Vec<[usize; 3]>,
        why: Split,
        fanned: bool,
    },
    /// A face that touches itself and has no ear: no triangulation of it is a surface (a fan
    /// would cross the slit); the caller drops it with a warning.
    NoSurface,
}

/// The surface of the face `pts` (at least three vertices, positions as loaded, no two
/// consecutive ones equal), whose vertices were written with rounding radius `rounding`
/// (`Mesh::rounding`).
pub(crate) fn face_surface(pts: &[DVec3], rounding: f64) -> FaceSurface {
    let m = pts.len();
    let touches_itself = (0..m).any(|a| (a + 1..m).any(|b| pts[a] == pts[b]));
    let why = if m == 3 {
        return FaceSurface::Polygon;
    } else if touches_itself {
        Split::Keyhole
    } else {
        // Planar up to the rounding of its digits: what the author meant planar stays one
        // polygon (a quad light, a 32-gon cap, whose triangles would be slivers whose planes
        // the rounding tilts). Its image folds only where a point lies within the rounding of
        // its plane, where it subtends no solid angle to speak of.
        let off = plane_deviation(pts);
        let tolerance = planarity_tolerance(pts, rounding);
        if off > tolerance {
            Split::NonPlanar { off, tolerance }
        } else if is_convex(pts, rounding) {
            return FaceSurface::Polygon;
        } else {
            Split::NonConvex
        }
    };
    match ear_clip(pts, turn_slack(pts, rounding)) {
        Some(tris) if !tris.is_empty() => FaceSurface::Triangles {
            tris,
            why,
            fanned: false,
        },
        _ if why == Split::Keyhole => FaceSurface::NoSurface,
        _ => FaceSurface::Triangles {
            tris: (1..m - 1).map(|k| [0, k, k + 1]).collect(),
            why,
            fanned: true,
        },
    }
}

/// Every corner of the face `pts` turns the way of its Newell normal (up to [`turn_slack`]).
fn is_convex(pts: &[DVec3], rounding: f64) -> bool {
    let Some(n) = crate::math::polygon_area_vector(pts.iter().copied()).try_normalize() else {
        return true;
    };
    let m = pts.len();
    let slack = turn_slack(pts, rounding);
    (0..m).all(|k| {
        let (a, b, c) = (pts[k], pts[(k + 1) % m], pts[(k + 2) % m]);
        (b - a).cross(c - b).dot(n) >= -slack
    })
}

/// How far a corner of the face `pts` may turn the wrong way (as the cross product of its two
/// edges, an area) and still count as straight: what moving its vertex by `rounding` can do,
/// and never less than the f64 rounding of that product.
fn turn_slack(pts: &[DVec3], rounding: f64) -> f64 {
    let longest = (0..pts.len())
        .map(|k| pts[k].distance(pts[(k + 1) % pts.len()]))
        .fold(0.0, f64::max);
    (2.0 * rounding * longest).max(1e-12 * longest * longest)
}

/// The triangles (indices into `pts`, counter-clockwise like the polygon) of a planar simple
/// polygon, or `None` when it has no ear at some step (it is not simple). `slack` is the area
/// (twice the triangle area, in the polygon's units squared) below which a corner counts as
/// straight rather than convex: the rounding of the input (see `precision`).
pub(crate) fn ear_clip(pts: &[DVec3], slack: f64) -> Option<Vec<[usize; 3]>> {
    let m = pts.len();
    if m < 3 {
        return None;
    }
    if m == 3 {
        return Some(vec![[0, 1, 2]]);
    }
    let n = crate::math::polygon_area_vector(pts.iter().copied()).try_normalize()?;
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
        crate::math::polygon_area_vector(pts.iter().copied()).length()
    }

    /// The triangles tile the polygon: their areas add up to its area, every one is
    /// counter-clockwise about the polygon's normal, and sampled points of the polygon lie in
    /// exactly one triangle (points outside it in none).
    fn check_tiling(pts: &[DVec3]) {
        let tris = ear_clip(pts, 1e-12).expect("a simple polygon has ears");
        assert_eq!(tris.len(), pts.len() - 2);
        let n = crate::math::polygon_area_vector(pts.iter().copied()).normalize();
        let mut sum = 0.0;
        for t in &tris {
            let tp = [pts[t[0]], pts[t[1]], pts[t[2]]];
            let a = crate::math::polygon_area_vector(tp.iter().copied());
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

    /// A square with a square hole, bridged by a keyhole slit (the corner and the hole's first
    /// vertex each visited twice), in a tilted plane: tiled inside itself, the hole left
    /// uncovered (`check_tiling`'s even-odd rule sees the slit's two edges cancel).
    #[test]
    fn a_keyhole_face_is_tiled_around_its_hole() {
        let tilt =
            |x: f64, y: f64| DVec3::new(x, 0.2 * x - 0.4 * y, y) + DVec3::new(-1.0, 2.0, 0.5);
        let ring = [
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0),
            (0.0, 4.0),
            (0.0, 0.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (3.0, 3.0),
            (3.0, 1.0),
            (1.0, 1.0),
        ];
        let pts: Vec<DVec3> = ring.iter().map(|&(x, y)| tilt(x, y)).collect();
        check_tiling(&pts);
        match face_surface(&pts, 0.0) {
            FaceSurface::Triangles { tris, why, fanned } => {
                assert_eq!(why, Split::Keyhole);
                assert!(!fanned);
                assert_eq!(tris.len(), 8);
            }
            other => panic!("{other:?}"),
        }
    }

    /// A quad bent out of its plane far beyond its rounding is split along one diagonal; a
    /// planar convex quad, also one bent by its rounding only, stays one polygon; an L is
    /// planar but split.
    #[test]
    fn the_surface_of_a_face() {
        let bent = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 2e-3),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        match face_surface(&bent, 5e-7) {
            FaceSurface::Triangles { tris, why, fanned } => {
                assert!(matches!(why, Split::NonPlanar { off, .. } if off > 1e-4));
                assert!(!fanned);
                assert_eq!(tris.len(), 2);
                // The two triangles share a diagonal and cover all four corners.
                let mut used = [0; 4];
                tris.iter().flatten().for_each(|&k| used[k] += 1);
                assert_eq!(used.iter().sum::<i32>(), 6);
                assert!(used.iter().all(|&u| u >= 1));
            }
            other => panic!("{other:?}"),
        }
        // A parallelogram in a general position, rounded to 6 decimals as Blender writes it.
        let r = |v: DVec3| (v * 1e6).round() / 1e6;
        let p0 = DVec3::new(0.1234567891, 0.2345678912, 0.3456789123);
        let u = DVec3::new(0.7123456789, 0.3321987654, 0.1234567);
        let v = DVec3::new(-0.2734191827, 0.5791364528, 0.8123457);
        let rounded = [r(p0), r(p0 + u), r(p0 + u + v), r(p0 + v)];
        assert!(plane_deviation(&rounded) > 1e-9);
        assert_eq!(face_surface(&rounded, 5e-7), FaceSurface::Polygon);
        let planar = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(2.0, 1.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        assert_eq!(face_surface(&planar, 5e-7), FaceSurface::Polygon);
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ];
        let l: Vec<DVec3> = l.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
        assert!(matches!(
            face_surface(&l, 0.0),
            FaceSurface::Triangles {
                why: Split::NonConvex,
                fanned: false,
                ..
            }
        ));
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
