//! The BRDF every renderer evaluates: Lambertian `kd/π` plus GGX with Schlick's Fresnel, and
//! its importance sampling (cosine-weighted diffuse, GGX visible normals for the specular
//! lobe). Directions are unit vectors in the shading frame (`z` = normal).

use crate::ltc::ggx;
use crate::scene::Material;
use glam::DVec3;
use std::f64::consts::{FRAC_1_PI, TAU};

/// Rec. 709 luminance, used to weigh RGB quantities when choosing between sampling strategies.
pub(crate) use crate::raster::luminance;

/// `ρ(v, l) cosθl` per channel; 0 when `v` or `l` is on or below the horizon.
#[inline]
pub(crate) fn eval_cos(material: &Material, v: DVec3, l: DVec3) -> DVec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return DVec3::ZERO;
    }
    let mut f = material.kd * (FRAC_1_PI * l.z);
    if material.has_specular() {
        f += specular_cos(material.ks, material.alpha, v, l);
    }
    f
}

/// The GGX term of [`eval_cos`]: `ρ_s(v, l) cosθl` per channel with Schlick's Fresnel of
/// reflectance `ks` at normal incidence; 0 when `v` or `l` is on or below the horizon.
#[inline]
pub(crate) fn specular_cos(ks: DVec3, alpha: f64, v: DVec3, l: DVec3) -> DVec3 {
    if v.z <= 0.0 || l.z <= 0.0 {
        return DVec3::ZERO;
    }
    let h = (v + l).normalize();
    let w = ggx::schlick_weight(v.dot(h));
    let spec = ggx::brdf_cos(v, l, alpha);
    ks.map(|f0| (f0 + (1.0 - f0) * w) * spec)
}

/// How a material is importance sampled: the probability of drawing from the specular lobe
/// (the rest is cosine-weighted), proportional to the luminance of `ks` against `kd`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BrdfSampler {
    pub specular_probability: f64,
    pub alpha: f64,
}

impl BrdfSampler {
    pub fn new(material: &Material) -> Self {
        let (d, s) = (
            luminance(material.kd).max(0.0),
            if material.has_specular() {
                luminance(material.ks).max(0.0)
            } else {
                0.0
            },
        );
        BrdfSampler {
            specular_probability: if s + d > 0.0 { s / (s + d) } else { 0.0 },
            alpha: material.alpha,
        }
    }

    /// A direction drawn from the mixture (`u0` picks the lobe); may be below the horizon,
    /// where the BRDF is 0.
    #[inline]
    pub fn sample(&self, v: DVec3, u0: f64, u1: f64, u2: f64) -> DVec3 {
        if u0 < self.specular_probability {
            let h = ggx::sample_vndf(v, self.alpha, u1, u2);
            ggx::reflect(v, h)
        } else {
            // Malley's method: a uniform point on the disk lifted to the hemisphere.
            let r = u1.sqrt();
            let (s, c) = (TAU * u2).sin_cos();
            DVec3::new(r * c, r * s, (1.0 - u1).max(0.0).sqrt())
        }
    }

    /// Solid-angle density of [`BrdfSampler::sample`] at `l`.
    #[inline]
    pub fn pdf(&self, v: DVec3, l: DVec3) -> f64 {
        if l.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability;
        let mut p = (1.0 - ps) * l.z * FRAC_1_PI;
        if ps > 0.0 {
            p += ps * ggx::pdf_vndf_reflect(v, l, self.alpha);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    fn material(kd: f64, ks: f64, alpha: f64) -> Material {
        Material {
            name: "m".into(),
            kd: DVec3::splat(kd),
            ks: DVec3::splat(ks),
            alpha,
            ke: DVec3::ZERO,
        }
    }

    /// The sampler's density integrates to the probability of landing above the horizon, and
    /// importance-sampled estimates of ∫ρ cos agree with uniform-hemisphere estimates of the
    /// same integral (two independent estimators, compared within their joint 5σ).
    #[test]
    fn sampled_and_uniform_estimates_of_albedo_agree() {
        let mut rng = Pcg32::new(7, 1);
        for &(kd, ks, alpha, theta) in &[
            (0.8, 0.0, 0.5, 0.3),
            (0.3, 0.7, 0.3, 0.8),
            (0.0, 1.0, 0.15, 1.2),
            (0.5, 0.5, 0.6, 0.1),
        ] {
            let m = material(kd, ks, alpha);
            let s = BrdfSampler::new(&m);
            let v = DVec3::new(f64::sin(theta), 0.0, f64::cos(theta));
            let n = 400_000;
            let (mut a, mut a2, mut b, mut b2, mut pint) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for _ in 0..n {
                let l = s.sample(v, rng.next_f64(), rng.next_f64(), rng.next_f64());
                let p = s.pdf(v, l);
                if p > 0.0 {
                    let x = eval_cos(&m, v, l).x / p;
                    a += x;
                    a2 += x * x;
                }
                // Uniform hemisphere for the second estimator and the pdf integral.
                let z = rng.next_f64();
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = TAU * rng.next_f64();
                let lu = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                let y = eval_cos(&m, v, lu).x * TAU;
                b += y;
                b2 += y * y;
                pint += s.pdf(v, lu) * TAU;
            }
            let nf = n as f64;
            let (ma, mb) = (a / nf, b / nf);
            let sa = ((a2 / nf - ma * ma) / nf).sqrt();
            let sb = ((b2 / nf - mb * mb) / nf).sqrt();
            assert!(
                (ma - mb).abs() < 5.0 * (sa * sa + sb * sb).sqrt(),
                "kd {kd} ks {ks} α {alpha}: {ma} vs {mb} (σ {sa}, {sb})"
            );
            // ∫ pdf over the upper hemisphere ≤ 1 (VNDF reflections can go below it).
            assert!(pint / nf < 1.0 + 0.02, "pdf integral {}", pint / nf);
        }
    }
}
