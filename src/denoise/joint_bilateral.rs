//! The separable joint-bilateral filter of 003 Sect. 4.1 (passes 3 and 4): S_N and U_N filtered
//! together with the same weights, a Gaussian whose standard deviation varies per pixel, and
//! plane-distance and normal weights from the G-buffer.

use super::{DenoiseSettings, GBuffer};
use crate::raster::Image;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Largest kernel radius in pixels: the radius is min(⌈3σ⌉, this).
pub const MAX_KERNEL_RADIUS: u32 = 64;

/// Separable joint-bilateral filter of S_N and U_N (003 Sect. 4.1, passes 3–4): a horizontal
/// pass then a vertical pass over both images at once. In each pass the output at the centre
/// pixel c is
///
/// `out[c] = Σₜ wₜ in[t] / Σₜ wₜ`,   t = c + k·(1, 0) (horizontal) or c + k·(0, 1) (vertical),
/// |k| ≤ r = min(⌈3σ_c⌉, [`MAX_KERNEL_RADIUS`]),
///
/// wₜ = exp(−k²/(2σ_c²)) · exp(−½ (|n_c·(p_t − p_c)| / (τ_p·f_c))²) · exp(−(1 − n_c·n_t)/τ_n²),
///
/// with σ_c = `sigma[c]` in pixels, p, n, f the G-buffer position, normal and footprint,
/// τ_p = `settings.plane_tolerance` (in footprints) and τ_n = `settings.normal_tolerance`
/// (≈ radians: 1 − cos θ ≈ θ²/2). The weights depend on the centre and the tap only, never on
/// the image values, so S_N and U_N see the same weights and 0 ≤ S_N ≤ U_N is preserved.
/// Invalid taps are skipped; the centre always has weight 1, so the sum of the weights is ≥ 1.
///
/// A pixel that is invalid, or whose σ is below `settings.sigma_min` (or NaN), is copied
/// unchanged by both passes: outside penumbrae the filter costs nothing.
///
/// Inputs are sanitised first: a NaN, infinite or negative channel reads as 0. Images whose
/// largest value is above 2⁵⁰⁰ (or, if positive, below 2⁻⁵⁰⁰) are filtered after an exact
/// scaling by a power of two, so sums cannot overflow; outputs are finite for any input.
///
/// Panics if the images, the G-buffer and `sigma` do not all have the same number of pixels.
pub fn joint_bilateral(
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    sigma: &[f64],
    settings: &DenoiseSettings,
) -> (Image, Image) {
    joint_bilateral_cancellable(s_n, u_n, g, sigma, settings, None)
}

/// [`joint_bilateral`] that stops early (leaving rows unfiltered, the result to be discarded)
/// once `cancel` is set: checked at the start of every row of both passes.
pub fn joint_bilateral_cancellable(
    s_n: &Image,
    u_n: &Image,
    g: &GBuffer,
    sigma: &[f64],
    settings: &DenoiseSettings,
    cancel: Option<&AtomicBool>,
) -> (Image, Image) {
    g.check();
    check_image(s_n, g, "S_N");
    check_image(u_n, g, "U_N");
    assert_eq!(sigma.len(), g.len(), "sigma must have one value per pixel");

    let scale = power_of_two_scale(
        s_n.pixels
            .iter()
            .chain(&u_n.pixels)
            .map(|&p| sanitize(p).max_element())
            .fold(0.0, f64::max),
    );
    let scaled =
        |img: &Image| -> Vec<DVec3> { img.pixels.iter().map(|&p| sanitize(p) * scale).collect() };
    let (s0, u0) = (scaled(s_n), scaled(u_n));

    let params = Params::new(settings);
    let mut s1 = vec![DVec3::ZERO; g.len()];
    let mut u1 = vec![DVec3::ZERO; g.len()];
    pass(
        &s0,
        &u0,
        g,
        sigma,
        &params,
        Axis::Horizontal,
        &mut s1,
        &mut u1,
        cancel,
    );
    let (mut s2, mut u2) = (s0, u0);
    pass(
        &s1,
        &u1,
        g,
        sigma,
        &params,
        Axis::Vertical,
        &mut s2,
        &mut u2,
        cancel,
    );

    let unscale = 1.0 / scale;
    let image = |pixels: Vec<DVec3>| Image {
        width: g.width,
        height: g.height,
        pixels: pixels
            .into_iter()
            .map(|p| (p * unscale).min(DVec3::splat(f64::MAX)))
            .collect(),
    };
    (image(s2), image(u2))
}

