//! The denoiser of Heitz, Hill and McGuire 2018 (paper 003) for the ratio estimator of direct
//! illumination: pure functions from whole images to whole images.
//!
//! The stochastic estimators produce, per pixel, the analytic unshadowed illumination U, the
//! stochastic shadowed illumination S_N and the stochastic unshadowed illumination U_N (the same
//! samples, so 0 ≤ S_N ≤ U_N per channel), plus a [`GBuffer`]. The result is
//!
//! `U × denoise[S_N] / denoise[U_N]`   (003 Eq. 25–27: denoise *before* dividing),
//!
//! which converges to S = U·W as the denoised neighbourhood grows, whereas denoising
//! W_N = S_N/U_N itself is biased (Eq. 26).
//!
//! * [`gbuffer`]: [`GBuffer`], the per-pixel surface the bilateral weights compare.
//! * `settings`: [`DenoiseSettings`] and the reasoning behind its defaults.
//! * `noise_estimate`: E, Eq. 29 (003 Sect. 4.2) and its 3×3 box filter.
//! * `joint_bilateral`: the separable joint-bilateral filter of S_N and
//!   U_N (003 Sect. 4.1, passes 3–4).
//! * `ratio`: W_N (Eq. 23), U × dS/dU (Eq. 25) and the two pipelines: [`ratio_denoised`]
//!   (003 Sect. 4.1, σ from E) and [`ratio_bilateral`] (fixed σ, paper 000's comparison).
//!
//! Every function parallelises over rows with rayon, allocates whole images per call and
//! nothing per pixel, is bit-identical whatever the number of threads, and returns finite values
//! for any input. See `docs/denoiser.md`.

pub(crate) use crate::raster::gbuffer;
pub(crate) mod joint_bilateral;
pub(crate) mod noise_estimate;
pub(crate) mod ratio;
pub(crate) mod settings;

#[cfg(test)]
mod test_util;

pub(crate) use gbuffer::GBuffer;
pub use joint_bilateral::{MAX_KERNEL_RADIUS, joint_bilateral, joint_bilateral_cancellable};
pub use noise_estimate::{box_filter_3x3, line_total_variation, noise_estimate};
pub use ratio::{
    DenoiseAovs, ratio_bilateral, ratio_bilateral_cancellable, ratio_combine, ratio_denoised,
    ratio_denoised_cancellable, scalar_image, weighted_shadow,
};
pub use settings::DenoiseSettings;
