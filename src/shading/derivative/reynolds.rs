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
