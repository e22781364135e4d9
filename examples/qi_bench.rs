//! Times the exact silhouettes with one ray per piece against quantitative invisibility (one
//! ray per connected set of pieces, the count carried along: `geometry::silhouettes::quantitative_invisibility`)
//! on the Stanford bunny and the real-world suite's displaced blob: microseconds per point and
//! rays per point, for the whole silhouette (`exact_silhouette`) and inside a light's window
//! (`exact_silhouette_in_window`, quad lights of two sizes).
//!
//!     cargo run --release --example qi_bench
use glam::DVec3;
use penumbra::bench::realworld_scenes::displaced_icosphere;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::SphericalPolygon;
use penumbra::geometry::{ExactSilhouetteScratch, exact_silhouette};
use penumbra::geometry::{WindowScratch, exact_silhouette_in_window};
use penumbra::math::Frame;
use std::time::Instant;

/// Deterministic uniform numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn unit(&mut self) -> DVec3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = std::f64::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Seconds per call of `f` over `n` items (best of three passes); `f` returns the rays cast.
fn per_point(n: usize, mut f: impl FnMut(usize) -> u32) -> (f64, f64) {
    let (mut best, mut rays) = (f64::INFINITY, 0u64);
    for _ in 0..3 {
        rays = 0;
        let t = Instant::now();
        for i in 0..n {
            rays += f(i) as u64;
        }
        best = best.min(t.elapsed().as_secs_f64() / n as f64);
    }
    (best * 1e6, rays as f64 / n as f64)
}

fn report(what: &str, per: (f64, f64), qi: (f64, f64)) {
    println!(
        "{what:<34} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>8.2}x",
        per.0,
        qi.0,
        per.1,
        qi.1,
        per.0 / qi.0
    );
}

fn main() {
    let bunny = {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
        let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
        let m = &scene.objects[0].mesh;
        IndexedPolyhedron::new(&m.positions, &m.faces)
    };
    // The real-world suite's blob (src/bench/realworld_scenes.rs), and a finer one.
    let blob = {
        let m = displaced_icosphere(DVec3::ZERO, 0.8, 3, 0.12);
        IndexedPolyhedron::new(&m.positions, &m.faces)
    };
    let fine = {
        let m = displaced_icosphere(DVec3::ZERO, 0.8, 5, 0.12);
        IndexedPolyhedron::new(&m.positions, &m.faces)
    };
    println!(
        "{:<34} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "mesh / path", "µs/pt ray", "µs/pt QI", "rays ray", "rays QI", "speedup"
    );
    let frame = Frame::from_z(DVec3::new(0.1, 1.0, 0.2).normalize());
    let mut out = SphericalPolygon::new();
    for (name, poly) in [
        ("bunny", &bunny),
        ("blob (1,280 faces)", &blob),
        ("blob (20,480 faces)", &fine),
    ] {
        let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
        let pts: Vec<DVec3> = (0..400)
            .map(|_| poly.center + rng.unit() * poly.radius * (1.05 + 3.0 * rng.next()))
            .collect();
        let mut per = ExactSilhouetteScratch::default();
        per.per_piece_rays = true;
        let mut qi = ExactSilhouetteScratch::default();
        let mut run = |s: &mut ExactSilhouetteScratch| {
            per_point(pts.len(), |i| {
                exact_silhouette(poly, pts[i], &frame, &mut out, s).map_or(0, |st| st.rays)
            })
        };
        let (a, b) = (run(&mut per), run(&mut qi));
        report(&format!("{name}, whole"), a, b);

        // Windowed: a quad light above the mesh, points on a floor below and beside it.
        for rel in [0.05, 0.5] {
            let size = rel * poly.radius;
            let centre = poly.center + DVec3::Y * 1.6 * poly.radius;
            let (u, v) = (DVec3::X * size, DVec3::Z * size * 0.7);
            let mut cases = Vec::new();
            while cases.len() < 400 {
                let x = poly.center
                    + DVec3::new(
                        (rng.next() * 2.0 - 1.0) * 2.0 * poly.radius,
                        -1.05 * poly.radius,
                        (rng.next() * 2.0 - 1.0) * 2.0 * poly.radius,
                    );
                let frame = Frame::from_z((centre - x).normalize());
                let mut w: Vec<DVec3> = [-u - v, u - v, u + v, v - u]
                    .iter()
                    .map(|&c| frame.to_local((centre + c - x).normalize()))
                    .collect();
                if w[0].cross(w[1]).dot(w[2]) < 0.0 {
                    w.reverse();
                }
                cases.push((x, frame, w));
            }
            let mut per = WindowScratch::default();
            per.per_piece_rays = true;
            let mut qi = WindowScratch::default();
            let mut run = |s: &mut WindowScratch| {
                per_point(cases.len(), |i| {
                    let (x, f, w) = &cases[i];
                    exact_silhouette_in_window(poly, *x, f, w, false, &mut out, s)
                        .map_or(0, |st| st.rays)
                })
            };
            let (a, b) = (run(&mut per), run(&mut qi));
            report(&format!("{name}, window {rel} r"), a, b);
        }
    }
}
