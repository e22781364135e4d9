//! The boundary kernel on a GPU (`gpu::BoundaryKernel`, feature `gpu`) against the CPU's
//! boundary formulation (`geometry::visible_integral_from_boundary`, itself checked against
//! Greiner–Hormann: tests/boundary_agreement.rs), in both precisions, on random configurations
//! of a light and up to four occluders. Runs on any Vulkan adapter: lavapipe (Mesa's CPU
//! Vulkan) on a machine without a GPU, which `.ci/run` installs. Without an adapter the tests
//! fail with the reason, unless `PENUMBRA_GPU_TESTS=skip`.
#![cfg(feature = "gpu")]

use glam::DVec3;
use penumbra::geometry::{
    BoundaryScratch, HorizonScratch, SphericalPolygon, boundary_pieces,
    clamped_integral_of_boundary, clip_to_horizon,
};
use penumbra::gpu::{BoundaryKernel, Configuration, MAX_EDGES, Precision};
use penumbra::ltc::{LtcEntry, LtcTable, edge_integral, form_factor};
use penumbra::math::Pcg32;
use std::f64::consts::TAU;

/// A convex spherical polygon of `n` vertices around `centre` at angular radius about
/// `radius`, counter-clockwise seen from outside, wholly above the horizon.
fn polygon(rng: &mut Pcg32, centre: DVec3, radius: f64, n: usize) -> SphericalPolygon {
    let c = centre.normalize();
    let t1 = c.any_orthonormal_vector();
    let t2 = c.cross(t1);
    let mut p = SphericalPolygon::new();
    let phase = rng.next_f64() * TAU;
    p.push_loop((0..n).map(|k| {
        let phi = phase + TAU * (k as f64 + 0.4 * rng.next_f64()) / n as f64;
        (c + radius.tan() * (phi.cos() * t1 + phi.sin() * t2)).normalize()
    }));
    p
}

fn direction(rng: &mut Pcg32, min_z: f64) -> DVec3 {
    loop {
        let v = DVec3::new(
            2.0 * rng.next_f64() - 1.0,
            2.0 * rng.next_f64() - 1.0,
            rng.next_f64(),
        );
        if v.length() > 0.1 && v.length() < 1.0 && v.normalize().z > min_z {
            return v.normalize();
        }
    }
}

/// A light, its occluders, and a lobe of the embedded table (every other configuration).
struct Case {
    light: SphericalPolygon,
    occluders: Vec<SphericalPolygon>,
    lobe: Option<LtcEntry>,
}

fn configurations(count: usize) -> Vec<Case> {
    let mut rng = Pcg32::new(41, 7);
    let table = LtcTable::embedded();
    (0..count)
        .map(|i| {
            let c = direction(&mut rng, 0.6);
            let n = 3 + rng.below(6) as usize;
            let r = 0.1 + 0.3 * rng.next_f64();
            let light = polygon(&mut rng, c, r, n);
            let k = rng.below(5) as usize;
            let occluders = (0..k)
                .map(|_| {
                    let o = (c + 0.3 * (direction(&mut rng, 0.0) - c)).normalize();
                    let m = 3 + rng.below(6) as usize;
                    let r = 0.05 + 0.25 * rng.next_f64();
                    polygon(&mut rng, o, r, m)
                })
                .collect();
            let lobe = (i % 2 == 0).then(|| {
                let (v, a) = (0.02 + 0.98 * rng.next_f64(), 0.05 + 0.95 * rng.next_f64());
                table.lookup(v, a)
            });
            Case {
                light,
                occluders,
                lobe,
            }
        })
        .collect()
}

fn kernel(precision: Precision) -> Option<BoundaryKernel> {
    match BoundaryKernel::new(precision) {
        Ok(k) => Some(k),
        Err(e) if std::env::var("PENUMBRA_GPU_TESTS").as_deref() == Ok("skip") => {
            eprintln!("skipped: {e}");
            None
        }
        Err(e) => panic!("{e} (install mesa-vulkan-drivers for lavapipe)"),
    }
}

/// How the GPU's values compare with the CPU's over the configurations.
struct Comparison {
    /// The largest difference of the form factor, relative to the light's.
    worst: f64,
    /// The root mean square of those.
    rms: f64,
    /// The largest difference of the lobe's clamped integral, relative to the light's value
    /// through either lobe.
    worst_lobe: f64,
    lobes: usize,
    fallbacks: usize,
}

