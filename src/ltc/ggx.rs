//! Isotropic GGX (Trowbridge–Reitz) microfacet BRDF with height-correlated Smith
//! masking-shadowing, in the local shading frame (z = normal, `v` in the xz-plane).
//!
//! * NDF (Walter et al. 2007, Eq. 33): `D(h) = α² / (π (1 + (α² − 1) cos²θh)²)`
//!   `= α² / (π (sin²θh + α² cos²θh)²)`, the second form being the one evaluated (no
//!   cancellation for `α → 0`, `θh → 0`).
//! * Smith Λ (Heitz 2014, Eq. 72): `Λ(ω) = (√(1 + α² tan²θ) − 1) / 2`.
//! * Height-correlated masking-shadowing (Heitz 2014, Eq. 99): `G2 = 1 / (1 + Λ(v) + Λ(l))`.
//! * BRDF (Walter et al. 2007, Eq. 20): `ρ = D(h) G2(v, l) F / (4 cosθv cosθl)`.
//!
//! With `S(ω) = √(cos²θ + α² sin²θ)` one has `1 + Λ(ω) = (S + cosθ) / (2 cosθ)` and
//! `G2 = 2 cosθv cosθl / (S(v) cosθl + S(l) cosθv)`, hence
//! `ρ cosθl = D(h) cosθl / (2 (S(v) cosθl + S(l) cosθv))` (F = 1). This form has no
//! division by a vanishing cosine, no `tan` and no `1 − cos²` cancellation, which is what
//! keeps [`brdf_cos`] finite for grazing directions and `α` down to `1e-4` (and below).
//!
//! Visible-normal sampling follows Heitz 2018 ("Sampling the GGX Distribution of Visible
//! Normals", JCGT 7(4)); its density is `D_v(h) = G1(v) max(0, v·h) D(h) / cosθv`
//! (Heitz 2014, Eq. 38) and the reflected direction has density `D_v(h) / (4 v·h)`.

use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Smallest roughness the formulas are evaluated with; smaller inputs are raised to it so
/// that `D` stays finite at `h = n` (`D(n) = 1/(π α²)`). Far below the table's `ALPHA_MIN`.
pub(crate) const ALPHA_FLOOR: f64 = 1e-7;

/// `z > 0`, false for NaN.
#[inline]
fn above(z: f64) -> bool {
    z > 0.0
}

#[inline]
fn alpha2(alpha: f64) -> f64 {
    let a = alpha.max(ALPHA_FLOOR);
    a * a
}

/// `D` from `sin²θh`, `cos²θh` (of a unit half vector) and `α²`.
#[inline]
fn ndf(sin2: f64, cos2: f64, a2: f64) -> f64 {
    let k = sin2 + a2 * cos2;
    a2 / (PI * k * k)
}

/// `S(ω) = √(cos²θ + α² sin²θ) = cosθ · √(1 + α² tan²θ)` for a unit direction.
#[inline]
fn s_term(w: DVec3, a2: f64) -> f64 {
    (w.z * w.z + a2 * (w.x * w.x + w.y * w.y)).sqrt()
}

/// The GGX normal distribution `D(h)` as a function of `cosθh` (0 for `cosθh <= 0`).
/// Normalised so that `∫ D(h) cosθh dωh = 1` over the hemisphere.
#[inline]
pub fn d_ggx(cos_theta_h: f64, alpha: f64) -> f64 {
    if cos_theta_h.is_nan() || cos_theta_h <= 0.0 {
        return 0.0;
    }
    let c = cos_theta_h.min(1.0);
    ndf((1.0 - c) * (1.0 + c), c * c, alpha2(alpha))
}

/// Smith's `Λ(ω)` for GGX (Heitz 2014, Eq. 72), evaluated as
/// `α² sin²θ / (2 cosθ (S + cosθ))` which avoids `tanθ` and the cancellation in
/// `√(1 + x) − 1`. Returns `+∞` for `cosθ <= 0` (fully masked).
#[inline]
#[cfg(test)]
pub(crate) fn lambda(cos_theta: f64, alpha: f64) -> f64 {
    if cos_theta.is_nan() || cos_theta <= 0.0 {
        return f64::INFINITY;
    }
    let c = cos_theta.min(1.0);
    let a2s2 = alpha2(alpha) * (1.0 - c) * (1.0 + c);
    let s = (c * c + a2s2).sqrt();
    a2s2 / (2.0 * c * (s + c))
}

/// Smith masking `G1(ω) = 1 / (1 + Λ(ω)) = 2 cosθ / (cosθ + S(ω))`; 0 below the horizon.
#[inline]
#[cfg(test)]
pub(crate) fn g1(w: DVec3, alpha: f64) -> f64 {
    if !above(w.z) {
        return 0.0;
    }
    2.0 * w.z / (w.z + s_term(w, alpha2(alpha)))
}

