//! Precomputed triangulations of the silhouettes of the non-convex Table 7.1 polyhedra (001
//! Sect. 6.2), checked at random points of every leaf cell against two oracles: the exact
//! silhouette computed on the fly (the triangles' solid angles add up to its solid angle, no
//! triangle is back-facing) and ray casting (a random direction is covered by as many
//! triangles as the number of times, 0 or 1, its ray meets the mesh).

use glam::DVec3;
use penumbra::accel::{Ray, intersect_triangle};
use penumbra::geometry::SilhouettePoint;
use penumbra::geometry::solid_angle_of_triangle;
use penumbra::geometry::{
    BspNode, ExactBspLimits, ExactSilhouetteBsp, ExactSilhouetteScratch, SilhouetteTriangulation,
    SphericalPolygon, TriangulationLimits, exact_silhouette, orient,
};
use penumbra::geometry::{concave_edge_endpoints, triangulate_silhouette};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::TABLE_7_1;
use std::f64::consts::PI;

use crate::silhouette_common;
use silhouette_common::{is_inside, polyhedron, solid_angle, triangles};

fn hits(tris: &[[DVec3; 3]], x: DVec3, w: DVec3) -> bool {
    let ray = Ray::new(x, w);
    tris.iter()
        .any(|t| intersect_triangle(&ray, t[0], t[1], t[2], 1e-12, f64::INFINITY).is_some())
}

/// A random point of a convex cell: a combination of its corners with cubed weights, which
/// pushes points toward the boundary where triangulations fail (001 Sect. 6.2.3).
fn point_in(corners: &[DVec3], rng: &mut Pcg32) -> DVec3 {
    let w: Vec<f64> = corners.iter().map(|_| rng.next_f64().powi(3)).collect();
    let s: f64 = w.iter().sum();
    corners.iter().zip(&w).map(|(&c, &wi)| c * (wi / s)).sum()
}

#[test]
fn triangulations_cover_the_silhouette_exactly_once_in_every_cell() {
    let frame = Frame::from_z(DVec3::Z);
    let mut sph = SphericalPolygon::new();
    let mut scratch = ExactSilhouetteScratch::default();
    let mut rng = Pcg32::new(17, 3);
    for row in TABLE_7_1.iter().filter(|r| !r.convex) {
        // The extruded cube has some 60k cells: two points each.
        let per_cell = if row.name == "extruded_cube" { 2 } else { 8 };
        let poly = polyhedron(row.name);
        let mesh = triangles(&poly);
        let r = 4.0 * poly.radius;
        let (lo, hi) = (poly.center - DVec3::splat(r), poly.center + DVec3::splat(r));
        let (exact, _) =
            ExactSilhouetteBsp::build(&poly, lo, hi, ExactBspLimits::default()).unwrap();
        let (tri, stats) =
            SilhouetteTriangulation::build(&poly, &exact, TriangulationLimits::default());
        eprintln!("{}: {stats:?}", row.name);
        assert!(tri.is_well_formed(poly.vertices.len()));
        let (mut points, mut directions, mut cells) = (0, 0, 0);
        for (n, cell) in tri.leaf_cells(1e-9 * poly.radius) {
            let BspNode::Leaf { first, count } = tri.nodes[n] else {
                unreachable!()
            };
            if count == u32::MAX || cell.is_empty() {
                continue;
            }
            cells += 1;
            let corners: Vec<DVec3> = cell.vertices().collect();
            let tris = &tri.tris[first as usize..(first + count) as usize];
            for _ in 0..per_cell {
                let x = point_in(&corners, &mut rng);
                if is_inside(&mesh, x)
                    || exact_silhouette(&poly, x, &frame, &mut sph, &mut scratch).is_err()
                {
                    continue;
                }
                points += 1;
                let dirs: Vec<[DVec3; 3]> = tris
                    .iter()
                    .map(|t| t.map(|p| SilhouettePoint::unpack(p).direction(&poly, x).unwrap()))
                    .collect();
                let mut total = 0.0;
                for d in &dirs {
                    assert!(
                        orient(d[0], d[1], d[2]) > -1e-12,
                        "{}: a back-facing triangle at {x}",
                        row.name
                    );
                    total += solid_angle_of_triangle(d[0], d[1], d[2]);
                }
                let exact_area = solid_angle(&sph);
                assert!(
                    (total - exact_area).abs() <= 1e-9 * exact_area.max(1.0),
                    "{}: triangles {total} vs silhouette {exact_area} at {x}",
                    row.name
                );
                // Ray casting: directions inside random triangles, and uniform ones.
                for k in 0..6 {
                    let w = if k < 3 && !dirs.is_empty() {
                        let d = dirs
                            [((rng.next_f64() * dirs.len() as f64) as usize).min(dirs.len() - 1)];
                        let (u, v) = (rng.next_f64(), rng.next_f64());
                        let (u, v) = if u + v > 1.0 {
                            (1.0 - u, 1.0 - v)
                        } else {
                            (u, v)
                        };
                        (d[0] * (1.0 - u - v) + d[1] * u + d[2] * v).normalize()
                    } else {
                        let z = 2.0 * rng.next_f64() - 1.0;
                        let phi = 2.0 * PI * rng.next_f64();
                        let s = (1.0 - z * z).sqrt();
                        DVec3::new(s * phi.cos(), s * phi.sin(), z)
                    };
                    let covering = dirs
                        .iter()
                        .filter(|d| {
                            orient(d[0], d[1], w) > 0.0
                                && orient(d[1], d[2], w) > 0.0
                                && orient(d[2], d[0], w) > 0.0
                        })
                        .count();
                    // Directions within rounding of a triangle edge are ambiguous: skip them.
                    let near_edge = dirs.iter().any(|d| {
                        (0..3).any(|e| {
                            let n = d[e].cross(d[(e + 1) % 3]);
                            n.length() > 0.0 && (n.normalize().dot(w)).abs() < 1e-9
                        })
                    });
                    if near_edge {
                        continue;
                    }
                    directions += 1;
                    assert_eq!(
                        covering,
                        hits(&mesh, x, w) as usize,
                        "{}: direction {w} from {x}",
                        row.name
                    );
                }
            }
        }
        eprintln!(
            "{}: {cells} cells, {points} points, {directions} directions",
            row.name
        );
        assert!(
            points > per_cell / 2 * cells,
            "{}: too few points checked",
            row.name
        );
        // Leaves without a proved triangulation are sampled by faces; they must stay rare.
        assert!(
            stats.unproved_volume_fraction < 0.01,
            "{}: {:.3} % of the volume without a proved triangulation",
            row.name,
            100.0 * stats.unproved_volume_fraction
        );
    }
}

