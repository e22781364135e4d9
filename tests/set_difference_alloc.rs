//! `SetDifference::subtract` must not allocate once its buffers have grown: a counting global
//! allocator (this test binary only) counts the allocations made by the test thread while
//! subtracting a warmed-up set of configurations again and again.

use glam::DVec3;
use penumbra::geometry::{PlanarPolygon, SetDifference};
use penumbra::math::{Frame, Pcg32};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::f64::consts::TAU;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn note_allocation() {
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Sutherland–Hodgman against the horizon (w ≥ 0), exact zeros on it.
fn horizon_clip(lp: &[DVec3]) -> Vec<DVec3> {
    let mut out = Vec::new();
    for i in 0..lp.len() {
        let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
        if a.z >= 0.0 {
            out.push(a);
        }
        if (a.z > 0.0 && b.z < 0.0) || (a.z < 0.0 && b.z > 0.0) {
            let x = if a.z > 0.0 {
                b * a.z - a * b.z
            } else {
                a * b.z - b * a.z
            };
            out.push(DVec3::new(x.x, x.y, 0.0).normalize());
        }
    }
    out
}

fn random_convex(rng: &mut Pcg32, center: DVec3, radius: f64) -> Vec<DVec3> {
    let f = Frame::from_z(center);
    let n = 3 + rng.below(6) as usize;
    let phase = rng.range(0.0, TAU);
    (0..n)
        .map(|k| {
            let t = phase + (k as f64 + 0.8 * rng.next_f64()) * TAU / n as f64;
            f.to_world(DVec3::new(radius * t.cos(), 0.7 * radius * t.sin(), 1.0))
                .normalize()
        })
        .collect()
}

fn planar(lp: &[DVec3]) -> PlanarPolygon {
    let mut p = PlanarPolygon::new();
    p.push_loop(lp.iter().copied());
    p
}

#[test]
fn subtract_does_not_allocate_in_steady_state() {
    let mut rng = Pcg32::new(17, 3);
    // Random pairs (many cut by the horizon), pairs sharing vertices and edges, and chains of
    // occluders whose running results have holes and several loops.
    let mut cases: Vec<(PlanarPolygon, Vec<PlanarPolygon>)> = Vec::new();
    while cases.len() < 300 {
        let z: f64 = rng.range(-0.3, 1.0);
        let phi = rng.range(0.0, TAU);
        let r = (1.0 - z * z).sqrt();
        let c1 = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let r1 = rng.range(0.1, 1.0);
        let light = horizon_clip(&random_convex(&mut rng, c1, r1));
        if light.len() < 3 {
            continue;
        }
        let mut occluders = Vec::new();
        for _ in 0..1 + rng.below(5) {
            let f = Frame::from_z(c1);
            let c2 = f
                .to_world(DVec3::new(rng.range(-0.8, 0.8), rng.range(-0.8, 0.8), 1.0))
                .normalize();
            let r2 = rng.range(0.05, 0.8);
            let mut occ = horizon_clip(&random_convex(&mut rng, c2, r2));
            if rng.below(3) == 0 && occ.len() >= 3 {
                // Share a light vertex and a point of a light edge.
                let i = rng.below(light.len() as u32) as usize;
                occ[0] = light[i];
                let (a, b) = (light[i], light[(i + 1) % light.len()]);
                occ[1] = (a + b).normalize();
            }
            if occ.len() >= 3 {
                occluders.push(planar(&occ));
            }
        }
        cases.push((planar(&light), occluders));
    }

    let mut sd = SetDifference::new();
    let (mut a, mut b) = (PlanarPolygon::new(), PlanarPolygon::new());
    let run = |sd: &mut SetDifference, a: &mut PlanarPolygon, b: &mut PlanarPolygon| {
        for (light, occluders) in &cases {
            a.copy_from(light);
            for occ in occluders {
                sd.subtract(a, occ, b, None);
                std::mem::swap(a, b);
            }
        }
    };
    // Warm-up: the buffers grow to the largest configuration.
    run(&mut sd, &mut a, &mut b);
    run(&mut sd, &mut a, &mut b);
    let capacity = sd.scratch_capacity();

    // The counter works: one allocation is seen.
    COUNTING.with(|c| c.set(true));
    drop(std::hint::black_box(Vec::<u8>::with_capacity(16)));
    COUNTING.with(|c| c.set(false));
    assert_eq!(ALLOCATIONS.swap(0, Ordering::Relaxed), 1);

    COUNTING.with(|c| c.set(true));
    for _ in 0..10 {
        run(&mut sd, &mut a, &mut b);
    }
    COUNTING.with(|c| c.set(false));

    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0);
    assert_eq!(sd.scratch_capacity(), capacity);
}
