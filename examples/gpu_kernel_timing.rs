//! The boundary kernel's throughput (docs/gpu.md): configurations per second on the GPU
//! adapter wgpu finds (lavapipe on a machine without a GPU: a CPU, and labelled so), in f32
//! and f64, against the CPU's boundary formulation and Greiner–Hormann on the same
//! configurations, one thread each.
//!
//! `cargo run --release --features gpu --example gpu_kernel_timing [COUNT]`

use glam::DVec3;
use penumbra::geometry::{BoundaryScratch, SphericalPolygon, visible_integral_from_boundary};
use penumbra::gpu::{BoundaryKernel, Configuration, Precision};
use penumbra::ltc::edge_integral;
use penumbra::math::Pcg32;
use penumbra::stress::boundary_agreement::greiner_hormann_about_the_light;
use std::f64::consts::TAU;
use std::time::Instant;

fn polygon(rng: &mut Pcg32, centre: DVec3, radius: f64, n: usize) -> SphericalPolygon {
    let c = centre.normalize();
    let t1 = c.any_orthonormal_vector();
    let t2 = c.cross(t1);
    let phase = rng.next_f64() * TAU;
    let mut p = SphericalPolygon::new();
    p.push_loop((0..n).map(|k| {
        let phi = phase + TAU * (k as f64 + 0.4 * rng.next_f64()) / n as f64;
        (c + radius.tan() * (phi.cos() * t1 + phi.sin() * t2)).normalize()
    }));
    p
}

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(65_536);
    let mut rng = Pcg32::new(17, 3);
    let cases: Vec<(SphericalPolygon, Vec<SphericalPolygon>)> = (0..count)
        .map(|_| {
            let c = DVec3::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5, 1.0).normalize();
            let light = polygon(&mut rng, c, 0.2, 4);
            let occluders = (0..2)
                .map(|_| {
                    let o = (c + 0.3 * DVec3::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5, 0.0))
                        .normalize();
                    polygon(&mut rng, o, 0.12, 6)
                })
                .collect();
            (light, occluders)
        })
        .collect();
    let views: Vec<Configuration> = cases
        .iter()
        .map(|(l, o)| Configuration {
            light: l,
            occluders: o,
            lobe: None,
            clip_here: false,
        })
        .collect();
    println!("{count} configurations: a quad light and two hexagonal occluders each");
    for precision in [Precision::F32, Precision::F64] {
        let kernel = match BoundaryKernel::new(precision) {
            Ok(k) => k,
            Err(e) => {
                println!("no GPU adapter: {e}");
                return;
            }
        };
        // The first dispatch compiles the pipeline's machine code: not timed.
        kernel.integrals(&views[..views.len().min(64)]).unwrap();
        let t = Instant::now();
        let out = kernel.integrals(&views).unwrap();
        let s = t.elapsed().as_secs_f64();
        println!(
            "gpu {:?} on {}: {:.3} s, {:.2} µs per configuration, {} fallbacks",
            kernel.precision(),
            kernel.adapter(),
            s,
            1e6 * s / count as f64,
            out.fallbacks
        );
    }
    let mut scratch = BoundaryScratch::new();
    let t = Instant::now();
    let mut sum = 0.0;
    for (l, o) in &cases {
        sum += visible_integral_from_boundary(l, o, &mut scratch, edge_integral);
    }
    let s = t.elapsed().as_secs_f64();
    println!(
        "cpu boundary, one thread: {s:.3} s, {:.2} µs per configuration (checksum {sum:.6})",
        1e6 * s / count as f64
    );
    let t = Instant::now();
    let mut sum = 0.0;
    for (l, o) in &cases {
        let refs: Vec<&SphericalPolygon> = o.iter().collect();
        sum += greiner_hormann_about_the_light(l, &refs).unwrap_or(0.0);
    }
    let s = t.elapsed().as_secs_f64();
    println!(
        "cpu Greiner–Hormann, one thread: {s:.3} s, {:.2} µs per configuration (checksum {:.6})",
        1e6 * s / count as f64,
        sum * TAU
    );
}
