//! The estimators of 003 Sect. 3, per pixel, from the analytic U and the sums S_N, U_N.

use crate::shading::brdf::luminance;
use glam::DVec3;

/// An estimator of the shadowed illumination S.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// S_N (Eq. 10).
    FullStochastic,
    /// U − (U_N − S_N): the control variate with c = 1 (Eq. 11). Can be negative.
    ControlVariate,
    /// U × S_N / U_N per channel (Eq. 15).
    Ratio,
    /// U × lum(S_N) / lum(U_N): one grayscale weighted shadow for all channels (Sect. 3.4).
    RatioGray,
}

/// The illumination-weighted shadow W_N = S_N / U_N (Eq. 23) of one channel (the denoiser's
/// definition: 1 where U_N is 0, clamped to [0, 1]).
pub(crate) use crate::denoise::ratio::weighted_shadow_value as weighted_shadow;

/// Combines the analytic unshadowed U with the stochastic S_N and U_N.
#[inline]
pub fn combine(estimator: Estimator, u: DVec3, s_n: DVec3, u_n: DVec3) -> DVec3 {
    match estimator {
        Estimator::FullStochastic => s_n,
        Estimator::ControlVariate => u - (u_n - s_n),
        Estimator::Ratio => DVec3::new(
            u.x * weighted_shadow(s_n.x, u_n.x),
            u.y * weighted_shadow(s_n.y, u_n.y),
            u.z * weighted_shadow(s_n.z, u_n.z),
        ),
        Estimator::RatioGray => u * weighted_shadow(luminance(s_n), luminance(u_n)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_is_exactly_u_when_nothing_is_shadowed() {
        let u = DVec3::new(0.3, 1.7, 1e-30);
        let s = DVec3::new(0.123456789, 3.3, 7e-300);
        for e in [Estimator::Ratio, Estimator::RatioGray] {
            assert_eq!(combine(e, u, s, s), u);
        }
        assert_eq!(combine(Estimator::ControlVariate, u, s, s), u);
    }

    #[test]
    fn fully_shadowed_ratio_is_zero_and_unseen_light_keeps_u() {
        let u = DVec3::splat(2.0);
        let un = DVec3::new(1.0, 0.5, 0.25);
        assert_eq!(combine(Estimator::Ratio, u, DVec3::ZERO, un), DVec3::ZERO);
        assert_eq!(combine(Estimator::Ratio, u, DVec3::ZERO, DVec3::ZERO), u);
    }
}
