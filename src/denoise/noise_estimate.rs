//! The noise estimate E of 003 Sect. 4.2 (Eq. 29): total variation of the second derivative of
//! the weighted shadow W_N along four lines through each pixel, then a 3×3 box filter.

use super::{DenoiseSettings, GBuffer};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Directions (dx, dy) of the n = 4 lines of the asterisk: 0°, 45°, 90° and 135°.
const DIRECTIONS: [(i64, i64); 4] = [(1, 0), (1, -1), (0, 1), (1, 1)];

/// Eq. 29 followed by the 3×3 box filter of 003 Sect. 4.1 (passes 1 and 2): the noise estimate
/// E of every pixel from the weighted-shadow image `w` (row-major, `g.width × g.height`).
///
/// See [`line_total_variation`] for Eq. 29 and [`box_filter_3x3`] for the box filter.
/// Invalid pixels get E = 0. The result is finite for any input and bit-identical whatever the
/// number of threads.
///
/// Panics if `w.len()` is not the number of pixels of `g`.
pub fn noise_estimate(w: &[f64], g: &GBuffer, settings: &DenoiseSettings) -> Vec<f64> {
    noise_estimate_cancellable(w, g, settings, None)
}

/// [`noise_estimate`](fn@noise_estimate) that stops early once `cancel` is set (checked at the
/// start of every row; the result is then incomplete and must be discarded).
pub(crate) fn noise_estimate_cancellable(
    w: &[f64],
    g: &GBuffer,
    settings: &DenoiseSettings,
    cancel: Option<&AtomicBool>,
) -> Vec<f64> {
    let raw = line_total_variation_cancellable(w, g, settings, cancel);
    box_filter_3x3(&raw, g)
}

/// Eq. 29 without the box filter:
///
/// `E[x] = (1/n) Σᵢ ∫_{ℓᵢ} |d²W_N(ℓᵢ(t))/dt²| dt`,
///
/// over n = 4 lines ℓᵢ through x at 0°, 45°, 90° and 135°. Each line has 2L+1 taps
/// (L = `settings.line_half_length`) at integer pixel positions, t counting taps (one step along
/// a diagonal is one tap, as along an axis), so the integral is the sum of the absolute second
/// differences `|W[t−1] − 2W[t] + W[t+1]|` over the 2L−1 interior taps. The line contains x but is
/// shifted along itself by a deterministic per-pixel random offset in [−⌊L/2⌋, ⌊L/2⌋] taps (a
/// hash of `settings.seed`, the pixel and the line), so that the lines of neighbouring pixels
/// differ; near the image border the line is slid inward instead of being cut, so border pixels
/// see full lines. A second difference touching an invalid pixel (or a non-finite W) is left out
/// (the line's integral covers its valid part only, which never inflates E), and the average is
/// over the lines with at least one second difference (E = 0 if none).
///
/// A constant or linear W gives E = 0; a straight step edge of height h crosses a line at most
/// once and adds at most 2h to its integral, so E ≤ 2h (≤ (3/4)·2h for an axis-aligned or
/// diagonal edge, which the line parallel to it does not cross), whereas noise adds to every
/// tap: an iid W of standard deviation s gives E ≈ (2L−1)·√(12/π)·s (Gaussian) and, on
/// average, exactly 2L−1 for fair 0/1 coin flips.
pub fn line_total_variation(w: &[f64], g: &GBuffer, settings: &DenoiseSettings) -> Vec<f64> {
    line_total_variation_cancellable(w, g, settings, None)
}

fn line_total_variation_cancellable(
    w: &[f64],
    g: &GBuffer,
    settings: &DenoiseSettings,
    cancel: Option<&AtomicBool>,
) -> Vec<f64> {
    g.check();
    assert_eq!(w.len(), g.len(), "W must have one value per G-buffer pixel");
    let mut out = vec![0.0; g.len()];
    if g.is_empty() {
        return out;
    }
    let (width, height) = (g.width as i64, g.height as i64);
    let l = settings.line_half_length.max(1) as i64;
    let span = 2 * l;
    let jitter = l / 2;
    out.par_chunks_mut(g.width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return;
            }
            let y = y as i64;
            for (x, e) in row.iter_mut().enumerate() {
                let x = x as i64;
                if !g.valid[(y * width + x) as usize] {
                    continue;
                }
                let mut total = 0.0;
                let mut lines = 0u32;
                for (i, &(dx, dy)) in DIRECTIONS.iter().enumerate() {
                    // Parameters t for which (x + t dx, y + t dy) lies in the image.
                    let (ax, bx) = axis_range(x, width, dx);
                    let (ay, by) = axis_range(y, height, dy);
                    let (tmin, tmax) = (ax.max(ay), bx.min(by));
                    let offset = (pixel_hash(settings.seed, x, y, i as u64)
                        % (2 * jitter as u64 + 1)) as i64
                        - jitter;
                    let (t0, t1) = if tmax - tmin <= span {
                        (tmin, tmax)
                    } else {
                        let t0 = (offset - l).clamp(tmin, tmax - span);
                        (t0, t0 + span)
                    };
                    let index = |t: i64| ((y + t * dy) * width + x + t * dx) as usize;
                    let mut sum = 0.0;
                    let mut count = 0u32;
                    for t in t0 + 1..t1 {
                        let (a, b, c) = (index(t - 1), index(t), index(t + 1));
                        if !(g.valid[a] && g.valid[b] && g.valid[c]) {
                            continue;
                        }
                        let d2 = (w[a] - 2.0 * w[b] + w[c]).abs();
                        if d2.is_finite() {
                            sum += d2;
                            count += 1;
                        }
                    }
                    if count > 0 {
                        total += sum;
                        lines += 1;
                    }
                }
                if lines > 0 {
                    *e = total / lines as f64;
                }
            }
        });
    out
}

