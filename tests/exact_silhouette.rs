//! The exact silhouette of non-convex polyhedra (001 Sect. 4.3) against two oracles: a Monte
//! Carlo estimate of the mesh's solid angle by ray casting (every point, every Table 7.1
//! polyhedron, including points inside the bowl's pit and the hole's tunnel), and, for the
//! convex ones, the silhouette loop chained from the contour (a second algorithm).

use glam::DVec3;
use penumbra::accel::Ray;
use penumbra::geometry::{
    ExactSilhouetteScratch, Sidedness, SilhouetteScratch, SphericalPolygon, exact_silhouette,
    silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::TABLE_7_1;
use std::f64::consts::PI;

use crate::silhouette_common;
use silhouette_common::{hit_count, polyhedron, solid_angle, triangles};

fn uniform_direction(rng: &mut Pcg32) -> DVec3 {
    let z = 2.0 * rng.next_f64() - 1.0;
    let phi = 2.0 * PI * rng.next_f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn exact_silhouettes_cover_the_solid_angle_of_every_table_7_1_polyhedron() {
    let mut rng = Pcg32::new(2024, 5);
    let frame = Frame::from_z(DVec3::new(0.3, 0.9, -0.2).normalize());
    let mut scratch = ExactSilhouetteScratch::default();
    let mut out = SphericalPolygon::new();
    let mut worst_z: f64 = 0.0;
    for row in TABLE_7_1 {
        let poly = polyhedron(row.name);
        let tris = triangles(&poly);
        let (mut points, mut degenerate, mut holes) = (0, 0, 0);
        while points < 24 {
            // Points around the mesh, and half of them close to it (in pits and tunnels).
            let spread = if points % 2 == 0 { 1.6 } else { 0.9 };
            let x = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 2.0 - 1.0;
            let x = x * spread * poly.radius;
            // Outside the mesh: an even number of crossings along a fixed ray.
            let probe = Ray::new(x, DVec3::new(0.5773, 0.5774, 0.5775));
            if hit_count(&tris, &probe) % 2 == 1 {
                continue;
            }
            match exact_silhouette(&poly, x, &frame, &mut out, &mut scratch) {
                Ok(_) => {}
                Err(_) => {
                    degenerate += 1;
                    assert!(degenerate < 3, "{}: too many degenerate points", row.name);
                    continue;
                }
            }
            points += 1;
            holes += out.loops().count().saturating_sub(1);
            let omega = solid_angle(&out);
            let n = 40_000;
            let k = (0..n)
                .filter(|_| hit_count(&tris, &Ray::new(x, uniform_direction(&mut rng))) > 0)
                .count();
            let p = k as f64 / n as f64;
            let mc = 4.0 * PI * p;
            let sigma = 4.0 * PI * (p * (1.0 - p) / n as f64).sqrt() + 1e-9;
            let z = (omega - mc) / sigma;
            worst_z = worst_z.max(z.abs());
            assert!(
                z.abs() < 4.5,
                "{} from {x}: exact silhouette {omega:.5} sr, ray casting {mc:.5} ± {sigma:.5} \
                 ({} loops)",
                row.name,
                out.loops().count()
            );
        }
        // Seen through its tunnel, the holed cube's silhouette has a hole (a second loop).
        if row.name == "hole" {
            assert!(
                holes > 0,
                "{}: no multi-loop silhouette was exercised",
                row.name
            );
        }
    }
    eprintln!("worst |z| = {worst_z:.2}");
}

#[test]
fn on_convex_meshes_the_exact_silhouette_is_the_chained_contour() {
    let mut rng = Pcg32::new(11, 3);
    let frame = Frame::from_z(DVec3::new(-0.2, 0.4, 0.9).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut es = ExactSilhouetteScratch::default();
    let mut cs = SilhouetteScratch::default();
    for row in TABLE_7_1.iter().filter(|r| r.convex) {
        let poly = polyhedron(row.name);
        let mut n = 0;
        while n < 200 {
            let x = (DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 2.0 - 1.0) * 3.0;
            if poly.face_planes.iter().all(|p| p.eval(x) < 0.0) {
                continue; // inside
            }
            let stats = exact_silhouette(&poly, x, &frame, &mut a, &mut es).unwrap();
            assert_eq!(stats.apparent_intersections, 0);
            assert_eq!(stats.kept, stats.contour_edges);
            silhouette(&poly, x, &frame, Sidedness::FrontOnly, &mut b, &mut cs);
            let (sa, sb) = (solid_angle(&a), solid_angle(&b));
            assert!((sa - sb).abs() < 1e-12, "{}: {sa} vs {sb}", row.name);
            n += 1;
        }
    }
}

/// The Stanford bunny (assets/meshes/bunny.obj, 3,674 triangles, closed): the silhouette with
/// the sweep for apparent intersections and the face hierarchy for the pieces' rays is the
/// all-pairs, all-faces one bit for bit (the same crossings met in the same order, the same
/// pieces kept), at points around it and near it; and its solid angle matches ray casting at a
/// few points.
#[test]
fn the_swept_silhouette_of_a_scanned_mesh_is_the_all_pairs_one() {
    let scene = penumbra::scene::obj::load_obj(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/meshes/bunny.obj"
    )))
    .unwrap();
    let m = &scene.objects[0].mesh;
    let poly = penumbra::geometry::IndexedPolyhedron::new(&m.positions, &m.faces);
    assert!(poly.diagnostics.closed_manifold && !poly.diagnostics.convex);
    let frame = Frame::from_z(DVec3::new(0.1, 1.0, 0.2).normalize());
    let mut rng = Pcg32::new(77, 1);
    let mut swept = ExactSilhouetteScratch::default();
    let mut all = ExactSilhouetteScratch::default();
    all.all_pairs = true;
    let (mut a, mut b) = (SphericalPolygon::default(), SphericalPolygon::default());
    let tris = triangles(&poly);
    let (mut compared, mut crossings) = (0, 0);
    for k in 0..90 {
        // From 1.05 to 4 radii from the centre (near the ears and far), and for a third of
        // the points just off a vertex, inside the bounding sphere.
        let x = if k % 3 == 2 {
            let v = poly.vertices[rng.below(poly.vertices.len() as u32) as usize];
            v + (v - poly.center).normalize() * 0.02 * poly.radius
        } else {
            let r = poly.radius * (1.05 + 3.0 * rng.next_f64());
            poly.center + uniform_direction(&mut rng) * r
        };
        let ra = exact_silhouette(&poly, x, &frame, &mut a, &mut swept);
        let rb = exact_silhouette(&poly, x, &frame, &mut b, &mut all);
        assert_eq!(ra.is_ok(), rb.is_ok(), "point {k}");
        assert_eq!(a, b, "point {k}: the swept silhouette differs");
        if let Ok(stats) = ra {
            compared += 1;
            crossings += stats.apparent_intersections;
        }
        if k < 4 && ra.is_ok() {
            let n = 20_000;
            let hits = (0..n)
                .filter(|_| {
                    let ray = Ray::new(x, uniform_direction(&mut rng));
                    hit_count(&tris, &ray) > 0
                })
                .count();
            let p = hits as f64 / n as f64;
            let mc = 4.0 * PI * p;
            let sigma = 4.0 * PI * (p * (1.0 - p) / n as f64).sqrt();
            let omega = solid_angle(&a);
            assert!(
                (omega - mc).abs() <= 4.5 * sigma + 1e-9,
                "point {k}: Ω {omega} against ray casting {mc} ± {sigma}"
            );
        }
    }
    assert!(compared >= 70, "{compared} points compared");
    assert!(
        crossings > 100,
        "the bunny's silhouettes cross themselves ({crossings})"
    );
}
