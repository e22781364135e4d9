//! Measures the constants of the tree cost model (`shading::cost_model`): what one silhouette
//! query costs computed at the point and read from a tree, and what a tree costs to build per
//! cell (convex) or per leaf (non-convex), over meshes of growing face counts. Writes
//! `out/cost_model.csv` and prints the fitted constants.
//!
//!     cargo run --release --example cost_model
use glam::DVec3;
use penumbra::bench::realworld_scenes::{displaced_icosphere, twisted_ellipsoid};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, Sidedness, SilhouetteBsp, SilhouetteScratch,
    SphericalPolygon, silhouette,
};
use penumbra::geometry::{ExactSilhouetteScratch, exact_silhouette};
use penumbra::geometry::{WindowScratch, exact_silhouette_in_window};
use penumbra::math::Frame;
use penumbra::scene::Mesh;
use penumbra::scene::shapes::{cylinder, icosphere, uv_ellipsoid};
use std::fmt::Write;
use std::time::Instant;

/// Query points: deterministic, in the box [-4, 4]³ and outside the mesh's bounding sphere.
fn points(poly: &IndexedPolyhedron, n: usize) -> Vec<DVec3> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let p = DVec3::new(next(), next(), next()) * 8.0 - 4.0;
        if (p - poly.center).length() > 1.05 * poly.radius {
            out.push(p);
        }
    }
    out
}

/// Seconds per call of `f` over `pts` (best of three passes).
fn per_query(pts: &[DVec3], mut f: impl FnMut(DVec3)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t = Instant::now();
        for &p in pts {
            f(p);
        }
        best = best.min(t.elapsed().as_secs_f64() / pts.len() as f64);
    }
    best
}

