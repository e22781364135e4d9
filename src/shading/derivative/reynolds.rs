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
    let w = a.cross(b);
    let s = w.length();
    if s <= 0.0 || s.is_nan() {
        return 0.0;
    }
    let n = w / s;
    let t = n.cross(a);
    let phi = s.atan2(a.dot(b));
    let (za, zb) = (a.z, b.z);
    let (lo, hi) = if za >= 0.0 && zb >= 0.0 {
        (0.0, phi)
    } else if za <= 0.0 && zb <= 0.0 {
        return 0.0;
    } else {
        // The crossing: z(φ) = a_z cos φ + t_z sin φ = 0 inside (0, Φ).
        let mut c = (-za).atan2(t.z);
        if c < 0.0 {
            c += std::f64::consts::PI;
        }
        let c = c.clamp(0.0, phi);
        if za > 0.0 { (0.0, c) } else { (c, phi) }
    };
    let (ua, ut) = (u.dot(a), u.dot(t));
    let (cc, cs, ss) = (za * ua, za * ut + t.z * ua, t.z * ut);
    // Antiderivatives of cos², sin cos and sin².
    let f = |x: f64| {
        let (s2, sx) = ((2.0 * x).sin(), x.sin());
        cc * (0.5 * x + 0.25 * s2) + cs * 0.5 * sx * sx + ss * (0.5 * x - 0.25 * s2)
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