/// 003 Sect. 4.1 pass 2: E denoised by a 3×3 box filter, the mean over the valid pixels of the
/// 3×3 neighbourhood (clipped at the image border). Invalid pixels get 0.
pub fn box_filter_3x3(e: &[f64], g: &GBuffer) -> Vec<f64> {
    g.check();
    assert_eq!(e.len(), g.len(), "E must have one value per G-buffer pixel");
    let mut out = vec![0.0; g.len()];
    if g.is_empty() {
        return out;
    }
    let (width, height) = (g.width as usize, g.height as usize);
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            if !g.valid[y * width + x] {
                continue;
            }
            let mut sum = 0.0;
            let mut count = 0u32;
            for ny in y.saturating_sub(1)..(y + 2).min(height) {
                for nx in x.saturating_sub(1)..(x + 2).min(width) {
                    let i = ny * width + nx;
                    if g.valid[i] {
                        sum += e[i];
                        count += 1;
                    }
                }
            }
            *o = sum / count as f64;
        }
    });
    out
}

/// The t for which c + t·d lies in [0, n): all of them (as far as any line goes) when d = 0.
fn axis_range(c: i64, n: i64, d: i64) -> (i64, i64) {
    match d {
        0 => (i64::MIN / 4, i64::MAX / 4),
        1 => (-c, n - 1 - c),
        _ => (c - (n - 1), c),
    }
}

/// A deterministic 64-bit hash of (seed, pixel, line): the SplitMix64 finaliser applied twice.
fn pixel_hash(seed: u64, x: i64, y: i64, line: u64) -> u64 {
    let key = (x as u64 & 0xFFFF_FFFF) | ((y as u64) << 32);
    mix64(seed ^ mix64(key.wrapping_add(line.wrapping_mul(0x9E37_79B9_7F4A_7C15))))
}

fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{flat, mean_var, plane_surface};
    use super::*;
    use crate::denoise::GBuffer;
    use crate::math::Pcg32;
    use glam::DVec3;

    fn w_from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> f64) -> Vec<f64> {
        (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect()
    }

    /// Test 1 (E part): the second derivative of a constant or linear W is 0, so E is 0 at every
    /// pixel, border included (the values are dyadic, so every difference is exact). A
    /// quadratic W = a x² has the second difference 2a along the three lines that are not
    /// vertical, so E = (3/4)(2L−1)·2a in the interior: the same code must see it.
    #[test]
    fn e_is_zero_on_constant_and_linear_w_and_exact_on_quadratic() {
        let s = DenoiseSettings::default();
        let (w, h) = (40, 30);
        let g = flat(w, h);
        for field in [
            w_from_fn(w, h, |_, _| 0.375),
            w_from_fn(w, h, |x, y| (x as f64 + 3.0 * y as f64) / 256.0),
            w_from_fn(w, h, |x, y| (200.0 - 2.0 * x as f64 + y as f64) / 512.0),
        ] {
            let raw = line_total_variation(&field, &g, &s);
            let e = noise_estimate(&field, &g, &s);
            assert!(raw.iter().chain(&e).all(|&v| v == 0.0));
        }
        let a = 1.0 / 1024.0;
        let quad = w_from_fn(w, h, |x, _| a * (x as f64) * (x as f64));
        let raw = line_total_variation(&quad, &g, &s);
        let expected = 0.75 * (2 * s.line_half_length - 1) as f64 * 2.0 * a;
        let l = s.line_half_length;
        for y in l..h - l {
            for x in l..w - l {
                let v = raw[(y * w + x) as usize];
                assert!(
                    (v - expected).abs() <= 1e-12,
                    "({x},{y}): {v} vs {expected}"
                );
            }
        }
    }

    /// Test 2: 003 Sect. 4.2's ordering argument. A random comb (fair 0/1 coin per pixel) and a
    /// step edge have the same variance 1/4, but for the comb every second difference
    /// |a − 2b + c| is 0, 1, 2 with probabilities 1/4, 1/2, 1/4 (mean 1), so E = 2L−1 on
    /// average, while a step of height 1 gives E ≤ (3/4)·2 everywhere.
    #[test]
    fn comb_gets_much_larger_e_than_step_of_same_variance() {
        let s = DenoiseSettings::default();
        let (w, h) = (256u32, 256u32);
        let g = flat(w, h);
        let mut rng = Pcg32::new(7, 1);
        let comb: Vec<f64> = (0..w * h).map(|_| (rng.next_u32() & 1) as f64).collect();
        let step = w_from_fn(w, h, |x, _| if x >= w / 2 { 1.0 } else { 0.0 });
        let (_, var_comb) = mean_var(&comb);
        let (_, var_step) = mean_var(&step);
        assert!((var_comb - 0.25).abs() < 0.01 && (var_step - 0.25).abs() < 0.01);

        let e_comb = noise_estimate(&comb, &g, &s);
        let e_step = noise_estimate(&step, &g, &s);
        let max_step = e_step.iter().cloned().fold(0.0, f64::max);
        assert!(max_step <= 1.5 + 1e-12, "step: E up to {max_step}");
        assert!(
            max_step >= 0.5,
            "the step edge must be seen at all: {max_step}"
        );

        // Pixels 20 apart see disjoint lines and box filters: independent samples of E.
        let samples: Vec<f64> = (0..w / 20)
            .flat_map(|j| (0..h / 20).map(move |i| (10 + 20 * i, 10 + 20 * j)))
            .map(|(x, y)| e_comb[(y * w + x) as usize])
            .collect();
        let (m, var) = mean_var(&samples);
        let expected = (2 * s.line_half_length - 1) as f64;
        let tol = 4.5 * (var / samples.len() as f64).sqrt();
        assert!(
            (m - expected).abs() < tol,
            "comb: mean E {m}, expected {expected} ± {tol}"
        );
        let min_comb = e_comb.iter().cloned().fold(f64::INFINITY, f64::min);
        assert!(
            min_comb > 2.0 * max_step,
            "comb min E {min_comb}, step max E {max_step}"
        );
    }

    /// 003 Sect. 4.2 / Fig. 10: noise shared by S_N and U_N (e.g. from sampling a highlight)
    /// cancels in W_N and is not counted as noise.
    #[test]
    fn noise_common_to_s_and_u_is_not_noise() {
        let s = DenoiseSettings::default();
        let (w, h) = (48, 40);
        let g = flat(w, h);
        let mut rng = Pcg32::new(3, 9);
        let u_n = crate::denoise::test_util::image_from_fn(w, h, |_, _| {
            DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 10.0
        });
        let mut s_n = u_n.clone();
        for p in &mut s_n.pixels {
            *p *= 0.5;
        }
        let wn = crate::denoise::weighted_shadow(&s_n, &u_n, &g);
        assert!(wn.iter().all(|&v| v == 0.5));
        assert!(noise_estimate(&wn, &g, &s).iter().all(|&v| v == 0.0));
        // Whereas the same noise in S_N alone is seen.
        let ones = crate::denoise::test_util::image_from_fn(w, h, |_, _| DVec3::splat(10.0));
        let wn = crate::denoise::weighted_shadow(&s_n, &ones, &g);
        let e = noise_estimate(&wn, &g, &s);
        assert!(e.iter().sum::<f64>() / e.len() as f64 > 1.0);
    }

    /// Invalid pixels are never mixed in: whatever W holds there (NaN, huge), E at the valid
    /// pixels is the same, finite, and E is 0 on the invalid ones.
    #[test]
    fn invalid_pixels_do_not_affect_e() {
        let s = DenoiseSettings::default();
        let (w, h) = (50u32, 36u32);
        let hole = |x: u32, y: u32| (15..30).contains(&x) && (10..22).contains(&y) || y == 0;
        let g = GBuffer::from_fn(w, h, |x, y| {
            (!hole(x, y)).then(|| plane_surface(x, y, DVec3::ZERO, 0.01))
        });
        let mut rng = Pcg32::new(11, 2);
        let base: Vec<f64> = (0..w * h).map(|_| rng.next_f64()).collect();
        let e0 = noise_estimate(&base, &g, &s);
        for junk in [f64::NAN, 1e300, -5.0, f64::INFINITY] {
            let mut field = base.clone();
            for y in 0..h {
                for x in 0..w {
                    if hole(x, y) {
                        field[(y * w + x) as usize] = junk;
                    }
                }
            }
            let e = noise_estimate(&field, &g, &s);
            assert_eq!(e, e0);
        }
        assert!(e0.iter().all(|v| v.is_finite()));
        for (i, v) in e0.iter().enumerate() {
            if !g.valid[i] {
                assert_eq!(*v, 0.0);
            }
        }
    }
}
