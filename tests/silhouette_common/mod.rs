//! Helpers shared by the silhouette tests: oracles that do not use the code under test (the
//! solid angle of a region of any size, point-in-mesh parity, ray hits) and loop comparison.
#![allow(dead_code)]

use glam::DVec3;
use penumbra::accel::{Ray, intersect_triangle};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::SphericalPolygon;
use penumbra::scene::thesis_polyhedra::thesis_polyhedron;
use std::f64::consts::PI;

/// A polyhedron of 001 Table 7.1 by name.
pub fn polyhedron(name: &str) -> IndexedPolyhedron {
    let m = thesis_polyhedron(name).unwrap();
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

/// The mesh as triangles (its convex faces fanned).
pub fn triangles(p: &IndexedPolyhedron) -> Vec<[DVec3; 3]> {
    p.fan_triangles().map(|(_, t)| t).collect()
}

/// Solid angle of a region of any size: each loop fanned about a fixed direction by Van
/// Oosterom–Strackee with the full-range atan2, summed, taken modulo 4π into [0, 4π).
pub fn solid_angle(poly: &SphericalPolygon) -> f64 {
    let c = DVec3::new(0.267, -0.534, 0.802).normalize();
    let mut total = 0.0;
    for lp in poly.loops() {
        for k in 0..lp.len() {
            let (a, b) = (lp[k].normalize(), lp[(k + 1) % lp.len()].normalize());
            total += 2.0
                * c.dot(a.cross(b))
                    .atan2(1.0 + c.dot(a) + a.dot(b) + b.dot(c));
        }
    }
    total.rem_euclid(4.0 * PI)
}

/// How many of `tris` the ray meets (t ≥ 0).
pub fn hit_count(tris: &[[DVec3; 3]], ray: &Ray) -> usize {
    tris.iter()
        .filter(|t| intersect_triangle(ray, t[0], t[1], t[2], 0.0, f64::INFINITY).is_some())
        .count()
}

/// Whether `x` lies inside the closed mesh `tris`: an odd number of crossings along a fixed ray.
pub fn is_inside(tris: &[[DVec3; 3]], x: DVec3) -> bool {
    hit_count(tris, &Ray::new(x, DVec3::new(0.5773, 0.5774, 0.5775))) % 2 == 1
}

/// The loops of `a` and `b` are the same cyclic sequences of directions (any start, any loop
/// order), to `tol`.
pub fn same_loops(a: &SphericalPolygon, b: &SphericalPolygon, tol: f64) -> bool {
    let la: Vec<&[DVec3]> = a.loops().collect();
    let lb: Vec<&[DVec3]> = b.loops().collect();
    let close = |p: DVec3, q: DVec3| (p.normalize() - q.normalize()).length() <= tol;
    la.len() == lb.len()
        && la.iter().all(|x| {
            lb.iter().any(|y| {
                x.len() == y.len()
                    && (0..y.len()).any(|s| (0..x.len()).all(|k| close(x[k], y[(k + s) % y.len()])))
            })
        })
}