/// Height-correlated masking-shadowing `G2(v, l) = 1 / (1 + Λ(v) + Λ(l))` (Heitz 2014,
/// Eq. 99); 0 if either direction is below the horizon.
#[inline]
#[cfg(test)]
pub(crate) fn g2(v: DVec3, l: DVec3, alpha: f64) -> f64 {
    if !(above(v.z) && above(l.z)) {
        return 0.0;
    }
    let a2 = alpha2(alpha);
    2.0 * v.z * l.z / (s_term(v, a2) * l.z + s_term(l, a2) * v.z)
}

/// `ρ(v, l) cosθl` with `F = 1`: the cosine-weighted GGX BRDF. 0 if `v` or `l` is on or
/// below the horizon. `v`, `l` are unit vectors in the local frame.
#[inline]
pub fn brdf_cos(v: DVec3, l: DVec3, alpha: f64) -> f64 {
    if !(above(v.z) && above(l.z)) {
        return 0.0;
    }
    let a2 = alpha2(alpha);
    let h = v + l; // h.z > 0, so |h| > 0
    let inv_len2 = 1.0 / h.length_squared();
    let d = ndf((h.x * h.x + h.y * h.y) * inv_len2, h.z * h.z * inv_len2, a2);
    d * l.z / (2.0 * (s_term(v, a2) * l.z + s_term(l, a2) * v.z))
}

/// `brdf_cos(v, l) / pdf_vndf_reflect(v, l) = G2(v, l) / G1(v)`: the Monte Carlo weight of
/// a direction drawn with [`sample_vndf`] + reflection (0 below the horizon). Always in
/// `[0, 1]`.
#[inline]
pub fn vndf_weight(v: DVec3, l: DVec3, alpha: f64) -> f64 {
    if !(above(v.z) && above(l.z)) {
        return 0.0;
    }
    let a2 = alpha2(alpha);
    let sv = s_term(v, a2);
    l.z * (v.z + sv) / (sv * l.z + s_term(l, a2) * v.z)
}

/// Schlick's Fresnel weight `(1 − v·h)⁵`, so that `F = F0 + (1 − F0) · weight`.
#[inline]
pub fn schlick_weight(v_dot_h: f64) -> f64 {
    let m = (1.0 - v_dot_h).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Mirror `v` about the unit vector `h`: `2 (v·h) h − v`.
#[inline]
pub fn reflect(v: DVec3, h: DVec3) -> DVec3 {
    2.0 * v.dot(h) * h - v
}

/// Sample a microfacet normal from the distribution of visible normals `D_v(h)` seen from
/// `v` (Heitz 2018, Listing 1), with `(u1, u2)` uniform in `[0, 1)²`. `v` must be above
/// the horizon. The light direction is `reflect(v, h)`; it may fall below the horizon.
#[inline]
pub fn sample_vndf(v: DVec3, alpha: f64, u1: f64, u2: f64) -> DVec3 {
    let a = alpha.max(ALPHA_FLOOR);
    // Stretch: the view direction in the configuration where the GGX lobe is a hemisphere.
    let vh = DVec3::new(a * v.x, a * v.y, v.z.max(0.0)).normalize();
    // Orthonormal basis around vh (T1 = z × vh, normalised; any basis if vh = z).
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        DVec3::X
    };
    let t2 = vh.cross(t1);
    // Uniform point on the unit disk, then warp the half-disk hidden by the projection.
    let r = u1.sqrt();
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    let p1 = r * cos_phi;
    let p2 = r * sin_phi;
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    // Reproject onto the hemisphere and unstretch.
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    DVec3::new(a * nh.x, a * nh.y, nh.z.max(0.0)).normalize()
}

/// Density, in solid angle, of `l = reflect(v, h)` with `h` drawn by [`sample_vndf`]:
/// `D_v(h) / (4 v·h) = G1(v) D(h) / (4 cosθv) = D(h) / (2 (cosθv + S(v)))`.
/// 0 when `v` is below the horizon or `l` cannot be produced (`h` below the horizon).
#[inline]
pub fn pdf_vndf_reflect(v: DVec3, l: DVec3, alpha: f64) -> f64 {
    if !above(v.z) {
        return 0.0;
    }
    let h = v + l;
    let len2 = h.length_squared();
    // v·h = (1 + v·l)/|v + l| >= 0; h.z <= 0 means no upper-hemisphere microfacet.
    if !(above(h.z) && len2 > 0.0) {
        return 0.0;
    }
    let a2 = alpha2(alpha);
    let inv_len2 = 1.0 / len2;
    let d = ndf((h.x * h.x + h.y * h.y) * inv_len2, h.z * h.z * inv_len2, a2);
    d / (2.0 * (v.z + s_term(v, a2)))
}