/// Silhouettes larger than a hemisphere (from inside the bowl) need the optional vertices.
#[test]
fn a_silhouette_without_a_plain_triangulation_uses_optional_vertices() {
    let poly = polyhedron("bowl");
    let frame = Frame::from_z(DVec3::Z);
    let mut sph = SphericalPolygon::new();
    let mut scratch = ExactSilhouetteScratch::default();
    let mut symbolic = Vec::new();
    let optional = concave_edge_endpoints(&poly);
    assert!(!optional.is_empty());
    let mut rng = Pcg32::new(2, 9);
    let (mut big, mut with_optional) = (0, 0);
    let mut out = Vec::new();
    let mesh = triangles(&poly);
    for _ in 0..4000 {
        let x = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5;
        if is_inside(&mesh, x)
            || exact_silhouette(&poly, x, &frame, &mut sph, &mut scratch).is_err()
        {
            continue;
        }
        let a = solid_angle(&sph);
        if a < 2.0 * PI {
            continue;
        }
        big += 1;
        penumbra::geometry::symbolic_loops(&scratch, &mut symbolic);
        let loops: Vec<Vec<SilhouettePoint>> = symbolic
            .split(|p| p.is_none())
            .filter(|l| !l.is_empty())
            .map(|l| l.iter().map(|p| p.unwrap()).collect())
            .collect();
        let plain = triangulate_silhouette(&poly, &loops, &[], x, &[x], &mut out);
        assert!(
            triangulate_silhouette(&poly, &loops, &optional, x, &[x], &mut out),
            "no triangulation at {x}"
        );
        let total: f64 = out
            .iter()
            .map(|t| {
                let d = t.map(|p| p.direction(&poly, x).unwrap());
                assert!(orient(d[0], d[1], d[2]) > 0.0);
                solid_angle_of_triangle(d[0], d[1], d[2])
            })
            .sum();
        assert!((total - a).abs() < 1e-9, "{total} vs {a}");
        if !plain {
            with_optional += 1;
        }
    }
    eprintln!(
        "bowl: {big} silhouettes over a hemisphere, {with_optional} needed optional vertices"
    );
    assert!(big > 0);
}
