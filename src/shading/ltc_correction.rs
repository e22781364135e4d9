//! The LTC's error, corrected without shadow rays (`--method analytic-exact`; docs/ltc.md,
//! "Converging to GGX").
//!
//! Alg. 1 finds the visible spherical polygon `V` exactly; only the LTC is approximate. With
//! `s · D̂` the integrand the LTC integrates (`integrate_lobes`: `s` = `specular_scale(F0)`,
//! `D̂ = (1 − c) D̂_M + c D_o` the LTC `D̂_M(ω) = D_o(M⁻¹ω/‖M⁻¹ω‖) |M⁻¹| / ‖M⁻¹ω‖³` of
//! 001 Eq. 3.11 with the table's cosine tail `c`, docs/ltc.md),
//!
//! ```text
//! ∫_V f_GGX cos dω = s ∫_V D̂ dω  +  ∫_V (f_GGX cos − s D̂) dω
//!                    (analytic, LTC)    (estimated here)
//! ```
//!
//! The second term is estimated by directions drawn from a mixture of three densities
//! (one-sample MIS with the balance heuristic, Veach 1997 Sect. 9.2.2), the lobe's share being
//! the LTC's own mass inside `V` (`∫_V D̂`, known exactly: the fraction of lobe samples that
//! land in `V`), clamped to [0.05, 0.95]:
//!
//! * `p_ltc = D̂`: the LTC itself (a cosine sample, mapped by `M` outside the tail's share),
//! * `p_ggx`: GGX visible normals (Heitz 2018), reflected, for the tail the LTC lacks,
//! * `p_fan = c(ω) / S`: uniform over the fan triangles of `V`'s loops, each loop fanned from
//!   its own first vertex (`S` the sum of their unsigned solid angles, `c(ω)` how many of them
//!   cover `ω`), for lights small against the lobe.
//!
//! Whether a direction lies in `V` is read from the same fan: the signed count of the triangles
//! covering it is `V`'s winding number (1 inside, 0 outside or in a hole). No ray is traced and
//! no triangulation built, and the estimate is zero wherever the LTC is exact: the noise is
//! where the LTC is wrong, and it vanishes as samples accumulate.

use super::brdf::specular_cos;
use crate::geometry::{SphericalPolygon, orient};
use crate::ltc::{LtcEntry, ggx};
use crate::math::Pcg32;
use crate::sampling::spherical_triangle::{SphericalTriangle, solid_angle_of_triangle};
use glam::{DMat3, DVec3};
use std::f64::consts::{FRAC_1_PI, TAU};

/// Bounds of the share of samples drawn from the lobe (LTC and GGX, half each); the rest are
/// drawn from the fan of `V`. Neither strategy is ever switched off (defensive mixture).
const LOBE_SHARE_MIN: f64 = 0.05;
const LOBE_SHARE_MAX: f64 = 0.95;

/// How many correction samples to take at a shading point, and from which random stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CorrectionSampling {
    /// Directions per light piece (0: the LTC alone).
    pub samples: u32,
    pub seed: u64,
    /// The camera ray's stream: every light piece of it draws from `(seed ⊕ piece, stream)`.
    pub stream: u64,
}

impl CorrectionSampling {
    /// The generator of light piece `(light, face)`: deterministic, independent of the order
    /// in which pieces and threads run.
    pub(crate) fn rng(&self, light: usize, face: Option<usize>) -> Pcg32 {
        let piece = (light as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ face.map_or(0, |f| (f as u64 + 1).wrapping_mul(0xbf58_476d_1ce4_e5b9));
        Pcg32::new(self.seed ^ piece, self.stream)
    }
}

/// The specular lobe at one shading point, in its local frame: GGX with Schlick's Fresnel,
/// and the LTC that approximates it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GlossyLobe {
    /// View direction (local frame, `z` = normal).
    v: DVec3,
    alpha: f64,
    ks: DVec3,
    /// `s = specular_scale(F0)` per channel: the LTC's integrand is `s · D̂`.
    scale: DVec3,
    m: DMat3,
    m_inv: DMat3,
    /// `|det M⁻¹|`.
    det_inv: f64,
    /// Share of the cosine tail ([`LtcEntry::cosine`]).
    cosine: f64,
}

impl GlossyLobe {
    /// `None` when the view is on or below the horizon (the BRDF is 0) or `M⁻¹` is singular.
    pub fn new(entry: &LtcEntry, scale: DVec3, v: DVec3, alpha: f64, ks: DVec3) -> Option<Self> {
        let det = entry.m_inv.determinant();
        if v.z <= 0.0 || !(det.abs() > 0.0 && det.is_finite()) {
            return None;
        }
        Some(GlossyLobe {
            v,
            alpha,
            ks,
            scale,
            m: entry.m_inv.inverse(),
            m_inv: entry.m_inv,
            det_inv: det.abs(),
            cosine: entry.cosine,
        })
    }

    /// `D̂(ω) = (1 − c) D̂_M(ω) + c D_o(ω)`: the fitted distribution's normalised density,
    /// `D̂_M` of 001 Eq. 3.11 and the cosine tail `D_o(ω) = max(0, ω_z)/π`.
    #[inline]
    pub(crate) fn ltc_density(&self, w: DVec3) -> f64 {
        let x = self.m_inv * w;
        let len2 = x.length_squared();
        // D_o(x/|x|) = (x.z/|x|)/π, times |M⁻¹| / |x|³.
        let d_m = if x.z > 0.0 && len2 > 0.0 {
            FRAC_1_PI * x.z * self.det_inv / (len2 * len2)
        } else {
            0.0
        };
        (1.0 - self.cosine) * d_m + self.cosine * FRAC_1_PI * w.z.max(0.0)
    }