/// `brdf_cos(v, l)` and `pdf_vndf_reflect(v, l)` together, sharing `D(h)` (used by the fitter).
#[inline]
pub(crate) fn brdf_cos_and_pdf(v: DVec3, l: DVec3, alpha: f64) -> (f64, f64) {
    if !above(v.z) {
        return (0.0, 0.0);
    }
    let h = v + l;
    let len2 = h.length_squared();
    if !(above(h.z) && len2 > 0.0) {
        return (0.0, 0.0);
    }
    let a2 = alpha2(alpha);
    let inv_len2 = 1.0 / len2;
    let d = ndf((h.x * h.x + h.y * h.y) * inv_len2, h.z * h.z * inv_len2, a2);
    let sv = s_term(v, a2);
    let pdf = d / (2.0 * (v.z + sv));
    let f = if l.z > 0.0 {
        d * l.z / (2.0 * (sv * l.z + s_term(l, a2) * v.z))
    } else {
        0.0
    };
    (f, pdf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    fn view(theta: f64) -> DVec3 {
        DVec3::new(theta.sin(), 0.0, theta.cos())
    }

    #[test]
    fn stable_forms_match_textbook_forms() {
        let mut rng = Pcg32::new(11, 3);
        for _ in 0..10_000 {
            let alpha = rng.range(0.05, 1.0);
            let v = view(rng.range(0.0, 1.5));
            let mut l = rng.unit_vector();
            l.z = l.z.abs().max(0.01);
            let l = l.normalize();
            let h = (v + l).normalize();
            let (cv, cl, ch) = (v.z, l.z, h.z);
            let a2 = alpha * alpha;
            let d = a2 / (PI * (1.0 + (a2 - 1.0) * ch * ch).powi(2));
            let lam = |c: f64| (-1.0 + (1.0 + a2 * (1.0 - c * c) / (c * c)).sqrt()) / 2.0;
            let g = 1.0 / (1.0 + lam(cv) + lam(cl));
            let rho = d * g / (4.0 * cv * cl);
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
            assert!(rel(d_ggx(ch, alpha), d) < 1e-9);
            assert!((lambda(cv, alpha) - lam(cv)).abs() < 1e-12 * (1.0 + lam(cv)));
            assert!(rel(g2(v, l, alpha), g) < 1e-12);
            assert!(rel(brdf_cos(v, l, alpha), rho * cl) < 1e-9);
            let (f, p) = brdf_cos_and_pdf(v, l, alpha);
            assert!(rel(f, brdf_cos(v, l, alpha)) < 1e-14);
            assert!(rel(p, pdf_vndf_reflect(v, l, alpha)) < 1e-14);
            let pdf_textbook = g1(v, alpha) * v.dot(h) * d / cv / (4.0 * v.dot(h));
            assert!(rel(pdf_vndf_reflect(v, l, alpha), pdf_textbook) < 1e-9);
            assert!(rel(vndf_weight(v, l, alpha), g / g1(v, alpha)) < 1e-12);
        }
    }

    #[test]
    fn no_nan_or_inf_at_extremes() {
        let mut rng = Pcg32::new(5, 9);
        let alphas: [f64; 5] = [1e-4, 1e-3, 0.02, 0.5, 1.0];
        let cosines: [f64; 7] = [1.0, 0.5, 1e-3, 1e-8, 1e-15, 0.0, -1e-12];
        for &alpha in &alphas {
            for &cv in &cosines {
                let v = DVec3::new((1.0 - cv * cv).max(0.0).sqrt(), 0.0, cv);
                for &cl in &cosines {
                    for k in 0..64 {
                        let phi = TAU * k as f64 / 64.0;
                        let sl = (1.0 - cl * cl).max(0.0).sqrt();
                        let l = DVec3::new(sl * phi.cos(), sl * phi.sin(), cl);
                        for x in [
                            brdf_cos(v, l, alpha),
                            pdf_vndf_reflect(v, l, alpha),
                            g2(v, l, alpha),
                            vndf_weight(v, l, alpha),
                        ] {
                            assert!(x.is_finite() && x >= 0.0, "{alpha} {v} {l} {x}");
                        }
                    }
                    // The exact mirror direction, where D is largest.
                    let r = DVec3::new(-v.x, 0.0, v.z);
                    assert!(brdf_cos(v, r, alpha).is_finite());
                    assert!(pdf_vndf_reflect(v, r, alpha).is_finite());
                }
                if cv > 0.0 {
                    for _ in 0..256 {
                        let h = sample_vndf(v, alpha, rng.next_f64(), rng.next_f64());
                        assert!(h.is_finite() && (h.length() - 1.0).abs() < 1e-12 && h.z >= 0.0);
                    }
                }
            }
        }
        assert_eq!(schlick_weight(1.0), 0.0);
        assert_eq!(schlick_weight(0.0), 1.0);
        assert!((schlick_weight(0.5) - 1.0 / 32.0).abs() < 1e-16);
    }

    #[test]
    fn brdf_is_reciprocal() {
        let mut rng = Pcg32::new(1, 1);
        for _ in 0..1000 {
            let mut a = rng.unit_vector();
            let mut b = rng.unit_vector();
            a.z = a.z.abs();
            b.z = b.z.abs();
            let alpha = rng.range(0.01, 1.0);
            let x = brdf_cos(a, b, alpha) / b.z;
            let y = brdf_cos(b, a, alpha) / a.z;
            assert!((x - y).abs() <= 1e-10 * x.max(y));
        }
    }
}