/// A channel that is NaN, infinite or negative reads as 0.
#[inline]
pub(crate) fn sanitize(p: DVec3) -> DVec3 {
    let f = |v: f64| if v.is_finite() && v > 0.0 { v } else { 0.0 };
    DVec3::new(f(p.x), f(p.y), f(p.z))
}

pub(crate) fn check_image(img: &Image, g: &GBuffer, name: &str) {
    assert!(
        img.width == g.width && img.height == g.height && img.pixels.len() == g.len(),
        "{name} is {}x{} ({} pixels), the G-buffer {}x{}",
        img.width,
        img.height,
        img.pixels.len(),
        g.width,
        g.height
    );
}

/// 1, or the power of two that brings `max` to [1/2, 1) when it is outside [2⁻⁵⁰⁰, 2⁵⁰⁰]
/// (to within 2²⁴ for subnormal or near-overflow maxima, where the exponent is clamped to ±1000).
fn power_of_two_scale(max: f64) -> f64 {
    const LIMIT: i32 = 500;
    let biased = ((max.to_bits() >> 52) & 0x7FF) as i32;
    // For a normal max = m·2^e with m in [1/2, 1), e = biased − 1022.
    let e = biased - 1022;
    if max > 0.0 && !(-LIMIT..=LIMIT).contains(&e) {
        let k = (-e).clamp(-1000, 1000);
        f64::from_bits(((1023 + k) as u64) << 52)
    } else {
        1.0
    }
}

/// Whether a pixel with this σ is filtered (false for NaN: copied).
#[inline]
fn is_filtered(sigma: f64, sigma_min: f64) -> bool {
    sigma >= sigma_min && sigma > 0.0
}

/// Per-call constants of the weights.
struct Params {
    sigma_min: f64,
    inv_plane_tolerance: f64,
    inv_normal_tolerance2: f64,
}

