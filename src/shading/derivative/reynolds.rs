//! The Reynolds transport theorem on the sphere, edge by edge, in closed form.
//!
//! The clamped cosine's integral over a region `P` whose boundary moves, `E = (1/π) ∫_P z⁺ dω`,
//! changes at `dE/dθ = (1/π) ∮_∂P z⁺ v_n dl`, with `v_n` the outward normal speed of the
//! boundary (the integrand itself does not depend on θ). An edge of `P` lies on the great
//! circle `ν · ω = 0`, `ν` its unit normal on the side of `P`; when `ν` turns at `ν̇`, the
//! circle's points move outward at `v_n = ω · ν̇` (from `ν(θ) · ω(θ) = 0`), whatever the edge's
//! endpoints do: they slide along the circle, which the theorem does not see. So each edge
//! contributes `(1/π) ∫ z⁺ (ν̇ · ω) dl` along its arc, a trigonometric polynomial of degree 2 in
//! the arc's angle ([`arc_rate`]), cut where the arc crosses the horizon `z = 0` (the kink of
//! `z⁺`).

use glam::DVec3;

/// `∫ z⁺ (u · ω) dl` along the shorter great arc from `a` to `b` (unit vectors): with
/// `ω(φ) = a cos φ + t sin φ`, `t` the unit tangent at `a` toward `b`, the integrand is
/// `(a_z cos φ + t_z sin φ)(u·a cos φ + u·t sin φ)`, integrated in closed form over the part
/// of `[0, Φ]` where `z ≥ 0` (one interval: an arc shorter than π crosses the horizon at most
/// once).
pub fn arc_rate(a: DVec3, b: DVec3, u: DVec3) -> f64 {
    if u == DVec3::ZERO {
        return 0.0;
    }
    let w = a.cross(b);
    let s = w.length();
    if s <= 0.0 || s.is_nan() {
        return 0.0;
    }
    let n = w / s;
    let t = n.cross(a);
    let (za, zb) = (a.z, b.z);
    // The ends of the part above the horizon, as points of the arc: their angles from `a`
    // (one atan2 each) and their sines and cosines (dot products, no trigonometry).
    let angle = |p: DVec3| {
        let (sin, cos) = (p.dot(t), p.dot(a));
        (sin.atan2(cos), sin, cos)
    };
    let start = (0.0, 0.0, 1.0);
    let (lo, hi) = if za >= 0.0 && zb >= 0.0 {
        (start, (s.atan2(a.dot(b)), s, a.dot(b)))
    } else if za <= 0.0 && zb <= 0.0 {
        return 0.0;
    } else {
        // The crossing of z(φ) = a_z cos φ + t_z sin φ = 0 inside the arc: the point of the
        // arc's circle on the horizon, on the arc's side.
        let mut c = n.cross(DVec3::Z).normalize_or_zero();
        if c.dot(a + b) < 0.0 {
            c = -c;
        }
        let crossing = angle(c);
        if za > 0.0 {
            (start, crossing)
        } else {
            (crossing, angle(b))
        }
    };
    let (ua, ut) = (u.dot(a), u.dot(t));
    let (cc, cs, ss) = (za * ua, za * ut + t.z * ua, t.z * ut);
    // Antiderivatives of cos², sin cos and sin² at (φ, sin φ, cos φ).
    let f = |(x, sin, cos): (f64, f64, f64)| {
        let sc = 0.5 * sin * cos;
        cc * (0.5 * x + sc) + cs * 0.5 * sin * sin + ss * (0.5 * x - sc)
    };
    f(hi) - f(lo)
}

/// Gauss–Legendre nodes and weights on [−1, 1], by Newton's method on the Legendre
/// polynomial (computed once).
fn gauss_legendre() -> &'static [(f64, f64); QUADRATURE_NODES] {
    static NODES: std::sync::OnceLock<[(f64, f64); QUADRATURE_NODES]> = std::sync::OnceLock::new();
    NODES.get_or_init(|| {
        let n = QUADRATURE_NODES;
        let mut out = [(0.0, 0.0); QUADRATURE_NODES];
        for (i, slot) in out.iter_mut().enumerate() {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            *slot = (x, 2.0 / ((1.0 - x * x) * dp * dp));
        }
        out
    })
}

/// Nodes of [`arc_rate_quadrature`]: its integrand along an arc shorter than π is a
/// trigonometric polynomial of degree 4 (the environment's 3-band SH, the cosine and the
/// normal speed, each linear or quadratic in ω), which 16 nodes integrate to rounding.
const QUADRATURE_NODES: usize = 16;

