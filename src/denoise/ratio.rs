//! The ratio-denoised image of 003 (Eq. 23–27) and the two pipelines that produce it.

use super::joint_bilateral::{check_image, sanitize};
use super::{DenoiseSettings, GBuffer, joint_bilateral, noise_estimate};
use crate::render::Image;
use glam::DVec3;
use rayon::prelude::*;

/// The intermediate images of a denoise call, for a debugger to show. Scalar images are
/// row-major with one value per pixel; [`scalar_image`] turns them into gray images.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DenoiseAovs {
    /// W_N = lum(S_N)/lum(U_N) (Eq. 23 on luminance, [`weighted_shadow`]); 1 where undefined.
    pub w_n: Vec<f64>,
    /// The noise estimate E after the 3×3 box filter (Eq. 29); all 0 for [`ratio_bilateral`],
    /// which does not compute it.
    pub noise: Vec<f64>,
    /// The Gaussian standard deviation used at each pixel, in pixels; 0 where the pixel was
    /// copied unchanged.
    pub sigma: Vec<f64>,
    /// denoise[S_N].
    pub s_denoised: Image,
    /// denoise[U_N].
    pub u_denoised: Image,
}

/// Rec. 709 luminance of a linear-RGB colour.
#[inline]
pub fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The grayscale weighted shadow of Eq. 23, W_N = S_N / U_N, on luminance (the grayscale
/// weighted shadow of 003 Sect. 3.4), which feeds the noise estimate.
///
/// W_N = 1 where lum(U_N) = 0 (then S_N = 0 too: 0/0, which 003 Sect. 4.2 sets to 1) and on
/// invalid pixels; elsewhere the ratio is clamped to [0, 1] (it lies there whenever
/// 0 ≤ S_N ≤ U_N). In f64 a positive lum(U_N), however small, gives a well-defined ratio, so only
/// an exact 0 counts as "both close to zero". Non-finite or negative channels read as 0.
pub fn weighted_shadow(s_n: &Image, u_n: &Image, g: &GBuffer) -> Vec<f64> {
    g.check();
    check_image(s_n, g, "S_N");
    check_image(u_n, g, "U_N");
    let mut w = vec![1.0; g.len()];
    w.par_iter_mut().enumerate().for_each(|(i, w)| {
        if g.valid[i] {
            // Halving is exact and keeps the weighted sums below f64::MAX.
            let s = luminance(sanitize(s_n.pixels[i]) * 0.5);
            let u = luminance(sanitize(u_n.pixels[i]) * 0.5);
            if u > 0.0 {
                *w = (s / u).clamp(0.0, 1.0);
            }
        }
    });
    w
}

/// Eq. 25 applied to U (003 Sect. 3.5): result = U × denoise[S_N] / denoise[U_N], per channel.
///
/// Where denoise[U_N] = 0 in a channel (then denoise[S_N] = 0 too, as the filter keeps
/// S_N ≤ U_N) the ratio is 0/0 and is taken as 1, i.e. the result is U: the same convention
/// W = 1 as the noise estimate, and the natural one, since no sample saw any light to shadow.
/// The ratio is clamped to [0, 1], which only removes rounding (the filter keeps
/// 0 ≤ dS ≤ dU). Non-finite or negative channels of U read as 0, so the result is finite.
pub fn ratio_combine(u: &Image, s_denoised: &Image, u_denoised: &Image) -> Image {
    let n = u.pixels.len();
    assert!(
        s_denoised.pixels.len() == n && u_denoised.pixels.len() == n,
        "U, denoise[S_N] and denoise[U_N] must have the same size"
    );
    let mut out = Image {
        width: u.width,
        height: u.height,
        pixels: vec![DVec3::ZERO; n],
    };
    let ratio = |s: f64, d: f64| {
        if d > 0.0 && s.is_finite() {
            (s / d).clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    out.pixels.par_iter_mut().enumerate().for_each(|(i, o)| {
        let (s, d) = (s_denoised.pixels[i], u_denoised.pixels[i]);
        let w = DVec3::new(ratio(s.x, d.x), ratio(s.y, d.y), ratio(s.z, d.z));
        *o = sanitize(u.pixels[i]) * w;
    });
    out
}

/// The σ actually applied for a requested `sigma`: 0 (copy) below `settings.sigma_min` or for
/// NaN, else `sigma` itself.
fn applied_sigma(sigma: f64, settings: &DenoiseSettings) -> f64 {
    if sigma >= settings.sigma_min && sigma > 0.0 {
        sigma
    } else {
        0.0
    }
}

/// The denoiser of 003 Sect. 4.1, passes 1–4 (no temporal pass):
///
/// 1. W_N from luminance ([`weighted_shadow`], Eq. 23), E from W_N ([`noise_estimate`], Eq. 29);
/// 2. E box-filtered 3×3 (inside [`noise_estimate`]);
/// 3. σ = min(`sigma_gain`·E, `sigma_max`) per pixel (0 below `sigma_min`: the pixel is copied);
///    003 Sect. 4.1: "the standard deviation of the Gaussian kernel proportional to the noise
///    estimate E";
/// 4. the joint-bilateral filter of S_N and U_N with that σ ([`joint_bilateral`]), then
///    U × denoise[S_N] / denoise[U_N] per channel ([`ratio_combine`], Eq. 25, 27).
///
/// Returns the final image and the intermediate images.
pub fn ratio_denoised(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    settings: &DenoiseSettings,
) -> (Image, DenoiseAovs) {
    check_image(u, g, "U");
    let w_n = weighted_shadow(s_n, u_n, g);
    let noise = noise_estimate(&w_n, g, settings);
    let sigma: Vec<f64> = noise
        .iter()
        .map(|&e| applied_sigma((settings.sigma_gain * e).min(settings.sigma_max), settings))
        .collect();
    finish(u, s_n, u_n, g, w_n, noise, sigma, settings)
}

/// The plain bilateral of paper 000's comparison (000 Sect. 5: S_N and U_N each denoised with a
/// bilateral filter, then combined): [`joint_bilateral`] with the same fixed `sigma_px` at
/// every valid pixel (no noise estimate), then U × denoise[S_N] / denoise[U_N] (Eq. 25).
/// `sigma_max` does not apply; the kernel radius is still capped at
/// [`super::MAX_KERNEL_RADIUS`].
pub fn ratio_bilateral(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    sigma_px: f64,
    settings: &DenoiseSettings,
) -> (Image, DenoiseAovs) {
    check_image(u, g, "U");
    let w_n = weighted_shadow(s_n, u_n, g);
    let sigma_px = applied_sigma(sigma_px, settings);
    let sigma: Vec<f64> = g
        .valid
        .iter()
        .map(|&v| if v { sigma_px } else { 0.0 })
        .collect();
    let noise = vec![0.0; g.len()];
    finish(u, s_n, u_n, g, w_n, noise, sigma, settings)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    w_n: Vec<f64>,
    noise: Vec<f64>,
    sigma: Vec<f64>,
    settings: &DenoiseSettings,
) -> (Image, DenoiseAovs) {
    let (s_denoised, u_denoised) = joint_bilateral(s_n, u_n, g, &sigma, settings);
    let out = ratio_combine(u, &s_denoised, &u_denoised);
    (
        out,
        DenoiseAovs {
            w_n,
            noise,
            sigma,
            s_denoised,
            u_denoised,
        },
    )
}

/// A scalar AOV as a gray image (the value in all three channels).
pub fn scalar_image(width: u32, height: u32, values: &[f64]) -> Image {
    assert_eq!(values.len(), width as usize * height as usize);
    Image {
        width,
        height,
        pixels: values.iter().map(|&v| DVec3::splat(v)).collect(),
    }
}
