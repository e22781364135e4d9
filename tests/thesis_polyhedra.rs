//! The nine test polyhedra of 001 Table 7.1: their counts, convexity and star-shapedness as the
//! table gives them, and the star centre checked by an oracle that does not use the kernel
//! (segments from the centre to points all over the surface cross no face on the way).

use glam::DVec3;
use penumbra::accel::{Ray, intersect_triangle};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{kernel, star_centre};
use penumbra::math::Pcg32;
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};

fn polyhedron(name: &str) -> IndexedPolyhedron {
    let m = thesis_polyhedron(name).unwrap();
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

fn triangles(p: &IndexedPolyhedron) -> Vec<[DVec3; 3]> {
    p.fan_triangles().map(|(_, t)| t).collect()
}

#[test]
fn counts_and_classes_match_table_7_1() {
    for row in TABLE_7_1 {
        let p = polyhedron(row.name);
        let c = p.feature_counts();
        assert_eq!(
            (c.vertices, c.edges, c.faces),
            (row.vertices, row.edges, row.faces),
            "{}",
            row.name
        );
        assert!(p.diagnostics.closed_manifold, "{} is not closed", row.name);
        assert_eq!(p.diagnostics.nonplanar_faces, 0, "{}", row.name);
        assert!(p.signed_volume() > 0.0, "{} is inside out", row.name);
        assert_eq!(p.diagnostics.convex, row.convex, "{} convexity", row.name);
        assert_eq!(
            star_centre(&p).is_some(),
            row.star_shaped,
            "{} star-shapedness",
            row.name
        );
    }
}

/// A kernel point sees the whole surface: the segment to any surface point meets no other part
/// of the mesh first. For the meshes that are not star-shaped, no point of a fine grid in the
/// bounding box passes the same test on a fixed set of surface points (a second, brute-force
/// search for a centre).
#[test]
fn star_centres_see_the_whole_surface() {
    let mut rng = Pcg32::new(7, 1);
    let sees_all = |centre: DVec3, tris: &[[DVec3; 3]], targets: &[DVec3]| {
        targets.iter().all(|&q| {
            let ray = Ray::new(centre, q - centre);
            // Hits strictly before the target (t < 1) by a margin: the target's own face is hit
            // at t = 1.
            !tris
                .iter()
                .any(|t| intersect_triangle(&ray, t[0], t[1], t[2], 1e-9, 1.0 - 1e-7).is_some())
        })
    };
    for row in TABLE_7_1 {
        let p = polyhedron(row.name);
        let tris = triangles(&p);
        let area = |t: &[DVec3; 3]| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let total: f64 = tris.iter().map(area).sum();
        // Area-uniform surface points.
        let targets: Vec<DVec3> = (0..400)
            .map(|_| {
                let mut u = rng.next_f64() * total;
                let t = tris
                    .iter()
                    .find(|t| {
                        u -= area(t);
                        u <= 0.0
                    })
                    .unwrap_or(tris.last().unwrap());
                let (a, b) = (rng.next_f64(), rng.next_f64());
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b
            })
            .collect();
        match star_centre(&p) {
            Some(c) => {
                assert!(p.face_planes.iter().all(|pl| pl.eval(c) < 0.0));
                assert!(
                    sees_all(c, &tris, &targets),
                    "{}: centre {c} is blocked",
                    row.name
                );
                assert!(kernel(&p).volume() > 0.0);
            }
            None => {
                let n = 12;
                for i in 0..n * n * n {
                    let g = DVec3::new((i % n) as f64, ((i / n) % n) as f64, (i / n / n) as f64);
                    let x = p.center + (g + 0.5) / n as f64 * 2.0 * p.radius - p.radius;
                    assert!(
                        !sees_all(x, &tris, &targets[..100]),
                        "{}: {x} sees the whole surface, yet no kernel was found",
                        row.name
                    );
                }
            }
        }
    }
}