/// The lobe's clamped integral of the whole light above the lobe's horizon: its scale.
fn light_lobe(light: &SphericalPolygon, entry: &LtcEntry) -> f64 {
    let mut mapped = light.clone();
    mapped.map_vertices(|v| entry.transform(v));
    let mut clipped = SphericalPolygon::new();
    clip_to_horizon(&mapped, &mut clipped, &mut HorizonScratch::default());
    form_factor(clipped.loops()).abs()
}

fn compare(kernel: &BoundaryKernel, cases: &[Case]) -> Comparison {
    let views: Vec<Configuration> = cases
        .iter()
        .map(|c| Configuration {
            light: &c.light,
            occluders: &c.occluders,
            lobe: c.lobe.map(|e| e.m_inv),
            clip_here: false,
        })
        .collect();
    let gpu = kernel.integrals(&views).unwrap();
    let mut scratch = BoundaryScratch::new();
    let (mut arcs, mut crossings) = (Vec::new(), Vec::new());
    let mut c = Comparison {
        worst: 0.0,
        rms: 0.0,
        worst_lobe: 0.0,
        lobes: 0,
        fallbacks: gpu.fallbacks,
    };
    for (i, case) in cases.iter().enumerate() {
        arcs.clear();
        boundary_pieces(&case.light, &case.occluders, &mut scratch, |p| {
            arcs.push((p.start, p.end))
        });
        let cpu = arcs.iter().map(|&(a, b)| edge_integral(a, b)).sum::<f64>() / TAU;
        let off = (gpu.diffuse[i] - cpu).abs() / form_factor(case.light.loops()).abs();
        c.worst = c.worst.max(off);
        c.rms += off * off;
        if let Some(entry) = &case.lobe {
            let mapped = arcs
                .iter()
                .map(|&(a, b)| (entry.transform(a), entry.transform(b)));
            let cpu =
                clamped_integral_of_boundary(mapped, &mut crossings, edge_integral).unwrap() / TAU;
            // The light's own value through either lobe: where it lies almost wholly below the
            // lobe's horizon, its lobe value is 1e-8 and what a pixel shows of it is its
            // diffuse part.
            let scale = light_lobe(&case.light, entry)
                .max(form_factor(case.light.loops()).abs())
                .max(1e-300);
            let off = (gpu.lobe[i].unwrap() - cpu).abs() / scale;
            c.worst_lobe = c.worst_lobe.max(off);
            c.lobes += 1;
        }
    }
    c.rms = (c.rms / cases.len() as f64).sqrt();
    c
}

impl Comparison {
    fn summary(&self) -> String {
        format!(
            "worst {:.1e} of the light's (rms {:.1e}), {} lobes worst {:.1e}, {} fallbacks",
            self.worst, self.rms, self.lobes, self.worst_lobe, self.fallbacks
        )
    }
}

/// Oracle: the CPU's boundary formulation, 4,096 configurations (half with a lobe of the
/// embedded table), in f32, relative to the light's value: the form factor's root mean square
/// within 1e-4 and every one within 1e-3 (the bound on an f32 image's relative RMSE),
/// every lobe within 1e-3; fallbacks (crossings that do not alternate in f32) under 1 %. Cut
/// positions at grazing crossings carry the error, not the sums.
#[test]
fn f32_kernel_matches_the_cpu() {
    let Some(k) = kernel(Precision::F32) else {
        return;
    };
    let c = compare(&k, &configurations(4096));
    println!("{}: f32 {}", k.adapter(), c.summary());
    assert!(c.fallbacks * 100 <= 4096, "{}", c.fallbacks);
    assert!(c.rms <= 1e-4 && c.worst <= 1e-3, "{} {}", c.rms, c.worst);
    assert!(c.worst_lobe <= 1e-3, "{}", c.worst_lobe);
}

/// Oracle: the CPU's boundary formulation in f64, where the adapter has SHADER_F64 (lavapipe
/// has): every configuration within 1e-10 of the light's value, form factor and lobe.
#[test]
fn f64_kernel_matches_the_cpu() {
    let Some(k) = kernel(Precision::F64) else {
        return;
    };
    if k.precision() != Precision::F64 {
        println!("{}: no SHADER_F64", k.adapter());
        return;
    }
    let c = compare(&k, &configurations(4096));
    println!("{}: f64 {}", k.adapter(), c.summary());
    assert_eq!(c.fallbacks, 0);
    assert!(
        c.worst < 1e-10 && c.worst_lobe < 1e-10,
        "{} {}",
        c.worst,
        c.worst_lobe
    );
}

