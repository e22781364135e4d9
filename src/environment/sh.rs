//! Three-band real spherical harmonics (9 coefficients per colour channel): projection of an
//! environment map, reconstruction (Eq. 8 of paper 002), unshadowed irradiance (Eq. 7,
//! Ramamoorthi–Hanrahan 2001) and the radiance written as a quadratic form in the direction,
//! which is what the polygon integral of [`super::polygon_integral`] consumes.
//!
//! The basis is defined on **world** coordinates: the environment is y-up, and the formulas
//! below are evaluated on the world (x, y, z) of the direction as they stand. So Y1−1 is the
//! up/down lobe, Y10 the ±z lobe and Y20 is symmetric about the z axis, not about "up". Nothing
//! depends on which axis is up, as long as projection and evaluation use the same convention.

use glam::{DMat3, DVec3};

use super::map::EnvironmentMap;

/// Y00 = 1 / (2 √π). The notes round it to 0.282095; full precision keeps the basis
/// orthonormal to 1e-16 instead of 1e-6.
pub(crate) const SH_Y00: f64 = 0.282_094_791_773_878_14;
/// The band-1 factor √(3 / 4π) (0.488603 in the notes).
pub(crate) const SH_Y1: f64 = 0.488_602_511_902_919_9;
/// The factor of Y2−2, Y2−1, Y21: √(15 / 4π) (1.092548 in the notes).
pub(crate) const SH_Y2_XY: f64 = 1.092_548_430_592_079_2;
/// The factor of Y20 = k (3z² − 1): √5 / (4 √π) (0.315392 in the notes).
pub(crate) const SH_Y20: f64 = 0.315_391_565_252_520_05;
/// The factor of Y22 = k (x² − y²): √15 / (4 √π) (0.546274 in the notes).
pub(crate) const SH_Y22: f64 = 0.546_274_215_296_039_6;

/// Ramamoorthi–Hanrahan's clamped-cosine convolution factors Â_l for l = 0, 1, 2 (Eq. 7).
pub(crate) const SH_COSINE_LOBE: [f64; 3] = [
    std::f64::consts::PI,
    2.0 * std::f64::consts::PI / 3.0,
    std::f64::consts::PI / 4.0,
];

/// The band l of each of the nine coefficients.
const BAND: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// The nine real SH basis functions at the world direction `d` (unit length), in the order
/// Y00; Y1−1 (y), Y10 (z), Y11 (x); Y2−2 (xy), Y2−1 (yz), Y20 (3z² − 1), Y21 (xz),
/// Y22 (x² − y²).
pub fn sh_basis(d: DVec3) -> [f64; 9] {
    let DVec3 { x, y, z } = d;
    [
        SH_Y00,
        SH_Y1 * y,
        SH_Y1 * z,
        SH_Y1 * x,
        SH_Y2_XY * x * y,
        SH_Y2_XY * y * z,
        SH_Y20 * (3.0 * z * z - 1.0),
        SH_Y2_XY * x * z,
        SH_Y22 * (x * x - y * y),
    ]
}

/// A 3-band SH radiance function: nine RGB coefficients in the order of [`sh_basis`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sh9 {
    pub coeffs: [DVec3; 9],
}

impl Sh9 {
    /// Projects the radiance the renderer sees (the map with its rotation and scale applied)
    /// onto the basis: L_lm = Σ_pixels L(d) Y_lm(d) ΔΩ, with ΔΩ the exact solid angle of the
    /// pixel and d its centre. The pixel values are constant over a pixel, the basis is not,
    /// so this is midpoint quadrature: O(Δθ²) relative error (about 1e-5 at 512×256).
    pub fn project(map: &EnvironmentMap) -> Sh9 {
        let to_world = map.rotation();
        let mut coeffs = [DVec3::ZERO; 9];
        for j in 0..map.height() {
            let solid_angle = map.solid_angle(j);
            for i in 0..map.width() {
                let radiance = map.scale * map.pixel(i, j);
                let y = sh_basis(to_world * map.direction(i, j));
                for (c, y) in coeffs.iter_mut().zip(y) {
                    *c += radiance * (y * solid_angle);
                }
            }
        }
        Sh9 { coeffs }
    }

    /// The reconstructed radiance in the world direction `d` (Eq. 8):
    /// Σ_lm L_lm Y_lm(d). Can be negative between lobes (ringing of the band limit).
    pub fn eval(&self, d: DVec3) -> DVec3 {
        let y = sh_basis(d);
        self.coeffs
            .iter()
            .zip(y)
            .fold(DVec3::ZERO, |acc, (c, y)| acc + *c * y)
    }

    /// The unshadowed irradiance ∫ L(ω) max(0, n·ω) dω of the 3-band radiance, exact for it
    /// (Eq. 7, Ramamoorthi–Hanrahan): Σ_lm Â_l L_lm Y_lm(n), Â = (π, 2π/3, π/4). For a map
    /// that is not band-limited this is the usual approximation (bands ≥ 3 dropped).
    pub fn irradiance(&self, n: DVec3) -> DVec3 {
        let y = sh_basis(n);
        let mut e = DVec3::ZERO;
        for k in 0..9 {
            e += self.coeffs[k] * (SH_COSINE_LOBE[BAND[k]] * y[k]);
        }
        e
    }

