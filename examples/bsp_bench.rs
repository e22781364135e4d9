//! Silhouette stage per shading point: chained from the contour on the fly vs read from the
//! BSP tree (001 Sect. 5.1), on the convex polyhedra of 001 Table 7.1, at random points in a
//! box of ±6 radii around each.
//!
//!     cargo run --release --example bsp_bench

use glam::DVec3;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    Sidedness, SilhouetteBsp, SilhouetteScratch, SphericalPolygon, silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};
use std::time::Instant;

fn main() {
    let frame = Frame::from_z(DVec3::new(0.1, -0.3, 0.95).normalize());
    println!(
        "| polyhedron | build (s) | nodes | leaves | vertices | size (bytes) | on the fly (ns/point) | BSP (ns/point) | ratio |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for row in TABLE_7_1.iter().filter(|r| r.convex) {
        let m = thesis_polyhedron(row.name).unwrap();
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let (lo, hi) = (
            poly.center - DVec3::splat(6.0 * poly.radius),
            poly.center + DVec3::splat(6.0 * poly.radius),
        );
        let (bsp, stats) = SilhouetteBsp::build_convex(&poly, lo, hi).unwrap();
        let mut rng = Pcg32::new(1, 1);
        let points: Vec<DVec3> = (0..200_000)
            .map(|_| lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .filter(|&x| poly.face_planes.iter().any(|p| p.eval(x) > 0.0))
            .collect();
        let mut out = SphericalPolygon::new();
        let mut scratch = SilhouetteScratch::default();
        let mut sink = 0usize;
        let mut best = [f64::INFINITY; 2];
        for _ in 0..3 {
            let t = Instant::now();
            for &x in &points {
                silhouette(
                    &poly,
                    x,
                    &frame,
                    Sidedness::FrontOnly,
                    &mut out,
                    &mut scratch,
                );
                sink += out.vertex_count();
            }
            best[0] = best[0].min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            for &x in &points {
                bsp.silhouette(&poly, x, &frame, &mut out);
                sink += out.vertex_count();
            }
            best[1] = best[1].min(t.elapsed().as_secs_f64());
        }
        let per = |s: f64| s / points.len() as f64 * 1e9;
        println!(
            "| {} | {:.4} | {} | {} | {} | {} | {:.0} | {:.0} | {:.1}× |",
            row.name,
            stats.seconds,
            stats.nodes,
            stats.leaves,
            stats.silhouette_vertices,
            stats.table_7_4_bytes,
            per(best[0]),
            per(best[1]),
            best[0] / best[1]
        );
        std::hint::black_box(sink);
    }
}