fn main() {
    let (lo, hi) = (DVec3::splat(-4.0), DVec3::splat(4.0));
    let frame = Frame::from_z(DVec3::Y);
    let mut out = SphericalPolygon::new();
    let mut csv =
        String::from("mesh,kind,faces,at_point_us,tree_us,tree_size,build_s,build_us_per_unit\n");
    let convex: Vec<(String, Mesh)> = [4u32, 8, 12, 16, 24, 32, 48]
        .iter()
        .map(|&s| (format!("cylinder{s}"), cylinder(DVec3::ZERO, 1.0, 1.5, s)))
        .chain((0..3).map(|k| (format!("icosphere{k}"), icosphere(DVec3::ZERO, 1.0, k))))
        .collect();
    let (mut fa, mut fb) = (Vec::new(), Vec::new());
    for (name, m) in &convex {
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let pts = points(&poly, 20_000);
        let mut sc = SilhouetteScratch::default();
        let at = per_query(&pts, |x| {
            silhouette(&poly, x, &frame, Sidedness::TwoSided, &mut out, &mut sc)
        });
        let t = Instant::now();
        let built = SilhouetteBsp::build_convex_limited(&poly, lo, hi, 400_000);
        let build = t.elapsed().as_secs_f64();
        let (tree_us, size) = match &built {
            Some((tree, st)) => (
                per_query(&pts, |x| {
                    tree.silhouette_at(&poly, x, x, &frame, &mut out);
                }) * 1e6,
                st.leaves,
            ),
            None => (f64::NAN, 0),
        };
        let per_unit = if size > 0 {
            build / size as f64 * 1e6
        } else {
            f64::NAN
        };
        fa.push((poly.face_count() as f64, at * 1e6 - tree_us));
        if size > 0 {
            fb.push(per_unit);
        }
        writeln!(
            csv,
            "{name},convex,{},{:.4},{tree_us:.4},{size},{build:.4},{per_unit:.3}",
            poly.face_count(),
            at * 1e6
        )
        .unwrap();
    }
    let nonconvex: Vec<(String, Mesh)> = vec![
        (
            "twisted6x4".into(),
            twisted_ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.7, 0.8), 6, 4, 0.2),
        ),
        (
            "twisted8x5".into(),
            twisted_ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.7, 0.8), 8, 5, 0.2),
        ),
        (
            "twisted10x6".into(),
            twisted_ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.7, 0.8), 10, 6, 0.2),
        ),
        (
            "twisted18x8".into(),
            twisted_ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.7, 0.8), 18, 8, 0.2),
        ),
        (
            "blob1".into(),
            displaced_icosphere(DVec3::ZERO, 1.0, 1, 0.15),
        ),
        (
            "blob2".into(),
            displaced_icosphere(DVec3::ZERO, 1.0, 2, 0.15),
        ),
        (
            "ellipsoid32x16".into(),
            uv_ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.6, 0.8), 32, 16),
        ),
    ];
    let (mut ea, mut eb) = (Vec::new(), Vec::new());
    for (name, m) in &nonconvex {
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        if poly.diagnostics.convex || !poly.diagnostics.closed_manifold {
            println!("{name}: skipped (convex or open)");
            continue;
        }
        let pts = points(&poly, 4_000);
        let mut sc = ExactSilhouetteScratch::default();
        let at = per_query(&pts, |x| {
            let _ = exact_silhouette(&poly, x, &frame, &mut out, &mut sc);
        });
        let t = Instant::now();
        let limits = ExactBspLimits {
            max_leaves: 20_000,
            ..ExactBspLimits::default()
        };
        let built = ExactSilhouetteBsp::build(&poly, lo, hi, limits);
        let build = t.elapsed().as_secs_f64();
        let (tree_us, size) = match &built {
            Some((tree, st)) => (
                per_query(&pts, |x| {
                    tree.silhouette_at(&poly, x, x, &frame, &mut out);
                }) * 1e6,
                st.leaves,
            ),
            None => (f64::NAN, 0),
        };
        // As an occluder inside a light's window: a square of a third of the mesh's angular
        // radius around the direction to its centre.
        let mut ws = WindowScratch::default();
        let windowed = per_query(&pts, |x| {
            let d = poly.center - x;
            let f = Frame::from_z(d.normalize());
            let t = (poly.radius / d.length()).min(0.9) / 3.0;
            let w = [
                DVec3::new(-t, -t, 1.0).normalize(),
                DVec3::new(t, -t, 1.0).normalize(),
                DVec3::new(t, t, 1.0).normalize(),
                DVec3::new(-t, t, 1.0).normalize(),
            ];
            let _ = exact_silhouette_in_window(&poly, x, &f, &w, false, &mut out, &mut ws);
        }) * 1e6;
        println!("{name}: windowed {windowed:.3} us per query");
        let per_unit = if size > 0 {
            build / size as f64 * 1e6
        } else {
            build / 20_000.0 * 1e6
        };
        ea.push((poly.face_count() as f64, at * 1e6));
        eb.push((poly.face_count() as f64, per_unit));
        writeln!(
            csv,
            "{name},exact,{},{:.4},{tree_us:.4},{size},{build:.4},{per_unit:.3}",
            poly.face_count(),
            at * 1e6
        )
        .unwrap();
    }
    print!("{csv}");
    // Least-squares slopes through the origin: saving per query per face, build cost per unit.
    let slope = |v: &[(f64, f64)]| {
        v.iter().map(|(f, y)| f * y).sum::<f64>() / v.iter().map(|(f, _)| f * f).sum::<f64>()
    };
    println!("convex: saving per query = {:.4} us per face", slope(&fa));
    println!("convex: build = {:.3} us per cell (median)", median(fb));
    println!("exact: at-point query = {:.4} us per face", slope(&ea));
    println!(
        "exact: build = {:.4} us per leaf per face",
        slope(&eb.iter().map(|&(f, u)| (f, u / f * f)).collect::<Vec<_>>())
    );
    std::fs::create_dir_all("out").unwrap();
    std::fs::write("out/cost_model.csv", csv).unwrap();
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