    /// The same radiance written as L(ω) = c + b·ω + ωᵀMω per channel, in world coordinates
    /// (the notes' "radiance as a quadratic"). Exact on the unit sphere, where x²+y²+z² = 1
    /// turned the constant of Y20 into part of c.
    pub fn quadratic(&self) -> ShQuadratic {
        let l = self.coeffs;
        let channel = |k: usize| {
            let [l00, l1m1, l10, l11, l2m2, l2m1, l20, l21, l22] = l.map(|c| c[k]);
            let c = SH_Y00 * l00 - SH_Y20 * l20;
            let b = SH_Y1 * DVec3::new(l11, l1m1, l10);
            // The off-diagonal entries carry half of Y2's factor each: ωᵀMω counts them twice.
            let k22 = SH_Y22;
            let (mxy, myz, mxz) = (k22 * l2m2, k22 * l2m1, k22 * l21);
            let m = DMat3::from_cols(
                DVec3::new(k22 * l22, mxy, mxz),
                DVec3::new(mxy, -k22 * l22, myz),
                DVec3::new(mxz, myz, 3.0 * SH_Y20 * l20),
            );
            Quadratic { c, b, m }
        };
        ShQuadratic {
            channels: [channel(0), channel(1), channel(2)],
        }
    }

    /// [`Self::quadratic`] expressed in a local frame: `world_to_local * ω_world` are the local
    /// coordinates, e.g. `DMat3::from_cols(t, b, n).transpose()` for a shading frame with the
    /// normal n as local z. This is the form the renderer's polygons (local, N = z) need.
    pub fn local_quadratic(&self, world_to_local: DMat3) -> ShQuadratic {
        self.quadratic().in_frame(world_to_local)
    }
}

impl std::ops::Add for Sh9 {
    type Output = Sh9;
    fn add(self, o: Sh9) -> Sh9 {
        Sh9 {
            coeffs: std::array::from_fn(|k| self.coeffs[k] + o.coeffs[k]),
        }
    }
}

impl std::ops::Mul<f64> for Sh9 {
    type Output = Sh9;
    fn mul(self, s: f64) -> Sh9 {
        Sh9 {
            coeffs: self.coeffs.map(|c| c * s),
        }
    }
}

/// One colour channel of a 3-band radiance as a quadratic form: L(ω) = c + b·ω + ωᵀMω,
/// M symmetric. Valid on the unit sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadratic {
    pub c: f64,
    pub b: DVec3,
    pub m: DMat3,
}

impl Quadratic {
    /// c + b·ω + ωᵀMω.
    pub fn eval(&self, w: DVec3) -> f64 {
        self.c + self.b.dot(w) + w.dot(self.m * w)
    }

    /// `d/dt q(R_t ω)` at t = 0, for the rotation `R_t` of angular velocity `omega`: the rate
    /// of the radiance seen at a fixed direction of a frame that turns with `−omega` relative
    /// to the radiance. With `K ω = omega × ω` (`Kᵀ = −K`), `∇q · Kω = (b + 2Mω) · Kω` gives
    /// `b' = Kᵀb = b × omega` and the symmetric `M' = MK − KM`; `c' = 0`. Exact on the sphere
    /// (`Kω` is tangent, so the extension off the sphere does not matter).
    pub fn rotation_rate(&self, omega: DVec3) -> Quadratic {
        let k = DMat3::from_cols(
            omega.cross(DVec3::X),
            omega.cross(DVec3::Y),
            omega.cross(DVec3::Z),
        );
        Quadratic {
            c: 0.0,
            b: self.b.cross(omega),
            m: self.m * k - k * self.m,
        }
    }

    /// The same function in a rotated frame, ω' = R ω: b' = R b, M' = R M Rᵀ.
    pub(crate) fn in_frame(&self, world_to_local: DMat3) -> Quadratic {
        let r = world_to_local;
        Quadratic {
            c: self.c,
            b: r * self.b,
            m: r * self.m * r.transpose(),
        }
    }
}

/// The three colour channels of a 3-band radiance as quadratic forms (red, green, blue).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShQuadratic {
    pub channels: [Quadratic; 3],
}

impl ShQuadratic {
    /// The RGB radiance at ω; equals [`Sh9::eval`] in the frame the quadratic is expressed in.
    pub fn eval(&self, w: DVec3) -> DVec3 {
        let [r, g, b] = &self.channels;
        DVec3::new(r.eval(w), g.eval(w), b.eval(w))
    }

    /// All three channels' [`Quadratic::rotation_rate`].
    pub fn rotation_rate(&self, omega: DVec3) -> ShQuadratic {
        ShQuadratic {
            channels: self.channels.map(|q| q.rotation_rate(omega)),
        }
    }

    /// All three channels in a rotated frame (see [`Quadratic::in_frame`]).
    pub fn in_frame(&self, world_to_local: DMat3) -> ShQuadratic {
        ShQuadratic {
            channels: self.channels.map(|q| q.in_frame(world_to_local)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    /// Oracle: central differences of `q(R_t ω)` (Rodrigues' rotation), whose error is
    /// O(h²) of a smooth function.
    #[test]
    fn rotation_rate_is_the_derivative_of_the_rotated_radiance() {
        let mut rng = Pcg32::new(7, 1);
        let mut u = || 2.0 * rng.next_f64() - 1.0;
        for _ in 0..50 {
            let sh = Sh9 {
                coeffs: std::array::from_fn(|_| DVec3::new(u(), u(), u())),
            };
            let q = sh.quadratic().channels[1];
            let omega = DVec3::new(u(), u(), u());
            let w = DVec3::new(u(), u(), u()).normalize();
            let turned = |t: f64| {
                let r = glam::DQuat::from_scaled_axis(omega * t);
                q.eval(r * w)
            };
            let h = 1e-5;
            let fd = (turned(h) - turned(-h)) / (2.0 * h);
            let exact = q.rotation_rate(omega).eval(w);
            assert!(
                (exact - fd).abs() <= 1e-8 * (1.0 + fd.abs()),
                "{exact} vs {fd}"
            );
        }
    }
}