impl Params {
    fn new(settings: &DenoiseSettings) -> Self {
        Params {
            sigma_min: settings.sigma_min.max(0.0),
            inv_plane_tolerance: 1.0 / settings.plane_tolerance,
            inv_normal_tolerance2: 1.0 / (settings.normal_tolerance * settings.normal_tolerance),
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Axis {
    Horizontal,
    Vertical,
}

/// One 1-D pass of the filter from (`src_s`, `src_u`) into (`dst_s`, `dst_u`), rows in parallel.
#[allow(clippy::too_many_arguments)]
fn pass(
    src_s: &[DVec3],
    src_u: &[DVec3],
    g: &GBuffer,
    sigma: &[f64],
    params: &Params,
    axis: Axis,
    dst_s: &mut [DVec3],
    dst_u: &mut [DVec3],
    cancel: Option<&AtomicBool>,
) {
    if g.is_empty() {
        return;
    }
    let (width, height) = (g.width as usize, g.height as usize);
    dst_s
        .par_chunks_mut(width)
        .zip(dst_u.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (row_s, row_u))| {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return;
            }
            for x in 0..width {
                let c = y * width + x;
                let sc = sigma[c];
                if !g.valid[c] || !is_filtered(sc, params.sigma_min) {
                    row_s[x] = src_s[c];
                    row_u[x] = src_u[c];
                    continue;
                }
                let radius = (3.0 * sc).ceil().min(MAX_KERNEL_RADIUS as f64) as usize;
                let inv_2s2 = 0.5 / (sc * sc);
                let (pc, nc) = (g.position[c], g.normal[c]);
                let inv_plane = {
                    let v = params.inv_plane_tolerance / g.footprint[c];
                    if v.is_finite() { v } else { f64::MAX }
                };
                let (lo, hi) = match axis {
                    Axis::Horizontal => (x.saturating_sub(radius), (x + radius).min(width - 1)),
                    Axis::Vertical => (y.saturating_sub(radius), (y + radius).min(height - 1)),
                };
                let (mut acc_s, mut acc_u, mut acc_w) = (src_s[c], src_u[c], 1.0);
                for j in lo..=hi {
                    let (t, k) = match axis {
                        Axis::Horizontal => (y * width + j, j as f64 - x as f64),
                        Axis::Vertical => (j * width + x, j as f64 - y as f64),
                    };
                    if t == c || !g.valid[t] {
                        continue;
                    }
                    let d = nc.dot(g.position[t] - pc) * inv_plane;
                    let bend = (1.0 - nc.dot(g.normal[t])).max(0.0);
                    let exponent =
                        k * k * inv_2s2 + 0.5 * d * d + bend * params.inv_normal_tolerance2;
                    let w = (-exponent).exp();
                    // Skips underflows and NaN (a NaN position or footprint).
                    if w.is_nan() || w <= 0.0 {
                        continue;
                    }
                    acc_s += w * src_s[t];
                    acc_u += w * src_u[t];
                    acc_w += w;
                }
                row_s[x] = acc_s / acc_w;
                row_u[x] = acc_u / acc_w;
            }
        });
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{flat, gaussian_kernel, image_from_fn, normal, plane_surface};
    use super::*;
    use crate::math::Pcg32;
    use crate::raster::gbuffer::Surface;

    /// A gently curved, tilted surface (paraboloid) with a hole of invalid pixels.
    fn curved_gbuffer(w: u32, h: u32) -> GBuffer {
        GBuffer::from_fn(w, h, |x, y| {
            if (10..14).contains(&x) && (5..20).contains(&y) {
                return None;
            }
            let (u, v) = (x as f64 * 0.01, y as f64 * 0.01);
            let z = 0.3 * u + 0.2 * (u * u + v * v);
            let normal = DVec3::new(-(0.3 + 0.4 * u), -0.4 * v, 1.0).normalize();
            Some(Surface {
                position: DVec3::new(u, -v, z),
                normal,
                footprint: 0.01,
            })
        })
    }

    /// Test 1 (filter part): constant S_N and U_N come out unchanged whatever σ and the
    /// bilateral weights (every output is a normalised weighted mean of equal values); pixels
    /// with σ below `sigma_min`, σ = NaN or an invalid G-buffer entry are copied bit for bit.
    #[test]
    fn constant_images_pass_unchanged() {
        let settings = DenoiseSettings::default();
        let (w, h) = (37, 29);
        let g = curved_gbuffer(w, h);
        let (cs, cu) = (DVec3::new(0.3, 0.2, 0.1), DVec3::new(1.0, 0.5, 2.0));
        let s_n = image_from_fn(w, h, |_, _| cs);
        let u_n = image_from_fn(w, h, |_, _| cu);
        let mut rng = Pcg32::new(5, 5);
        let sigma: Vec<f64> = (0..w * h)
            .map(|i| match i % 7 {
                0 => 0.1,
                1 => f64::NAN,
                _ => rng.range(0.0, 12.0),
            })
            .collect();
        let (ds, du) = joint_bilateral(&s_n, &u_n, &g, &sigma, &settings);
        for (i, &sigma_i) in sigma.iter().enumerate() {
            for (out, c) in [(ds.pixels[i], cs), (du.pixels[i], cu)] {
                assert!(
                    (out - c).abs().max_element() <= 1e-14 * c.max_element(),
                    "pixel {i}: {out} vs {c}"
                );
            }
            if !g.valid[i] || !is_filtered(sigma_i, settings.sigma_min) {
                assert_eq!((ds.pixels[i], du.pixels[i]), (cs, cu));
            }
        }
    }

    /// Test 5: on a plane (all bilateral weights 1) and away from the border, each pass is the
    /// normalised 1-D kernel w_k ∝ exp(−k²/2σ²), |k| ≤ ⌈3σ⌉, so an output pixel is
    /// Σ_{k,l} w_k w_l x_{k,l} and iid noise of variance 1 leaves variance (Σ_k w_k²)². Measured
    /// on pixels 2⌈3σ⌉+1 apart (independent outputs, Gaussian since the input is), the sample
    /// variance over m of them has relative standard deviation √(2/m); tolerance 4.5 of those.
    #[test]
    fn variance_reduction_matches_kernel() {
        let settings = DenoiseSettings::default();
        let (w, h) = (256u32, 256u32);
        let g = flat(w, h);
        for sigma_px in [1.5, 3.0] {
            let kernel = gaussian_kernel(sigma_px);
            let expected = kernel.iter().map(|k| k * k).sum::<f64>().powi(2);
            let r = (3.0 * sigma_px).ceil() as u32;
            let step = 2 * r + 1;
            let sigma = vec![sigma_px; g.len()];
            let mut rng = Pcg32::new(99, sigma_px.to_bits());
            let (mut sum_sq, mut m) = ([0.0; 2], 0usize);
            for _ in 0..16 {
                let s_n = image_from_fn(w, h, |_, _| {
                    DVec3::new(normal(&mut rng), normal(&mut rng), 0.0) + DVec3::splat(100.0)
                });
                let u_n = image_from_fn(w, h, |_, _| DVec3::splat(200.0));
                let (ds, du) = joint_bilateral(&s_n, &u_n, &g, &sigma, &settings);
                let mut y = r;
                while y + r < h {
                    let mut x = r;
                    while x + r < w {
                        let p = ds.at(x, y) - DVec3::splat(100.0);
                        sum_sq[0] += p.x * p.x;
                        sum_sq[1] += p.y * p.y;
                        m += 1;
                        assert!((du.at(x, y) - DVec3::splat(200.0)).abs().max_element() < 1e-12);
                        x += step;
                    }
                    y += step;
                }
            }
            let tol = 4.5 * (2.0 / m as f64).sqrt();
            for s in sum_sq {
                let ratio = s / m as f64 / expected;
                assert!(
                    (ratio - 1.0).abs() < tol,
                    "sigma {sigma_px}: variance ratio {ratio} (expected 1 ± {tol}, m = {m}, \
                     expected variance {expected})"
                );
            }
            // The factor is far from 1, so the test can tell filtering from copying.
            assert!(expected < 0.1);
        }
    }

    /// Two surfaces side by side: the left half of the image on a plane facing the viewer, the
    /// right half either the same plane 50 footprints farther back (a depth step) or a plane
    /// folded 60° along the seam (a crease). S_N/U_N = 0.2 on the left and 0.8 on the right.
    fn two_sides(crease: bool, w: u32, h: u32) -> GBuffer {
        let f = 0.01;
        let seam = w / 2;
        GBuffer::from_fn(w, h, |x, y| {
            if x < seam {
                Some(plane_surface(x, y, DVec3::ZERO, f))
            } else if !crease {
                Some(plane_surface(x, y, DVec3::new(0.0, 0.0, -0.5), f))
            } else {
                let a = 60f64.to_radians();
                let k = (x - seam) as f64;
                Some(Surface {
                    position: f * DVec3::new(seam as f64 + k * a.cos(), -(y as f64), -k * a.sin()),
                    normal: DVec3::new(a.sin(), 0.0, a.cos()),
                    footprint: f,
                })
            }
        })
    }

    /// Test 4: no leaking across G-buffer discontinuities. (a) Piecewise-constant sides: every
    /// output pixel keeps its side's value (to 1e-3 of the contrast; the 60° crease lets through
    /// e^{−(1−cos 60°)/0.3²} ≈ 0.4 % of a tap's weight). (b) Noisy sides: each side's mean after
    /// filtering matches the side's mean computed directly. The difference is
    /// Σ_t (x_t − μ)(b_t − 1/n), b_t the share of input t in the side's output mean, whose
    /// variance is at most s² max_t b_t ≤ 4 s²/n (a pixel's share is at most 2× the uniform one
    /// per pass, at a border); tolerance 4.5 standard deviations. The same data filtered as if
    /// all were one plane moves the means by far more (the test can fail).
    #[test]
    fn no_leak_across_gbuffer_discontinuities() {
        let settings = DenoiseSettings::default();
        let (w, h) = (128u32, 96u32);
        let seam = w / 2;
        let sigma = vec![8.0; (w * h) as usize];
        let side_w = |x: u32| if x < seam { 0.2 } else { 0.8 };
        let u_n = image_from_fn(w, h, |_, _| DVec3::splat(1.0));
        let mut rng = Pcg32::new(4, 4);
        let half_width = 0.1;
        let noisy = image_from_fn(w, h, |x, _| {
            DVec3::splat(side_w(x) + half_width * (2.0 * rng.next_f64() - 1.0))
        });
        let constant = image_from_fn(w, h, |x, _| DVec3::splat(side_w(x)));
        let side_means = |img: &Image| {
            let mut sums = [0.0; 2];
            for y in 0..h {
                for x in 0..w {
                    sums[(x >= seam) as usize] += img.at(x, y).x;
                }
            }
            let n = (seam * h) as f64;
            [sums[0] / n, sums[1] / n]
        };
        let n = (seam * h) as f64;
        let tol = 4.5 * (4.0 * half_width * half_width / 3.0 / n).sqrt();
        let direct = side_means(&noisy);
        for crease in [false, true] {
            let g = two_sides(crease, w, h);
            let (ds, _) = joint_bilateral(&constant, &u_n, &g, &sigma, &settings);
            for y in 0..h {
                for x in 0..w {
                    let err = (ds.at(x, y).x - side_w(x)).abs();
                    assert!(err <= 1e-3 * 0.6, "crease {crease}: ({x},{y}) off by {err}");
                }
            }
            let (ds, _) = joint_bilateral(&noisy, &u_n, &g, &sigma, &settings);
            let filtered = side_means(&ds);
            for side in 0..2 {
                let err = (filtered[side] - direct[side]).abs();
                assert!(
                    err < tol,
                    "crease {crease}, side {side}: off by {err} (tol {tol})"
                );
            }
        }
        let (ds, _) = joint_bilateral(&noisy, &u_n, &flat(w, h), &sigma, &settings);
        let leaked = side_means(&ds);
        assert!((leaked[0] - direct[0]).abs() > 3.0 * tol);
        assert!((leaked[1] - direct[1]).abs() > 3.0 * tol);
    }

    /// Test 6 (filter part): NaN, infinite, negative, huge and subnormal inputs, σ = ∞, NaN or
    /// huge, NaN G-buffer entries on invalid pixels and a zero footprint: finite, non-negative
    /// output, and S ≤ U is kept.
    #[test]
    fn hostile_inputs_give_finite_output() {
        let settings = DenoiseSettings::default();
        let (w, h) = (23u32, 17u32);
        let mut g = curved_gbuffer(w, h);
        for i in 0..g.len() {
            if !g.valid[i] {
                g.position[i] = DVec3::NAN;
                g.normal[i] = DVec3::NAN;
                g.footprint[i] = f64::NAN;
            }
        }
        g.footprint[5] = 0.0;
        let specials = [
            0.0,
            -1.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            1e300,
            f64::MIN_POSITIVE / 1e10,
            1.0,
        ];
        let mut rng = Pcg32::new(8, 8);
        let mut pick = || specials[rng.below(specials.len() as u32) as usize];
        let s_n = image_from_fn(w, h, |_, _| DVec3::new(pick(), pick(), pick()));
        let u_n = image_from_fn(w, h, |x, y| {
            let s = super::sanitize(s_n.at(x, y));
            super::sanitize(DVec3::new(pick(), pick(), pick())).max(s)
        });
        let sigma: Vec<f64> = (0..g.len())
            .map(|i| [f64::INFINITY, f64::NAN, 1e12, 3.0, 0.0][i % 5])
            .collect();
        for (s_img, u_img) in [(&s_n, &u_n), (&Image::new(w, h), &Image::new(w, h))] {
            let (ds, du) = joint_bilateral(s_img, u_img, &g, &sigma, &settings);
            for (a, b) in ds.pixels.iter().zip(&du.pixels) {
                assert!(a.is_finite() && b.is_finite() && a.min_element() >= 0.0);
                assert!(
                    (*a - *b).max_element() <= 1e-12 * b.max_element(),
                    "S {a} > U {b}"
                );
            }
        }
        // A valid G-buffer entry with a NaN position never yields NaN either.
        let mut g = flat(w, h);
        g.position[40] = DVec3::NAN;
        let (ds, du) = joint_bilateral(&s_n, &u_n, &g, &vec![2.0; g.len()], &settings);
        assert!(ds.pixels.iter().chain(&du.pixels).all(|p| p.is_finite()));
    }

    #[test]
    fn power_of_two_scale_is_exact_and_bounded() {
        for max in [1.0, 3.5, 2f64.powi(499), f64::MIN_POSITIVE, 0.0] {
            if max >= 2f64.powi(-500) || max == 0.0 {
                assert_eq!(power_of_two_scale(max), 1.0);
            }
        }
        for max in [
            f64::MAX,
            1e300,
            2f64.powi(600),
            1e-200,
            5e-324,
            f64::MIN_POSITIVE,
        ] {
            let s = power_of_two_scale(max);
            assert!(s.is_finite() && s > 0.0 && s.to_bits() & ((1 << 52) - 1) == 0);
            let scaled = max * s;
            assert!(
                (2f64.powi(-80)..2f64.powi(25)).contains(&scaled),
                "{max} -> {scaled}"
            );
        }
    }
}
