//! Times the contour edges (001 Eq. 4.2) and the whole exact silhouette per point, by the scan
//! over all edges and through the normal-cone hierarchy over the edges
//! (`geometry::mesh::edge_hierarchy`), on the bunny, the displaced blob and displaced icospheres of
//! levels 1–5, at points at several distances; with the nodes visited and edges tested. Writes
//! `out/edge_hierarchy.csv`; the figures are in docs/silhouettes.md.
//!
//!     cargo run --release --example edge_hierarchy_bench
use glam::DVec3;
use penumbra::bench::realworld_scenes::displaced_icosphere;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::SphericalPolygon;
use penumbra::geometry::{BuildParams, ContourScratch, EdgeHierarchy, contour_edge_indices};
use penumbra::geometry::{ExactSilhouetteScratch, exact_silhouette};
use penumbra::math::Frame;
use std::fmt::Write;
use std::sync::Arc;
use std::time::Instant;

/// Deterministic points at `dist` mesh radii from the mesh's centre (uniform directions).
fn points(poly: &IndexedPolyhedron, dist: f64, n: usize) -> Vec<DVec3> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = std::f64::consts::TAU * next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            poly.center + DVec3::new(r * phi.cos(), r * phi.sin(), z) * dist * poly.radius
        })
        .collect()
}

/// Microseconds per call of `f` over `pts` (best of three passes).
fn per_query(pts: &[DVec3], mut f: impl FnMut(DVec3)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t = Instant::now();
        for &p in pts {
            f(p);
        }
        best = best.min(t.elapsed().as_secs_f64() / pts.len() as f64);
    }
    best * 1e6
}

fn main() {
    let frame = Frame::from_z(DVec3::Y);
    let mut out = SphericalPolygon::new();
    let bunny = {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
        let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
        scene.objects.into_iter().next().unwrap().mesh
    };
    let mut meshes = vec![("bunny".to_string(), bunny)];
    for level in 0..=5 {
        meshes.push((
            format!("blob{level}"),
            displaced_icosphere(DVec3::ZERO, 1.0, level, 0.12),
        ));
    }
    let mut csv = String::from(
        "mesh,faces,edges,dist,nodes,contour_scan_us,contour_tree_us,contour_speedup,\
         nodes_visited,edges_tested,contour_edges,exact_scan_us,exact_tree_us,exact_speedup\n",
    );
    println!(
        "{:>8} {:>6} {:>6} {:>5} | {:>9} {:>9} {:>6} | {:>7} {:>7} {:>7} | {:>9} {:>9} {:>6}",
        "mesh",
        "faces",
        "edges",
        "dist",
        "scan µs",
        "tree µs",
        "×",
        "nodes",
        "tested",
        "contour",
        "exact sc",
        "exact tr",
        "×"
    );
    let only = std::env::var("MESHES").unwrap_or_default();
    for (name, m) in &meshes {
        if !only.is_empty() && !only.split(',').any(|o| o == name) {
            continue;
        }
        let mut poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let params = BuildParams {
            leaf_edges: std::env::var("LEAF")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(8),
            normal_weight: std::env::var("NW")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(1.0),
        };
        poly.index.edge_hierarchy = Some(Arc::new(EdgeHierarchy::build_with(&poly, params)));
        poly.index.edge_hierarchy_per_point = true;
        let t = Instant::now();
        let h = EdgeHierarchy::build_with(&poly, params);
        let build_ms = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "{name}: {} nodes, built in {build_ms:.2} ms, pays: {}, kept by Polyhedron::new: {}",
            h.node_count(),
            h.pays(&poly),
            IndexedPolyhedron::new(&m.positions, &m.faces)
                .index
                .edge_hierarchy
                .is_some()
        );
        let dists: Vec<f64> = std::env::var("DISTS")
            .ok()
            .map(|v| v.split(',').filter_map(|d| d.parse().ok()).collect())
            .unwrap_or(vec![1.2, 2.0, 5.0, 20.0]);
        for &dist in &dists {
            let n = (400_000 / poly.edges.len()).clamp(40, 4000);
            let pts = points(&poly, dist, n);
            let (mut hs, mut ss) = (ContourScratch::default(), ContourScratch::default());
            ss.scan = true;
            let mut ids = Vec::new();
            let scan_us = per_query(&pts, |x| {
                contour_edge_indices(&poly, x, Some(1e-9 * poly.radius), &mut ss, &mut ids).ok();
            });
            let tree_us = per_query(&pts, |x| {
                contour_edge_indices(&poly, x, Some(1e-9 * poly.radius), &mut hs, &mut ids).ok();
            });
            let (mut nodes, mut tested, mut contour) = (0u64, 0u64, 0u64);
            for &x in &pts {
                contour_edge_indices(&poly, x, None, &mut hs, &mut ids).ok();
                nodes += hs.stats.nodes_visited as u64;
                tested += hs.stats.edges_tested as u64;
                contour += ids.len() as u64;
            }
            let k = pts.len() as f64;
            let (nodes, tested, contour) =
                (nodes as f64 / k, tested as f64 / k, contour as f64 / k);
            let epts = &pts[..pts
                .len()
                .min(if poly.edges.len() > 10_000 { 40 } else { 200 })];
            let mut se = ExactSilhouetteScratch::default();
            se.scan_edges = true;
            let mut he = ExactSilhouetteScratch::default();
            let exact_scan = per_query(epts, |x| {
                exact_silhouette(&poly, x, &frame, &mut out, &mut se).ok();
            });
            let exact_tree = per_query(epts, |x| {
                exact_silhouette(&poly, x, &frame, &mut out, &mut he).ok();
            });
            println!(
                "{name:>8} {:>6} {:>6} {dist:>5} | {scan_us:>9.2} {tree_us:>9.2} {:>6.2} | \
                 {nodes:>7.0} {tested:>7.0} {contour:>7.0} | {exact_scan:>9.1} {exact_tree:>9.1} \
                 {:>6.2}",
                poly.face_count(),
                poly.edges.len(),
                scan_us / tree_us,
                exact_scan / exact_tree
            );
            writeln!(
                csv,
                "{name},{},{},{dist},{},{scan_us:.3},{tree_us:.3},{:.3},{nodes:.1},{tested:.1},\
                 {contour:.1},{exact_scan:.2},{exact_tree:.2},{:.3}",
                poly.face_count(),
                poly.edges.len(),
                h.node_count(),
                scan_us / tree_us,
                exact_scan / exact_tree
            )
            .unwrap();
        }
    }
    std::fs::create_dir_all("out").unwrap();
    std::fs::write("out/edge_hierarchy.csv", csv).unwrap();
    println!("wrote out/edge_hierarchy.csv");
}