/// `∫ L(ω) z⁺ (u · ω) dl` along the shorter great arc from `a` to `b`, by Gauss–Legendre
/// quadrature over the part above the horizon (the kink of `z⁺` is a cut of the interval, so
/// each part is smooth): for integrands with no closed form, the environment's SH radiance.
pub fn arc_rate_quadrature(
    a: DVec3,
    b: DVec3,
    u: DVec3,
    radiance: &dyn Fn(DVec3) -> DVec3,
) -> DVec3 {
    if u == DVec3::ZERO {
        return DVec3::ZERO;
    }
    let w = a.cross(b);
    let s = w.length();
    if s <= 0.0 || s.is_nan() {
        return DVec3::ZERO;
    }
    let n = w / s;
    let t = n.cross(a);
    let phi = s.atan2(a.dot(b));
    let (lo, hi) = match (a.z >= 0.0, b.z >= 0.0) {
        (true, true) => (0.0, phi),
        (false, false) => return DVec3::ZERO,
        (above, _) => {
            let mut c = n.cross(DVec3::Z).normalize_or_zero();
            if c.dot(a + b) < 0.0 {
                c = -c;
            }
            let at = c.dot(t).atan2(c.dot(a)).clamp(0.0, phi);
            if above { (0.0, at) } else { (at, phi) }
        }
    };
    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let mut sum = DVec3::ZERO;
    for &(x, weight) in gauss_legendre() {
        let f = mid + half * x;
        let p = a * f.cos() + t * f.sin();
        sum += radiance(p) * (p.z.max(0.0) * u.dot(p) * weight);
    }
    sum * half
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: Gauss–Legendre quadrature of the same line integral, split at the horizon.
    fn quadrature(a: DVec3, b: DVec3, u: DVec3) -> f64 {
        let n = a.cross(b).normalize();
        let t = n.cross(a);
        let phi = a.cross(b).length().atan2(a.dot(b));
        let steps = 20_000;
        let h = phi / steps as f64;
        // Composite midpoint rule: the kink costs O(h²) at most.
        (0..steps)
            .map(|k| {
                let x = (k as f64 + 0.5) * h;
                let w = a * x.cos() + t * x.sin();
                w.z.max(0.0) * u.dot(w) * h
            })
            .sum()
    }

    /// Oracle: the closed form of `arc_rate`, with a constant radiance (the 16 nodes must
    /// integrate the degree-2 polynomial in cos, sin to rounding), and the composite midpoint
    /// rule with a radiance quadratic in ω (the SH's degree).
    #[test]
    fn the_quadrature_matches_the_closed_form_and_the_midpoint_rule() {
        let mut rng = crate::math::Pcg32::new(9, 1);
        for _ in 0..200 {
            let (a, b, u) = (rng.unit_vector(), rng.unit_vector(), rng.unit_vector());
            let one = |_: DVec3| DVec3::ONE;
            let q = arc_rate_quadrature(a, b, u, &one).x;
            let exact = arc_rate(a, b, u);
            assert!((q - exact).abs() < 1e-13, "{q} vs {exact}");
            let k = rng.unit_vector();
            let quad = move |w: DVec3| DVec3::splat(0.3 + w.dot(k) + (w.dot(k)).powi(2));
            let g = arc_rate_quadrature(a, b, u, &quad).x;
            let n = a.cross(b).normalize();
            let t = n.cross(a);
            let phi = a.cross(b).length().atan2(a.dot(b));
            let steps = 20_000;
            let h = phi / steps as f64;
            let m: f64 = (0..steps)
                .map(|j| {
                    let x = (j as f64 + 0.5) * h;
                    let w = a * x.cos() + t * x.sin();
                    quad(w).x * w.z.max(0.0) * u.dot(w) * h
                })
                .sum();
            assert!((g - m).abs() < 1e-7, "{g} vs {m}");
        }
    }

    #[test]
    fn arc_rate_matches_quadrature_across_the_horizon() {
        let mut rng = crate::math::Pcg32::new(7, 0);
        for _ in 0..200 {
            let (a, b, u) = (rng.unit_vector(), rng.unit_vector(), rng.unit_vector());
            let exact = arc_rate(a, b, u);
            let numeric = quadrature(a, b, u);
            assert!(
                (exact - numeric).abs() < 1e-7,
                "{a} {b} {u}: {exact} vs {numeric}"
            );
        }
    }
}
