//! BVH build time and ray throughput on a ~100k-triangle subdivided sphere.
//!
//! `cargo run --release --example bvh_bench [n_lon n_lat]`

use std::time::Instant;

use glam::DVec3;
use penumbra::accel::{Bvh, Ray};
use penumbra::math::Pcg32;
use penumbra::scene::shapes::uv_ellipsoid;
use penumbra::scene::{Material, ObjectFlags, Scene, SceneObject};
use rayon::prelude::*;

fn time<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t0 = Instant::now();
    let r = f();
    (r, t0.elapsed().as_secs_f64())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let (n_lon, n_lat) = (
        args.first().copied().unwrap_or(224),
        args.get(1).copied().unwrap_or(224),
    );
    let scene = Scene {
        objects: vec![SceneObject {
            name: "sphere".into(),
            mesh: uv_ellipsoid(DVec3::ZERO, DVec3::ONE, n_lon, n_lat),
            material: Material::default(),
            flags: ObjectFlags {
                light: false,
                occluder: true,
                receiver: true,
                is_static: false,
            },
        }],
        ..Default::default()
    };

    let threads = rayon::current_num_threads();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let bvh = Bvh::build(&scene); // warm-up
    let build_par = median((0..5).map(|_| time(|| Bvh::build(&scene)).1).collect());
    let build_one = median(
        (0..5)
            .map(|_| one.install(|| time(|| Bvh::build(&scene)).1))
            .collect(),
    );
    println!(
        "{} triangles, {} nodes; build {:.1} ms on 1 thread, {:.1} ms on {threads}",
        bvh.triangle_count(),
        bvh.node_count(),
        build_one * 1e3,
        build_par * 1e3,
    );

    // Primary rays: a 1024x1024 pinhole camera at distance 3 (the sphere fills ~40%).
    let res = 1024u32;
    let eye = DVec3::new(0.3, -3.0, 0.5);
    let fwd = (-eye).normalize();
    let right = fwd.cross(DVec3::Z).normalize();
    let up = right.cross(fwd);
    let primary: Vec<Ray> = (0..res * res)
        .map(|i| {
            let (x, y) = (i % res, i / res);
            let sx = (x as f64 + 0.5) / res as f64 * 2.0 - 1.0;
            let sy = 1.0 - (y as f64 + 0.5) / res as f64 * 2.0;
            Ray::new(eye, fwd + 0.5 * (sx * right + sy * up))
        })
        .collect();
    // Incoherent rays: random origins in [-2, 2]^3, random directions.
    let mut rng = Pcg32::new(7, 7);
    let random: Vec<Ray> = (0..1 << 20)
        .map(|_| {
            let o = DVec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            );
            Ray::new(o, rng.unit_vector())
        })
        .collect();
    // Shadow rays: from the primary hit points to random points of a light above.
    let hits: Vec<_> = primary
        .iter()
        .filter_map(|r| bvh.intersect(r, 0.0, f64::INFINITY))
        .collect();
    let shadow: Vec<(Ray, u32)> = hits
        .iter()
        .map(|h| {
            let l = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 4.0);
            (Ray::new(h.point, l - h.point), h.face)
        })
        .collect();

    let report = |name: &str, n: usize, count: usize, f: &(dyn Fn() -> usize + Sync)| {
        // Best of three runs each (the machine is shared).
        let best = |run: &dyn Fn() -> (usize, f64)| {
            (0..3)
                .map(|_| run())
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap()
        };
        let (c1, t1) = best(&|| one.install(|| time(f)));
        let (cp, tp) = best(&|| time(f));
        assert_eq!(c1, cp);
        assert_eq!(c1, count);
        println!(
            "{name:>10}: {n} rays, {:5.1}% hit/occluded, {:6.2} Mrays/s on 1 thread, {:6.2} Mrays/s on {threads}",
            100.0 * c1 as f64 / n as f64,
            n as f64 / t1 / 1e6,
            n as f64 / tp / 1e6,
        );
    };
    let closest = |rays: &[Ray]| {
        rays.par_iter()
            .filter(|r| bvh.intersect(r, 0.0, f64::INFINITY).is_some())
            .count()
    };
    let n_primary = closest(&primary);
    report("primary", primary.len(), n_primary, &|| closest(&primary));
    let n_random = closest(&random);
    report("random", random.len(), n_random, &|| closest(&random));
    let occl = || {
        shadow
            .par_iter()
            .filter(|(r, face)| bvh.occluded(r, 1e-9, 1.0 - 1e-9, |_, f| f != *face))
            .count()
    };
    let n_shadow = occl();
    report("shadow", shadow.len(), n_shadow, &occl);
}
