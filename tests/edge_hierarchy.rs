//! Contour edges through the normal-cone hierarchy over the edges (`geometry::mesh::edge_hierarchy`)
//! against the scan (`contour_edges`, an independent oracle): the same edges in the same order,
//! and the exact silhouette built from them the same bit for bit, on the bunny, a displaced
//! icosphere (closed and opened), a UV sphere and the polyhedra of 001 Table 7.1, at points far,
//! near, inside the bounding sphere and just off the faces' planes.

use glam::DVec3;
use penumbra::bench::realworld_scenes::displaced_icosphere;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ContourScratch, CoplanarFace, EdgeHierarchy, contour_edge_indices, coplanar_tolerance,
};
use penumbra::geometry::{
    ExactSilhouetteScratch, SphericalPolygon, contour_edges, exact_silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::shapes::uv_ellipsoid;
use penumbra::scene::thesis_polyhedra::TABLE_7_1;
use std::sync::Arc;

use crate::silhouette_common::polyhedron;

fn bunny() -> IndexedPolyhedron {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
    let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
    let m = &scene.objects[0].mesh;
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

/// `poly` with an edge hierarchy, whatever its size (small meshes are scanned otherwise).
fn with_hierarchy(mut poly: IndexedPolyhedron) -> IndexedPolyhedron {
    if poly.index.edge_hierarchy.is_none() {
        poly.index.edge_hierarchy = Some(Arc::new(EdgeHierarchy::build(&poly.mesh)));
    }
    poly.index.edge_hierarchy_per_point = true;
    poly
}

/// The meshes under test, with their hierarchies.
fn meshes() -> Vec<(String, IndexedPolyhedron)> {
    let blob = displaced_icosphere(DVec3::new(0.3, -0.2, 0.1), 0.8, 3, 0.12);
    let mut open = blob.clone();
    // Opened: every seventh face removed, so that boundary edges are contour edges whenever
    // their face is front-facing.
    open.faces = open
        .faces
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 7 != 3)
        .map(|(_, f)| f.clone())
        .collect();
    let sphere = uv_ellipsoid(
        DVec3::new(-1.0, 2.0, 0.5),
        DVec3::new(1.0, 0.7, 1.3),
        32,
        16,
    );
    let mut out = vec![
        ("bunny".to_string(), bunny()),
        (
            "displaced icosphere".to_string(),
            IndexedPolyhedron::new(&blob.positions, &blob.faces),
        ),
        (
            "opened icosphere".to_string(),
            IndexedPolyhedron::new(&open.positions, &open.faces),
        ),
        (
            "uv sphere".to_string(),
            IndexedPolyhedron::new(&sphere.positions, &sphere.faces),
        ),
    ];
    for row in TABLE_7_1 {
        out.push((row.name.to_string(), polyhedron(row.name)));
    }
    out.into_iter()
        .map(|(n, p)| (n, with_hierarchy(p)))
        .collect()
}

fn uniform_direction(rng: &mut Pcg32) -> DVec3 {
    let z = 2.0 * rng.next_f64() - 1.0;
    let phi = std::f64::consts::TAU * rng.next_f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A point off the plane of face `f` by `offset` times the mesh radius, near the face (a
/// random point of the face's neighbourhood in the plane).
fn off_face(poly: &IndexedPolyhedron, f: usize, offset: f64, rng: &mut Pcg32) -> DVec3 {
    let idx = poly.face(f);
    let q = idx
        .iter()
        .fold(DVec3::ZERO, |s, &v| s + poly.vertices[v as usize])
        / idx.len() as f64;
    let n = poly.face_planes[f].n;
    let t = uniform_direction(rng).reject_from(n);
    let p = q + t * (0.3 * poly.radius * rng.next_f64());
    // Onto the plane (to rounding), then off it.
    let p = p - n * poly.face_planes[f].eval(p);
    p + n * (offset * poly.radius)
}

/// Points far, near, inside the bounding sphere and just off the faces' planes.
fn points(poly: &IndexedPolyhedron, rng: &mut Pcg32, n: usize) -> Vec<DVec3> {
    let mut pts = Vec::with_capacity(n);
    let offsets = [1e-12, -1e-12, 1e-10, -1e-9, 2e-9, 1e-6, -1e-4, 1e-2];
    for k in 0..n {
        let p = match k % 4 {
            0 => poly.center + uniform_direction(rng) * poly.radius * (2.0 + 30.0 * rng.next_f64()),
            1 => poly.center + uniform_direction(rng) * poly.radius * (1.0 + rng.next_f64()),
            2 => poly.center + uniform_direction(rng) * poly.radius * rng.next_f64(),
            _ => {
                let f = (rng.next_u32() as usize) % poly.face_count();
                off_face(poly, f, offsets[(k / 4) % offsets.len()], rng)
            }
        };
        pts.push(p);
    }
    pts
}

/// The hierarchy's contour edges are the scan's, edge for edge and in order, and they are the
/// silhouette's contour edges (`contour_edges`, oriented) plus the boundary edges whose face is
/// turned away (an open mesh's image ends there too); with the coplanarity tolerance, both
/// report the same degenerate points.
#[test]
fn hierarchy_contour_edges_equal_the_scan() {
    let mut rng = Pcg32::new(4242, 9);
    let (mut hier, mut scan) = (ContourScratch::default(), ContourScratch::default());
    scan.scan = true;
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for (name, poly) in meshes() {
        let tol = coplanar_tolerance(&poly);
        let (mut skipped, mut degenerate, mut total) = (0u64, 0, 0u64);
        for x in points(&poly, &mut rng, 400) {
            contour_edge_indices(&poly, x, None, &mut hier, &mut a).unwrap();
            contour_edge_indices(&poly, x, None, &mut scan, &mut b).unwrap();
            assert_eq!(a, b, "{name} from {x}");
            let oriented: Vec<[u32; 2]> = a
                .iter()
                .map(|&e| {
                    let e = &poly.edges[e as usize];
                    if poly.face_planes[e.faces[0] as usize].eval(x) > 0.0 {
                        [e.v[1], e.v[0]]
                    } else {
                        [e.v[0], e.v[1]]
                    }
                })
                .collect();
            // `contour_edges` (the silhouette's predicate: one face turned toward x) and the
            // boundary edges whose face is turned away, which bound an open mesh's image too.
            let oracle: Vec<[u32; 2]> = contour_edges(&poly, x).collect();
            let back_boundary: Vec<[u32; 2]> = poly
                .edges
                .iter()
                .filter(|e| e.is_boundary() && poly.face_planes[e.faces[0] as usize].eval(x) <= 0.0)
                .map(|e| e.v)
                .collect();
            let mut want = oracle.clone();
            want.extend(back_boundary);
            let (mut got, mut want) = (oriented.clone(), want);
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want, "{name} from {x}");
            skipped += (poly.edges.len() as u32 - hier.stats.edges_tested) as u64;
            total += poly.edges.len() as u64;

            let ra = contour_edge_indices(&poly, x, Some(tol), &mut hier, &mut a);
            let rb = contour_edge_indices(&poly, x, Some(tol), &mut scan, &mut b);
            assert_eq!(ra, rb, "{name} from {x}");
            if ra == Err(CoplanarFace) {
                degenerate += 1;
            } else {
                assert_eq!(a, b, "{name} from {x}");
            }
        }
        assert!(
            degenerate > 0,
            "{name}: no point within the tolerance of a plane"
        );
        // The hierarchy must skip something on the large meshes (else it only costs).
        if poly.edges.len() > 1000 {
            assert!(
                skipped * 2 > total,
                "{name}: only {skipped} of {total} edge tests skipped"
            );
        }
    }
}

fn bits(p: &SphericalPolygon) -> Vec<Vec<[u64; 3]>> {
    p.loops()
        .map(|l| {
            l.iter()
                .map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
                .collect()
        })
        .collect()
}

/// The exact silhouette with the hierarchy's contour edges is the one with the scan's, bit for
/// bit (loops, statistics and degenerate points alike).
#[test]
fn exact_silhouette_through_the_hierarchy_is_the_scans_bit_for_bit() {
    let mut rng = Pcg32::new(77, 3);
    let frame = Frame::from_z(DVec3::new(0.2, 0.9, -0.3).normalize());
    let mut hier = ExactSilhouetteScratch::default();
    let mut scan = ExactSilhouetteScratch::default();
    scan.scan_edges = true;
    let (mut a, mut b) = (SphericalPolygon::default(), SphericalPolygon::default());
    for (name, poly) in meshes() {
        let n = if poly.edges.len() > 2000 { 120 } else { 240 };
        let mut ok = 0;
        for x in points(&poly, &mut rng, n) {
            let ra = exact_silhouette(&poly, x, &frame, &mut a, &mut hier);
            let rb = exact_silhouette(&poly, x, &frame, &mut b, &mut scan);
            assert_eq!(ra, rb, "{name} from {x}");
            assert_eq!(bits(&a), bits(&b), "{name} from {x}");
            ok += ra.is_ok() as u32;
        }
        assert!(ok > 0, "{name}: every point degenerate");
    }
}

/// The skip test is conservative at points within 1e-12 (relative) of a face plane, on either
/// side: every edge of that face is a candidate (its plane is within the coplanarity
/// tolerance, which the skip test's margin exceeds).
#[test]
fn the_skip_test_is_conservative_next_to_a_face_plane() {
    let mut rng = Pcg32::new(5, 5);
    let mut cand = Vec::new();
    for (name, poly) in meshes() {
        let h = poly.index.edge_hierarchy.as_deref().unwrap();
        let step = (poly.face_count() / 300).max(1);
        for f in (0..poly.face_count()).step_by(step) {
            for offset in [0.0, 1e-12, -1e-12, 3e-13, -7e-13] {
                let x = off_face(&poly, f, offset, &mut rng);
                assert!(poly.face_planes[f].eval(x).abs() <= 2e-12 * poly.radius);
                cand.clear();
                h.candidates(x, &mut cand);
                for (e, edge) in poly.edges.iter().enumerate() {
                    if edge.faces.contains(&(f as u32)) {
                        assert!(
                            cand.contains(&(e as u32)),
                            "{name}: edge {e} of face {f} skipped from {x} (offset {offset})"
                        );
                    }
                }
            }
        }
    }
}

/// The windowed query (`candidates_in_window`: the cone and the pyramid of a convex window) is
/// a subsequence of the cone's query, and holds every contour or boundary edge (the scan's,
/// an independent oracle) with a point seen inside the window, found by sampling each edge:
/// quads of random size and place seen from points far, near and just off the faces' planes.
#[test]
fn the_windows_pyramid_keeps_every_edge_seen_in_the_window() {
    let mut rng = Pcg32::new(77, 3);
    let mut scan = ContourScratch::default();
    scan.scan = true;
    let (mut cone, mut window, mut contour) = (Vec::new(), Vec::new(), Vec::new());
    let (mut pruned, mut total, mut seen) = (0usize, 0usize, 0usize);
    for (name, poly) in meshes() {
        let Some(h) = poly.index.edge_hierarchy.as_deref() else {
            continue;
        };
        for x in points(&poly, &mut rng, 120) {
            // A quad around a point near the mesh, seen from x.
            let target = poly.center + uniform_direction(&mut rng) * poly.radius * rng.next_f64();
            let f = Frame::from_z((target - x).normalize_or_zero());
            let (su, sv) = (
                poly.radius * (0.05 + rng.next_f64()),
                poly.radius * (0.05 + rng.next_f64()),
            );
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(a, b)| (target + f.x * (a * su) + f.y * (b * sv) - x).normalize());
            let axis = corners.iter().sum::<DVec3>().normalize();
            let cos = corners.iter().map(|w| w.dot(axis)).fold(1.0f64, f64::min);
            if cos < 0.5 {
                continue; // the windowed silhouette leaves such windows to the whole one
            }
            let sin = (1.0 - cos * cos).sqrt();
            let orient = corners[0].cross(corners[1]).dot(corners[2]).signum();
            let sides: Vec<DVec3> = (0..4)
                .map(|i| (corners[i].cross(corners[(i + 1) % 4]) * orient).normalize())
                .collect();
            cone.clear();
            window.clear();
            h.candidates_in_cone(x, axis, cos, sin, &mut cone);
            h.candidates_in_window(x, axis, cos, sin, &sides, &mut window);
            // A subsequence of the cone's list.
            let mut it = cone.iter();
            assert!(
                window.iter().all(|e| it.any(|c| c == e)),
                "{name} from {x}: not a subsequence of the cone's query"
            );
            pruned += cone.len() - window.len();
            total += cone.len();
            // Every contour or boundary edge with a sampled point inside the window.
            if contour_edge_indices(&poly, x, None, &mut scan, &mut contour).is_err() {
                continue;
            }
            for &e in &contour {
                let edge = &poly.edges[e as usize];
                let (a, b) = (
                    poly.vertices[edge.v[0] as usize],
                    poly.vertices[edge.v[1] as usize],
                );
                let inside = (0..=64).any(|k| {
                    let d = (a + (b - a) * (k as f64 / 64.0) - x).normalize_or_zero();
                    sides.iter().all(|n| n.dot(d) > 1e-9)
                });
                if inside {
                    seen += 1;
                    assert!(
                        window.contains(&e),
                        "{name} from {x}: edge {e} seen in the window is missing"
                    );
                }
            }
        }
    }
    assert!(seen > 1000, "only {seen} edges seen inside a window");
    // The pyramid must prune something beyond the cone (else it only costs).
    assert!(pruned * 10 > total, "pruned {pruned} of {total}");
}
