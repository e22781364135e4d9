//! The ratio-denoised image of 003 (Eq. 23–27) and the two pipelines that produce it.

use super::joint_bilateral::joint_bilateral_cancellable;
use super::joint_bilateral::{check_image, sanitize};
use super::noise_estimate::noise_estimate_cancellable;
use super::{DenoiseSettings, GBuffer};
use crate::raster::Image;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

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
    /// `denoise[S_N]`.
    pub s_denoised: Image,
    /// `denoise[U_N]`.
    pub u_denoised: Image,
}

pub(crate) use crate::raster::luminance;

/// The illumination-weighted shadow W_N = S_N / U_N (Eq. 23) of one value: clamped to [0, 1]
/// (it lies there whenever 0 ≤ S_N ≤ U_N, both sums using the same weights), and 1 where U_N
/// is not positive (no sample saw the light: 0/0, which 003 Sect. 4.2 sets to 1). The one
/// definition, for the ratio estimators per channel (`stochastic::weighted_shadow`) and for
/// the image below.
#[inline]
pub(crate) fn weighted_shadow_value(s_n: f64, u_n: f64) -> f64 {
    if u_n > 0.0 {
        (s_n / u_n).clamp(0.0, 1.0)
    } else {
        1.0
    }
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
            // Halving (exact for normal values) keeps the weighted sums below f64::MAX.
            let s = luminance(sanitize(s_n.pixels[i]) * 0.5);
            let u = luminance(sanitize(u_n.pixels[i]) * 0.5);
            *w = weighted_shadow_value(s, u);
        }
    });
    w
}

/// Eq. 25 applied to U (003 Sect. 3.5): result = `U × denoise[S_N] / denoise[U_N]`, per channel.
///
/// Where `denoise[U_N]` = 0 in a channel (then `denoise[S_N]` = 0 too, as the filter keeps
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
/// 1. W_N from luminance ([`weighted_shadow`], Eq. 23), E from W_N
///    (`noise_estimate`, Eq. 29);
/// 2. E box-filtered 3×3 (inside `noise_estimate`);
/// 3. σ = min(`sigma_gain`·E, `sigma_max`) per pixel (0 below `sigma_min`: the pixel is copied);
///    003 Sect. 4.1: "the standard deviation of the Gaussian kernel proportional to the noise
///    estimate E";
/// 4. the joint-bilateral filter of S_N and U_N with that σ
///    (`joint_bilateral`), then
///    `U × denoise[S_N] / denoise[U_N]` per channel ([`ratio_combine`], Eq. 25, 27).
///
/// Returns the final image and the intermediate images.
pub fn ratio_denoised(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    settings: &DenoiseSettings,
) -> (Image, DenoiseAovs) {
    ratio_denoised_cancellable(u, s_n, u_n, g, settings, None)
}

/// [`ratio_denoised`] whose filter stops early once `cancel` is set (the result is then
/// incomplete and must be discarded).
pub fn ratio_denoised_cancellable(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    settings: &DenoiseSettings,
    cancel: Option<&AtomicBool>,
) -> (Image, DenoiseAovs) {
    check_image(u, g, "U");
    let w_n = weighted_shadow(s_n, u_n, g);
    let noise = noise_estimate_cancellable(&w_n, g, settings, cancel);
    let sigma: Vec<f64> = noise
        .iter()
        .map(|&e| applied_sigma((settings.sigma_gain * e).min(settings.sigma_max), settings))
        .collect();
    finish(u, s_n, u_n, g, w_n, noise, sigma, settings, cancel)
}

/// The plain bilateral of paper 000's comparison (000 Sect. 5: S_N and U_N each denoised with a
/// bilateral filter, then combined): `joint_bilateral` with the same
/// fixed `sigma_px` at every valid pixel (no noise estimate), then
/// `U × denoise[S_N] / denoise[U_N]` (Eq. 25). `sigma_max` does not apply; the kernel radius is
/// still capped at [`super::MAX_KERNEL_RADIUS`]; below `sigma_min` nothing is filtered.
pub fn ratio_bilateral(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    sigma_px: f64,
    settings: &DenoiseSettings,
) -> (Image, DenoiseAovs) {
    ratio_bilateral_cancellable(u, s_n, u_n, g, sigma_px, settings, None)
}

