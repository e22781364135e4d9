//! Micro-benchmark of `SetDifference::subtract`: a quad light minus a hexagon occluder that
//! overlaps it partially (two proper crossings), plus a few other typical configurations.
//!
//! `cargo run --release --example set_difference_bench`

use glam::DVec3;
use penumbra::geometry::{PlanarPolygon, SetDifference};
use std::hint::black_box;
use std::time::Instant;

fn h(x: f64, y: f64) -> DVec3 {
    DVec3::new(x, y, 1.0).normalize()
}

fn polygon(points: &[DVec3]) -> PlanarPolygon {
    let mut p = PlanarPolygon::new();
    p.push_loop(points.iter().copied());
    p
}

fn hexagon(cx: f64, cy: f64, r: f64) -> PlanarPolygon {
    let pts: Vec<DVec3> = (0..6)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 6.0 + 0.1;
            h(cx + r * a.cos(), cy + r * a.sin())
        })
        .collect();
    polygon(&pts)
}

/// Nanoseconds per call, best of five runs of `n` calls.
fn time(name: &str, light: &PlanarPolygon, occluder: &PlanarPolygon, n: u32) -> f64 {
    let mut sd = SetDifference::new();
    let mut out = PlanarPolygon::new();
    sd.subtract(light, occluder, &mut out, None);
    let (loops, vertices) = (out.loop_count(), out.vertex_count());
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = Instant::now();
        for _ in 0..n {
            sd.subtract(black_box(light), black_box(occluder), &mut out, None);
            black_box(&out);
        }
        best = best.min(start.elapsed().as_secs_f64() * 1e9 / n as f64);
    }
    println!("{name:<44} {best:8.1} ns/call  ({loops} loop(s), {vertices} vertices)");
    best
}

fn main() {
    let n = 1_000_000;
    let quad = polygon(&[h(-0.5, -0.3), h(0.5, -0.3), h(0.5, 0.3), h(-0.5, 0.3)]);
    time(
        "quad − hexagon, partial overlap (2 crossings)",
        &quad,
        &hexagon(0.45, 0.2, 0.25),
        n,
    );
    time(
        "quad − hexagon inside (a hole)",
        &quad,
        &hexagon(0.0, 0.0, 0.2),
        n,
    );
    time("quad − hexagon disjoint", &quad, &hexagon(1.5, 0.0, 0.2), n);
    time(
        "quad − hexagon covering it",
        &quad,
        &hexagon(0.0, 0.0, 2.0),
        n,
    );
    // A light cut by the horizon, sharing a horizon stretch with the occluder.
    let hz = |az: f64| DVec3::new(az.to_radians().cos(), az.to_radians().sin(), 0.0);
    let sph = |az: f64, el: f64| {
        let (az, el) = (az.to_radians(), el.to_radians());
        DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin())
    };
    time(
        "horizon quad − horizon quad (shared stretch)",
        &polygon(&[hz(0.0), hz(60.0), sph(60.0, 30.0), sph(0.0, 30.0)]),
        &polygon(&[hz(30.0), hz(90.0), sph(90.0, 40.0), sph(30.0, 40.0)]),
        n,
    );
}
