//! GGX against numerical quadrature: normalisation of `D` (projected microfacet area), of the
//! VNDF reflection pdf, and a χ² test of the VNDF sampler against that pdf. The quadrature
//! error bounds come from comparing two Gauss–Legendre orders on the same panels.

use crate::ltc_common;

use glam::DVec3;
use ltc_common::{Z999, chi2_critical, gauss_legendre, gl_1d};
use penumbra::ltc::ggx::{self, d_ggx, pdf_vndf_reflect, reflect, sample_vndf};
use penumbra::math::Pcg32;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Polar-angle panels adapted to the lobe width: breakpoints `atan(α 2^k)`, on which
/// `D(θ)` (a function of `tanθ/α`) is smooth and resolved for every α.
fn theta_panels(alpha: f64) -> Vec<f64> {
    let mut b = vec![0.0];
    for k in -30..=30 {
        let t = (alpha * 2f64.powi(k)).atan();
        if t > 1e-12 && t < FRAC_PI_2 - 1e-9 {
            b.push(t);
        }
    }
    b.push(FRAC_PI_2);
    b
}

fn view(theta: f64) -> DVec3 {
    DVec3::new(theta.sin(), 0.0, theta.cos())
}

const ALPHAS: [f64; 7] = [1e-4, 1e-3, 0.01, 0.1, 0.3, 0.6, 1.0];

#[test]
fn ltc_ndf_projected_area_is_one() {
    // ∫ D(h) cosθh dωh = 2π ∫ D(cosθ) cosθ sinθ dθ. `d_ggx` takes cosθ, which near θ = 0
    // does not carry sin²θ to full precision: the rounding of cos(θ) moves sin²θ by up to ε,
    // i.e. D by a relative 2ε/(sin²θ + α² cos²θ). That conditioning bound, integrated with the
    // same rule, is part of the tolerance along with the quadrature error estimate.
    let (g1, g2) = (gauss_legendre(16), gauss_legendre(24));
    for &alpha in &ALPHAS {
        let p = theta_panels(alpha);
        let integ = |gl: &[(f64, f64)], f: &dyn Fn(f64) -> f64| -> f64 {
            p.windows(2).map(|w| gl_1d(gl, w[0], w[1], f)).sum()
        };
        let f = |t: f64| TAU * d_ggx(t.cos(), alpha) * t.cos() * t.sin();
        let cond = |t: f64| {
            let (s, c) = t.sin_cos();
            f(t) * 2.0 * f64::EPSILON / (s * s + alpha * alpha * c * c)
        };
        let (lo, hi) = (integ(&g1, &f), integ(&g2, &f));
        let tol = (hi - lo).abs() + integ(&g2, &cond) + 1e-14;
        assert!((hi - 1.0).abs() <= tol, "alpha {alpha}: {hi} (±{tol:e})");
        println!(
            "alpha {alpha:>7}: ∫D cos = 1 {:+.1e} (tolerance {tol:.1e})",
            hi - 1.0
        );
    }
}

/// Breakpoints graded geometrically (ratio 2, 24 levels) towards both ends of `[a, b]`, so
/// that square-root behaviour and boundary layers at the ends are resolved.
fn graded(a: f64, b: f64) -> Vec<f64> {
    let w = b - a;
    let mut x: Vec<f64> = (0..24).map(|k| a + w * 0.5f64.powi(k + 1)).collect();
    x.extend((0..24).map(|k| b - w * 0.5f64.powi(k + 1)));
    x.push(a);
    x.push(b);
    x.sort_by(f64::total_cmp);
    x.dedup();
    x
}

/// φ ∈ [0, π] of the kinks at polar angle θ of the half vector: `v·h = 0` and the horizon of
/// `l = reflect(v, h)` (`2 (v·h) cosθ = cosθv`).
fn phi_cuts(v: DVec3, theta: f64) -> Vec<f64> {
    let (st, ct) = theta.sin_cos();
    let mut cuts = vec![];
    if v.x > 0.0 && st > 0.0 {
        for c in [
            -v.z * ct / (v.x * st),
            (0.5 * v.z / ct - v.z * ct) / (v.x * st),
        ] {
            if c.abs() < 1.0 {
                cuts.push(c.acos());
            }
        }
    }
    cuts
}