/// [`ratio_bilateral`] whose filter stops early once `cancel` is set.
pub fn ratio_bilateral_cancellable(
    u: &Image,
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    sigma_px: f64,
    settings: &DenoiseSettings,
    cancel: Option<&AtomicBool>,
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
    finish(u, s_n, u_n, g, w_n, noise, sigma, settings, cancel)
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
    cancel: Option<&AtomicBool>,
) -> (Image, DenoiseAovs) {
    let (s_denoised, u_denoised) =
        joint_bilateral_cancellable(s_n, u_n, g, &sigma, settings, cancel);
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

#[cfg(test)]
mod tests {
    use super::super::test_util::{flat, gaussian_kernel, image_from_fn, mean_var};
    use super::*;
    use crate::math::Pcg32;

    fn splat_image(w: u32, h: u32, c: DVec3) -> Image {
        image_from_fn(w, h, |_, _| c)
    }

    /// Test 1 (pipeline part): constant S_N and U_N give E = 0, σ = 0 and the result
    /// U × S_N/U_N exactly; with a fixed σ = 5 the ratio is still S_N/U_N to rounding, and a
    /// textured U comes out with its texture intact (only the shadow is filtered).
    #[test]
    fn constant_inputs_come_out_unchanged() {
        let settings = DenoiseSettings::default();
        let (w, h) = (40, 32);
        let g = flat(w, h);
        let (cs, cu) = (DVec3::new(0.1, 0.6, 0.3), DVec3::new(0.4, 0.8, 1.2));
        let (s_n, u_n) = (splat_image(w, h, cs), splat_image(w, h, cu));
        let u = image_from_fn(w, h, |x, y| {
            DVec3::new(1.0 + (x % 3) as f64, 2.0 + ((x + y) % 5) as f64, 0.5)
        });
        let (out, aovs) = ratio_denoised(&u, &s_n, &u_n, &g, &settings);
        assert!(aovs.noise.iter().chain(&aovs.sigma).all(|&v| v == 0.0));
        assert_eq!(aovs.s_denoised, s_n);
        assert_eq!(aovs.u_denoised, u_n);
        for i in 0..g.len() {
            assert_eq!(out.pixels[i], u.pixels[i] * (cs / cu));
        }
        let (out, aovs) = ratio_bilateral(&u, &s_n, &u_n, &g, 5.0, &settings);
        assert!(aovs.sigma.iter().all(|&v| v == 5.0));
        for i in 0..g.len() {
            let expected = u.pixels[i] * (cs / cu);
            assert!((out.pixels[i] - expected).abs().max_element() < 1e-14 * 3.0);
        }
    }

    /// Test 3: 003 Eq. 26 vs Eq. 27. Every pixel has the same true W and N = 4 samples of two
    /// kinds, each with probability 1/2: weight r = 1, visible with probability 0.9, or r = 10,
    /// visible with probability 0.1, so W = E[rV]/E[r] = 0.95/5.5 (Eq. 14), while W_N = S_N/U_N
    /// averages to ≈ 0.23: the per-pixel ratio is biased, and so is any denoising of it.
    /// `denoise[S_N]`/`denoise[U_N]` is a ratio estimator over n_eff = N/Σw² samples (Σw² of the
    /// 2-D kernel): its mean over pixels 2⌈3σ⌉+1 apart (independent) must be within
    /// 4.5 standard errors plus its second-order bias (W Var r − Cov(rV, r))/(n_eff E[r]²),
    /// both from the sample statistics; denoising W_N directly must miss by far more.
    #[test]
    fn denoise_before_divide_is_consistent() {
        let settings = DenoiseSettings::default();
        let (w, h) = (256u32, 256u32);
        let g = flat(w, h);
        let n = 4;
        let true_w = (0.5 * 1.0 * 0.9 + 0.5 * 10.0 * 0.1) / (0.5 * 1.0 + 0.5 * 10.0);
        let mut rng = Pcg32::new(21, 3);
        let (mut s_n, mut u_n) = (Image::new(w, h), Image::new(w, h));
        // Sums of r, r², rV, r²V over every sample.
        let mut m = [0.0; 4];
        for i in 0..g.len() {
            let (mut s, mut u) = (0.0, 0.0);
            for _ in 0..n {
                let (r, p) = if rng.next_u32() & 1 == 1 {
                    (10.0, 0.1)
                } else {
                    (1.0, 0.9)
                };
                let v = if rng.next_f64() < p { 1.0 } else { 0.0 };
                u += r;
                s += r * v;
                for (k, x) in [r, r * r, r * v, r * r * v].into_iter().enumerate() {
                    m[k] += x;
                }
            }
            s_n.pixels[i] = DVec3::splat(s);
            u_n.pixels[i] = DVec3::splat(u);
        }
        let count = (g.len() * n) as f64;
        let [mean_r, mean_r2, _, mean_r2v] = m.map(|x| x / count);
        let mean_rv = m[2] / count;
        let var_r = mean_r2 - mean_r * mean_r;
        let cov = mean_r2v - mean_rv * mean_r;

        let sigma_px = 4.0;
        let ones = splat_image(w, h, DVec3::ONE);
        let (ratio_img, aovs) = ratio_bilateral(&ones, &s_n, &u_n, &g, sigma_px, &settings);
        let w_img = scalar_image(w, h, &aovs.w_n);
        let sigma = vec![sigma_px; g.len()];
        let (direct, _) = crate::denoise::joint_bilateral(&w_img, &ones, &g, &sigma, &settings);

        let r = (3.0 * sigma_px).ceil() as u32;
        let step = 2 * r + 1;
        let (mut ratio_vals, mut direct_vals) = (Vec::new(), Vec::new());
        for y in (r..h - r).step_by(step as usize) {
            for x in (r..w - r).step_by(step as usize) {
                ratio_vals.push(ratio_img.at(x, y).x);
                direct_vals.push(direct.at(x, y).x);
            }
        }
        let (m_ratio, var_ratio) = mean_var(&ratio_vals);
        let (m_direct, _) = mean_var(&direct_vals);
        let se = (var_ratio / ratio_vals.len() as f64).sqrt();
        let sum_w2 = gaussian_kernel(sigma_px)
            .iter()
            .map(|k| k * k)
            .sum::<f64>()
            .powi(2);
        let n_eff = n as f64 / sum_w2;
        let bias = (true_w * var_r - cov) / (n_eff * mean_r * mean_r);
        let tol = 4.5 * se + bias.abs();
        let ratio_err = (m_ratio - true_w).abs();
        let direct_err = (m_direct - true_w).abs();
        assert!(
            ratio_err < tol,
            "ratio: mean {m_ratio} vs W {true_w} (tol {tol}, se {se}, bias {bias})"
        );
        assert!(
            direct_err > 5.0 * tol,
            "denoising W_N: mean {m_direct}, W {true_w}, tol {tol}"
        );

        // The full pipeline (σ from E) is just as consistent: a sanity check on all pixels.
        let (full, _) = ratio_denoised(&ones, &s_n, &u_n, &g, &settings);
        let all: Vec<f64> = full.pixels.iter().map(|p| p.x).collect();
        let (m_full, _) = mean_var(&all);
        assert!((m_full - true_w).abs() < direct_err / 2.0, "full: {m_full}");
    }

    /// Test 6 (pipeline part): S_N = U_N = 0 everywhere (Eq. 28's 0/0) gives W = 1 and the
    /// result U; adding invalid pixels with NaN G-buffer data, non-finite U, S_N, U_N and a
    /// zero-size image changes nothing: every output and AOV is finite.
    #[test]
    fn zero_and_invalid_inputs_give_finite_output() {
        let settings = DenoiseSettings::default();
        let (w, h) = (31u32, 19u32);
        let zero = Image::new(w, h);
        let u = image_from_fn(w, h, |x, y| DVec3::new(x as f64, y as f64, 1.0));
        let mut g = GBuffer::from_fn(w, h, |x, y| {
            ((x + y) % 4 != 0).then(|| super::super::test_util::plane_surface(x, y, DVec3::Z, 0.1))
        });
        for i in 0..g.len() {
            if !g.valid[i] {
                g.position[i] = DVec3::NAN;
                g.normal[i] = DVec3::NAN;
                g.footprint[i] = f64::NAN;
            }
        }
        for gb in [flat(w, h), g.clone()] {
            let (out, aovs) = ratio_denoised(&u, &zero, &zero, &gb, &settings);
            assert_eq!(out, u);
            assert!(aovs.w_n.iter().all(|&v| v == 1.0));
            let (out, _) = ratio_bilateral(&u, &zero, &zero, &gb, 6.0, &settings);
            assert_eq!(out, u);
        }
        let mut rng = Pcg32::new(1, 1);
        let specials = [0.0, f64::NAN, f64::INFINITY, -3.0, f64::MAX, 1e-310, 0.5];
        let mut pick = || {
            let mut c = || specials[rng.below(specials.len() as u32) as usize];
            DVec3::new(c(), c(), c())
        };
        let u_bad = image_from_fn(w, h, |_, _| pick());
        let s_bad = image_from_fn(w, h, |_, _| pick());
        let un_bad = image_from_fn(w, h, |_, _| pick());
        for (out, aovs) in [
            ratio_denoised(&u_bad, &s_bad, &un_bad, &g, &settings),
            ratio_bilateral(&u_bad, &s_bad, &un_bad, &g, 3.0, &settings),
        ] {
            assert_eq!(out.invalid_counts(), (0, 0, 0));
            assert_eq!(aovs.s_denoised.invalid_counts(), (0, 0, 0));
            assert_eq!(aovs.u_denoised.invalid_counts(), (0, 0, 0));
            for v in aovs.w_n.iter().chain(&aovs.noise).chain(&aovs.sigma) {
                assert!(v.is_finite() && *v >= 0.0);
            }
        }
        let empty = Image::new(0, 0);
        let (out, _) = ratio_denoised(&empty, &empty, &empty, &flat(0, 0), &settings);
        assert!(out.pixels.is_empty());
    }

    /// A noisy penumbra between an umbra and a lit region: the output is bit-identical with 1
    /// and 3 threads, the lit region (S_N = U_N, so W_N = 1 and E = 0) is copied and equals
    /// the textured U exactly, the umbra is exactly 0, and in the penumbra the error against the
    /// true W is much smaller than that of W_N.
    #[test]
    fn penumbra_is_denoised_deterministically_and_lit_region_is_untouched() {
        let settings = DenoiseSettings::default();
        let (w, h) = (160u32, 64u32);
        let g = flat(w, h);
        let true_w = |x: u32| ((x as f64 - 50.0) / 60.0).clamp(0.0, 1.0);
        let mut rng = Pcg32::new(77, 0);
        let (mut s_n, mut u_n) = (Image::new(w, h), Image::new(w, h));
        for y in 0..h {
            for x in 0..w {
                let (mut s, mut u) = (DVec3::ZERO, DVec3::ZERO);
                for _ in 0..4 {
                    let r = DVec3::new(rng.range(0.5, 1.5), rng.range(0.5, 1.5), 1.0);
                    u += r;
                    if rng.next_f64() < true_w(x) {
                        s += r;
                    }
                }
                s_n.pixels[(y * w + x) as usize] = s;
                u_n.pixels[(y * w + x) as usize] = u;
            }
        }
        let u = image_from_fn(w, h, |x, y| {
            DVec3::new(0.5 + ((x / 3 + y / 3) % 2) as f64, 1.0, 0.25)
        });
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ratio_denoised(&u, &s_n, &u_n, &g, &settings))
        };
        let (out, aovs) = run(1);
        let (out3, aovs3) = run(3);
        let bits = |img: &Image| -> Vec<u64> {
            img.pixels
                .iter()
                .flat_map(|p| p.to_array().map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&out), bits(&out3));
        assert_eq!(bits(&aovs.s_denoised), bits(&aovs3.s_denoised));
        let b = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(b(&aovs.noise), b(&aovs3.noise));

        // Farther than a line plus the box filter from the penumbra: untouched.
        let margin = settings.line_half_length + settings.line_half_length / 2 + 2;
        let (mut err_out, mut err_raw, mut n) = (0.0, 0.0, 0.0);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if x + margin < 50 {
                    assert_eq!(aovs.sigma[i], 0.0);
                    assert_eq!(out.pixels[i], DVec3::ZERO);
                } else if x > 110 + margin {
                    assert_eq!(aovs.sigma[i], 0.0);
                    assert_eq!(out.pixels[i], u.pixels[i]);
                } else if (60..100).contains(&x) && (10..h - 10).contains(&y) {
                    let wt = true_w(x);
                    err_out += ((out.pixels[i] / u.pixels[i]).y - wt).powi(2);
                    err_raw += (aovs.w_n[i] - wt).powi(2);
                    n += 1.0;
                }
            }
        }
        let (rms_out, rms_raw) = ((err_out / n).sqrt(), (err_raw / n).sqrt());
        assert!(rms_out < rms_raw / 3.0, "rms {rms_out} vs noisy {rms_raw}");
    }
}