    /// A direction distributed as `D̂`: a cosine-distributed `ω_o`, mapped by `M` unless `u1`
    /// falls in the tail's share (then rescaled to `[0, 1)`).
    #[inline]
    fn sample_ltc(&self, u1: f64, u2: f64) -> DVec3 {
        let (u1, tail) = if u1 < self.cosine {
            (u1 / self.cosine, true)
        } else {
            ((u1 - self.cosine) / (1.0 - self.cosine), false)
        };
        let r = u1.sqrt();
        let (s, c) = (TAU * u2).sin_cos();
        let wo = DVec3::new(r * c, r * s, (1.0 - u1).max(0.0).sqrt());
        if tail { wo } else { (self.m * wo).normalize() }
    }

    /// `f_GGX cos − s D̂` per channel at `ω` (above the horizon).
    #[inline]
    pub(crate) fn difference(&self, w: DVec3) -> DVec3 {
        specular_cos(self.ks, self.alpha, self.v, w) - self.scale * self.ltc_density(w)
    }
}

/// One triangle of a loop's fan, as drawn from and as tested against.
#[derive(Clone, Copy, Debug)]
struct FanTriangle {
    apex: DVec3,
    a: DVec3,
    b: DVec3,
    /// +1 counter-clockwise (part of a filled loop), −1 clockwise (a hole, or a fold).
    sign: f64,
    /// Running sum of the fan's unsigned solid angles up to and including this triangle.
    cumulative: f64,
    sampler: SphericalTriangle,
}

impl FanTriangle {
    /// Is `w` inside (boundary included)?
    #[inline]
    fn covers(&self, w: DVec3) -> bool {
        let s = self.sign;
        s * orient(self.apex, self.a, w) >= 0.0
            && s * orient(self.a, self.b, w) >= 0.0
            && s * orient(self.b, self.apex, w) >= 0.0
    }
}

/// Reused buffers of [`estimate_correction`].
#[derive(Default)]
pub(crate) struct CorrectionScratch {
    fan: Vec<FanTriangle>,
}

/// The mean and its variance of one light piece's correction estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct CorrectionEstimate {
    /// Estimate of `∫_V (f_GGX cos − s D̂) dω` per channel (unit radiance).
    pub mean: DVec3,
    /// Variance of `mean` (the sample variance over `samples`).
    pub variance: DVec3,
}

/// Estimates `∫_V (f_GGX cos − s D̂) dω` over the visible polygon `visible` (local frame,
/// clipped to the horizon, holes clockwise) with `samples` directions from `rng`. `lobe_mass`
/// is `∫_V D̂` (the LTC integral of `V`, which the caller has just computed): it sets how
/// many samples are drawn from the lobe rather than from `V`.
pub(crate) fn estimate_correction(
    visible: &SphericalPolygon,
    lobe: &GlossyLobe,
    lobe_mass: f64,
    samples: u32,
    rng: &mut Pcg32,
    scratch: &mut CorrectionScratch,
) -> CorrectionEstimate {
    let fan = &mut scratch.fan;
    fan.clear();
    let mut total = 0.0;
    for lp in visible.loops() {
        let Some((&apex, rest)) = lp.split_first() else {
            continue;
        };
        for e in rest.windows(2) {
            let (a, b) = (e[0], e[1]);
            let area = solid_angle_of_triangle(apex, a, b);
            let Some(sampler) = SphericalTriangle::new(apex, a, b) else {
                continue; // no area: never drawn, and covers nothing of measure
            };
            total += area.abs();
            fan.push(FanTriangle {
                apex,
                a,
                b,
                sign: area.signum(),
                cumulative: total,
                sampler,
            });
        }
    }
    if samples == 0 || fan.is_empty() || total.is_nan() || total <= 0.0 {
        return CorrectionEstimate::default();
    }
    // A lobe sample lands in V with probability ∫_V D̂ (LTC) or about that (GGX): where V holds
    // most of the lobe, the lobe's samples follow the integrand; where V is a small part of it,
    // the fan's do.
    let lobe_share = lobe_mass.clamp(LOBE_SHARE_MIN, LOBE_SHARE_MAX);
    let (p_ltc, p_ggx, p_fan) = (0.5 * lobe_share, 0.5 * lobe_share, 1.0 - lobe_share);
    let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..samples {
        let (u0, u1, u2) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
        let w = if u0 < p_ltc {
            lobe.sample_ltc(u1, u2)
        } else if u0 < p_ltc + p_ggx {
            ggx::reflect(lobe.v, ggx::sample_vndf(lobe.v, lobe.alpha, u1, u2))
        } else {
            // Reuse u0 to pick the triangle, in proportion to its solid angle.
            let t = (u0 - p_ltc - p_ggx) / p_fan * total;
            let k = fan
                .partition_point(|f| f.cumulative <= t)
                .min(fan.len() - 1);
            fan[k].sampler.sample(u1, u2)
        };
        if w.z <= 0.0 {
            continue; // V is above the horizon
        }
        let (mut winding, mut covering) = (0.0, 0u32);
        for f in fan.iter() {
            if f.covers(w) {
                winding += f.sign;
                covering += 1;
            }
        }
        if winding < 0.5 {
            continue; // outside V, or in a hole
        }
        let pdf = p_ltc * lobe.ltc_density(w)
            + p_ggx * ggx::pdf_vndf_reflect(lobe.v, w, lobe.alpha)
            + p_fan * covering as f64 / total;
        let x = lobe.difference(w) / pdf;
        sum += x;
        sum2 += x * x;
    }
    let n = samples as f64;
    let mean = sum / n;
    CorrectionEstimate {
        mean,
        variance: ((sum2 / n - mean * mean) / n).max(DVec3::ZERO),
    }
}
