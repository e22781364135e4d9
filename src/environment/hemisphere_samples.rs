//! The ray samples of 002 Sect. 4: N cosine-weighted directions over the hemisphere from the
//! Hammersley point set (Niederreiter 1992), rotated about the normal by a per-pixel angle so
//! that neighbouring pixels do not share their sample pattern (002 used a texture of random
//! angles; here the angle is a hash of the pixel and the seed: reproducible bit for bit).

use std::f64::consts::{PI, TAU};

use glam::DVec3;

/// The N cosine-weighted Hammersley directions in the local frame (z = normal), before the
/// per-pixel rotation: `(cos φ_i, sin φ_i)` of the azimuth and the local direction's radius
/// and height, so that a rotation by α costs two multiplications per sample.
#[derive(Clone, Debug, Default)]
pub struct HemisphereSamples {
    /// Per sample: (r cos φ, r sin φ, cos θ) with r = sin θ.
    local: Vec<DVec3>,
}

/// The base-2 radical inverse (van der Corput) of `i`.
#[inline]
pub(crate) fn radical_inverse_2(i: u32) -> f64 {
    i.reverse_bits() as f64 * (1.0 / 4_294_967_296.0)
}

impl HemisphereSamples {
    /// N samples: point i of the Hammersley set is (u, v) = ((i + ½)/N, Φ₂(i)); Malley's method
    /// maps it to the cosine-weighted direction with sin θ = √u, φ = 2πv (pdf cos θ / π).
    pub fn new(n: u32) -> Self {
        let local = (0..n)
            .map(|i| {
                let u = (i as f64 + 0.5) / n as f64;
                let phi = TAU * radical_inverse_2(i);
                let r = u.sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt())
            })
            .collect();
        HemisphereSamples { local }
    }

    pub(crate) fn len(&self) -> usize {
        self.local.len()
    }

    pub fn is_empty(&self) -> bool {
        self.local.is_empty()
    }

    /// Sample `i` rotated about the normal by the angle whose (cos, sin) is `rot`, in the
    /// local frame.
    #[inline]
    pub(crate) fn rotated(&self, i: usize, rot: (f64, f64)) -> DVec3 {
        let l = self.local[i];
        let (c, s) = rot;
        DVec3::new(c * l.x - s * l.y, s * l.x + c * l.y, l.z)
    }

    /// The weight of one sample in an irradiance estimate: E ≈ (π/N) Σ L(ω_i) (002 Alg. 2
    /// line 15), since cos θ / pdf = π.
    pub(crate) fn weight(&self) -> f64 {
        PI / self.local.len().max(1) as f64
    }
}

/// The per-pixel rotation angle of 002 Sect. 4 as (cos α, sin α), α in [0, 2π): a hash of the
/// seed and the pixel (and the sub-pixel position), the same whichever thread shades it.
#[inline]
pub fn pixel_rotation(seed: u64, pixel: u64) -> (f64, f64) {
    // SplitMix64 finaliser of the pair: well mixed, cheap, stable across platforms.
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(pixel.wrapping_mul(0xD1B5_4A32_D192_ED03));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let a = TAU * ((z >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0));
    (a.cos(), a.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_unit_upper_hemisphere_and_cosine_distributed() {
        let s = HemisphereSamples::new(4096);
        let rot = pixel_rotation(7, 123);
        let (mut mean_cos, mut mean_z) = (0.0, 0.0);
        for i in 0..s.len() {
            let d = s.rotated(i, rot);
            assert!((d.length() - 1.0).abs() < 1e-12 && d.z > 0.0);
            mean_cos += d.z;
            mean_z += d.z * d.z;
        }
        let n = s.len() as f64;
        // Under pdf cos θ/π: E[cos θ] = 2/3, E[cos² θ] = 1/2 (closed forms). The stratified
        // set integrates these smooth functions to O(1/N).
        assert!((mean_cos / n - 2.0 / 3.0).abs() < 1e-3);
        assert!((mean_z / n - 0.5).abs() < 1e-3);
    }
}