/// Polar angles where a φ-cut appears or disappears (|cos φ| = 1), or where the horizon of `l`
/// is a circle θ = const (normal incidence): the φ-integral is not smooth there.
fn theta_events(v: DVec3) -> Vec<f64> {
    if v.x == 0.0 {
        return vec![FRAC_PI_4];
    }
    let mut ev = vec![FRAC_PI_2 - v.x.atan2(v.z)];
    // Horizon cut: g(θ) = |(0.5 vz/cosθ − vz cosθ)/(vx sinθ)| − 1 changes sign; bisection on
    // a fine scan.
    let g = |t: f64| ((0.5 * v.z / t.cos() - v.z * t.cos()) / (v.x * t.sin())).abs() - 1.0;
    let n = 4000;
    for k in 1..n {
        let (a, b) = (
            FRAC_PI_2 * k as f64 / n as f64,
            FRAC_PI_2 * (k + 1) as f64 / n as f64,
        );
        if b < FRAC_PI_2 && g(a).signum() != g(b).signum() {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..100 {
                let m = 0.5 * (lo + hi);
                if g(m).signum() == g(lo).signum() {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            ev.push(0.5 * (lo + hi));
        }
    }
    ev
}

/// `∫ g(h) dωh` over the hemisphere of half vectors for integrands even in φ with kinks at
/// `v·h = 0` and at the horizon of `l = reflect(v, h)` (where `brdf_cos` rises steeply, over
/// `Δl.z ~ α`): θ on lobe-adapted panels plus panels graded towards the θ where a kink
/// appears, φ ∈ [0, π] split at the kinks with panels graded towards them.
fn hemisphere_integral(v: DVec3, alpha: f64, gl: &[(f64, f64)], g: impl Fn(DVec3) -> f64) -> f64 {
    let mut tb = theta_panels(alpha);
    for t in theta_events(v) {
        if t > 0.0 && t < FRAC_PI_2 {
            let (a, b) = (
                tb.iter().copied().filter(|&x| x < t).fold(0.0, f64::max),
                tb.iter()
                    .copied()
                    .filter(|&x| x > t)
                    .fold(FRAC_PI_2, f64::min),
            );
            tb.extend(graded(a, t));
            tb.extend(graded(t, b));
        }
    }
    tb.sort_by(f64::total_cmp);
    tb.dedup();
    let mut total = 0.0;
    for w in tb.windows(2) {
        total += gl_1d(gl, w[0], w[1], |t| {
            let (st, ct) = t.sin_cos();
            let mut cuts = vec![0.0, PI];
            cuts.extend(phi_cuts(v, t));
            cuts.sort_by(f64::total_cmp);
            let mut inner = 0.0;
            for c in cuts.windows(2) {
                let pts = graded(c[0], c[1]);
                for p in pts.windows(2) {
                    inner += gl_1d(gl, p[0], p[1], |phi| {
                        g(DVec3::new(st * phi.cos(), st * phi.sin(), ct))
                    });
                }
            }
            2.0 * inner * st
        });
    }
    total
}

#[test]
fn ltc_vndf_reflection_pdf_integrates_to_one() {
    // ∫ pdf(l) dωl = ∫ pdf(reflect(v, h)) 4 (v·h) dωh (|dωl/dωh| = 4 v·h).
    let (g1, g2) = (gauss_legendre(12), gauss_legendre(20));
    for &alpha in &ALPHAS {
        for &tv in &[0.0, 0.5, 1.0, 1.4, 1.55] {
            let v = view(tv);
            let g = |h: DVec3| {
                let vh = v.dot(h);
                if vh <= 0.0 {
                    0.0
                } else {
                    pdf_vndf_reflect(v, reflect(v, h), alpha) * 4.0 * vh
                }
            };
            let lo = hemisphere_integral(v, alpha, &g1, g);
            let hi = hemisphere_integral(v, alpha, &g2, g);
            let tol = (hi - lo).abs() + 1e-12;
            assert!(
                (hi - 1.0).abs() <= tol,
                "alpha {alpha} thetav {tv}: ∫pdf = {hi} (±{tol:e})"
            );
        }
    }
}

#[test]
fn ltc_albedo_at_most_one_and_moments_match_quadrature() {
    // norm = ∫ brdf_cos dωl ≤ 1 and fresnel = ∫ brdf_cos (1 − v·h)⁵ dωl by quadrature over h
    // (independent of the table's graded midpoint rule on the VNDF square), compared with
    // fit::lobe_moments at the table's resolution, claimed accurate to 1e-5 (docs/ltc.md).
    let (g1, g2) = (gauss_legendre(12), gauss_legendre(20));
    let mut worst = 0.0f64;
    for &alpha in &[1e-4, 0.01, 0.05, 0.3, 1.0] {
        for &tv in &[0.0, 0.7, 1.3, 1.55] {
            let v = view(tv);
            let g = |h: DVec3, fres: bool| {
                let vh = v.dot(h);
                if vh <= 0.0 {
                    0.0
                } else {
                    let w = if fres { ggx::schlick_weight(vh) } else { 1.0 };
                    ggx::brdf_cos(v, reflect(v, h), alpha) * 4.0 * vh * w
                }
            };
            let m = penumbra::ltc::fit::lobe_moments(v, alpha, penumbra::ltc::fit::MOMENT_SAMPLES);
            for (fres, got) in [(false, m.norm), (true, m.fresnel)] {
                let lo = hemisphere_integral(v, alpha, &g1, |h| g(h, fres));
                let hi = hemisphere_integral(v, alpha, &g2, |h| g(h, fres));
                let qerr = (hi - lo).abs();
                if !fres {
                    assert!(hi <= 1.0 + qerr, "albedo {hi} > 1");
                }
                worst = worst.max((got - hi).abs());
                assert!(
                    (got - hi).abs() < 1e-5 + qerr,
                    "alpha {alpha} thetav {tv} {}: lobe_moments {got} vs quadrature {hi} ± {qerr:e}",
                    if fres { "fresnel" } else { "norm" }
                );
            }
        }
    }
    println!("lobe_moments vs quadrature: max |error| {worst:.1e}");
}

#[test]
fn ltc_vndf_samples_match_pdf_histogram() {
    // Bins in h: s = t/(1 + t), t = tan²θh/α² (≈ equal mass), 16 bins × 24 in φ. Expected bin
    // probabilities from the public pdf by quadrature (θ panels graded geometrically inside
    // a bin, φ split at the kink v·h = 0); χ² at the 99.9 % level.
    let (ns, nphi) = (16usize, 24usize);
    let n_samples = 1_000_000usize;
    let gl = gauss_legendre(10);
    let mut rng = Pcg32::new(99, 7);
    for &(alpha, tv) in &[(0.05, 0.3), (0.4, 1.0), (1.0, 1.45), (0.002, 1.2)] {
        let v = view(tv);
        let theta_of = |s: f64| {
            if s >= 1.0 {
                FRAC_PI_2
            } else {
                (alpha * (s / (1.0 - s)).sqrt()).atan()
            }
        };
        let mut counts = vec![0u64; ns * nphi];
        for _ in 0..n_samples {
            let h = sample_vndf(v, alpha, rng.next_f64(), rng.next_f64());
            let t = (h.x * h.x + h.y * h.y) / (h.z * h.z * alpha * alpha);
            let s = t / (1.0 + t);
            let phi = h.y.atan2(h.x).rem_euclid(TAU);
            let i = ((s * ns as f64) as usize).min(ns - 1);
            let j = ((phi / TAU * nphi as f64) as usize).min(nphi - 1);
            counts[i * nphi + j] += 1;
        }
        // Density of h: pdf_l(reflect(v, h)) · 4 (v·h).
        let dens = |h: DVec3| {
            let vh = v.dot(h);
            if vh <= 0.0 {
                0.0
            } else {
                pdf_vndf_reflect(v, reflect(v, h), alpha) * 4.0 * vh
            }
        };
        let mut chi2 = 0.0;
        let mut df = 0usize;
        let mut total_p = 0.0;
        for i in 0..ns {
            let (t0, t1) = (
                theta_of(i as f64 / ns as f64),
                theta_of((i + 1) as f64 / ns as f64),
            );
            let mut tb = vec![t0, t1];
            if t0 > 0.0 {
                let mut t = 1.25 * t0;
                while t < t1 {
                    tb.push(t);
                    t *= 1.25;
                }
            } else {
                tb.extend((1..8).map(|k| t1 * k as f64 / 8.0));
            }
            tb.sort_by(f64::total_cmp);
            for j in 0..nphi {
                let (p0, p1) = (
                    TAU * j as f64 / nphi as f64,
                    TAU * (j + 1) as f64 / nphi as f64,
                );
                let mut p = 0.0;
                for w in tb.windows(2) {
                    p += gl_1d(&gl, w[0], w[1], |t| {
                        let mut pb = vec![p0, p1];
                        for c in phi_cuts(v, t) {
                            for c in [c, TAU - c] {
                                if c > p0 && c < p1 {
                                    pb.push(c);
                                }
                            }
                        }
                        pb.extend((1..4).map(|k| p0 + (p1 - p0) * k as f64 / 4.0));
                        pb.sort_by(f64::total_cmp);
                        let (st, ct) = t.sin_cos();
                        pb.windows(2)
                            .map(|q| {
                                gl_1d(&gl, q[0], q[1], |phi| {
                                    dens(DVec3::new(st * phi.cos(), st * phi.sin(), ct))
                                })
                            })
                            .sum::<f64>()
                            * st
                    });
                }
                total_p += p;
                let e = p * n_samples as f64;
                let o = counts[i * nphi + j] as f64;
                if e >= 5.0 {
                    chi2 += (o - e) * (o - e) / e;
                    df += 1;
                } else {
                    assert!(
                        o <= 5.0 + 10.0 * e.max(1.0),
                        "bin {i},{j}: {o} samples, expected {e}"
                    );
                }
            }
        }
        let crit = chi2_critical(df as f64 - 1.0, Z999);
        println!(
            "alpha {alpha} thetav {tv}: chi2 {chi2:.1} (df {}, 99.9% critical {crit:.1}), Σp = 1 {:+.1e}",
            df - 1,
            total_p - 1.0
        );
        assert!((total_p - 1.0).abs() < 1e-6, "Σp = {total_p}");
        assert!(chi2 < crit, "chi2 {chi2} > {crit}");
    }
}