/// Oracle: the CPU's path, every polygon clipped to the horizon (`clip_to_horizon`) and then
/// the boundary formulation, against the kernel given the unclipped polygons (`clip_here`):
/// 2,048 lights and occluders crossing the horizon, in f64 where the adapter has it.
#[test]
fn the_horizon_clip_from_the_boundary_matches_clipping_first() {
    let Some(k) = kernel(Precision::F64) else {
        return;
    };
    let mut rng = Pcg32::new(5, 9);
    let mut cases = Vec::new();
    while cases.len() < 2048 {
        // Centres from 0.3 below the horizon to the zenith; polygons within a hemisphere.
        let c = {
            let v = direction(&mut rng, 0.0);
            let z = -0.3 + 1.3 * rng.next_f64();
            let t = DVec3::new(v.x, v.y, 0.0).normalize_or(DVec3::X);
            (t * (1.0 - z * z).max(0.0).sqrt() + DVec3::Z * z).normalize()
        };
        let n = 3 + rng.below(6) as usize;
        let r = 0.1 + 0.4 * rng.next_f64();
        let light = polygon(&mut rng, c, r, n);
        let occluders: Vec<SphericalPolygon> = (0..rng.below(4))
            .map(|_| {
                let o = (c + 0.4 * (direction(&mut rng, -1.0) - c)).normalize();
                let m = 3 + rng.below(6) as usize;
                let r = 0.05 + 0.3 * rng.next_f64();
                polygon(&mut rng, o, r, m)
            })
            .collect();
        cases.push((light, occluders));
    }
    let views: Vec<Configuration> = cases
        .iter()
        .map(|(l, o)| Configuration {
            light: l,
            occluders: o,
            lobe: None,
            clip_here: true,
        })
        .collect();
    let gpu = k.integrals(&views).unwrap();
    let clip = |p: &SphericalPolygon| {
        let mut c = SphericalPolygon::new();
        clip_to_horizon(p, &mut c, &mut HorizonScratch::default());
        c
    };
    let mut scratch = BoundaryScratch::new();
    let (mut worst, mut crossing) = (0.0f64, 0);
    for (i, (l, o)) in cases.iter().enumerate() {
        let light = clip(l);
        let occluders: Vec<SphericalPolygon> = o.iter().map(clip).collect();
        let cpu = if light.is_empty() {
            0.0
        } else {
            let mut sum = 0.0;
            boundary_pieces(&light, &occluders, &mut scratch, |p| {
                sum += edge_integral(p.start, p.end)
            });
            sum / TAU
        };
        crossing += l.vertices().iter().any(|v| v.z < 0.0) as usize;
        // The light's form factor above the horizon, or its whole one where none is above.
        let scale = form_factor(light.loops())
            .abs()
            .max(1e-3 * form_factor(l.loops()).abs());
        worst = worst.max((gpu.diffuse[i] - cpu).abs() / scale);
    }
    println!(
        "{}: {:?}, {crossing} lights crossing the horizon, worst {worst:.1e} of the light's, {} \
         fallbacks",
        k.adapter(),
        k.precision(),
        gpu.fallbacks
    );
    assert!(crossing > 500, "{crossing}");
    let bound = if k.precision() == Precision::F64 {
        1e-10
    } else {
        1e-3
    };
    assert!(worst <= bound, "{worst}");
    assert!(gpu.fallbacks * 100 <= cases.len(), "{}", gpu.fallbacks);
}

/// A configuration beyond the shader's arrays is finished on the CPU and counted.
#[test]
fn configurations_beyond_the_arrays_fall_back_and_are_counted() {
    let Some(k) = kernel(Precision::F32) else {
        return;
    };
    let mut rng = Pcg32::new(3, 3);
    let light = polygon(&mut rng, DVec3::Z, 0.4, MAX_EDGES + 1);
    let mut configs = configurations(3);
    configs.push(Case {
        light,
        occluders: Vec::new(),
        lobe: None,
    });
    let c = compare(&k, &configs);
    assert_eq!(c.fallbacks, 1);
    assert!(c.worst <= 1e-3, "{}", c.worst);
}
