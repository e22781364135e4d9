//! Shared helpers of the denoiser tests.

use super::GBuffer;
use crate::math::Pcg32;
use crate::raster::Image;
use crate::raster::gbuffer::Surface;
use glam::DVec3;

/// A standard normal deviate (Box–Muller).
pub(crate) fn normal(rng: &mut Pcg32) -> f64 {
    let u1 = 1.0 - rng.next_f64();
    let u2 = rng.next_f64();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// An image with pixel (x, y) = f(x, y).
pub(crate) fn image_from_fn(
    width: u32,
    height: u32,
    mut f: impl FnMut(u32, u32) -> DVec3,
) -> Image {
    let mut img = Image::new(width, height);
    for y in 0..height {
        for x in 0..width {
            img.pixels[(y * width + x) as usize] = f(x, y);
        }
    }
    img
}

/// A plane seen head-on: pixel (x, y) at `origin + f·(x, −y, 0)`, normal +z, footprint f.
pub(crate) fn plane_surface(x: u32, y: u32, origin: DVec3, f: f64) -> Surface {
    Surface {
        position: origin + f * DVec3::new(x as f64, -(y as f64), 0.0),
        normal: DVec3::Z,
        footprint: f,
    }
}

/// Mean and unbiased variance.
pub(crate) fn mean_var(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var)
}

/// The normalised 1-D kernel of [`super::joint_bilateral`] on a plane: exp(−k²/2σ²) for
/// |k| ≤ ⌈3σ⌉, divided by its sum (written here from the documented definition).
pub(crate) fn gaussian_kernel(sigma: f64) -> Vec<f64> {
    let r = (3.0 * sigma).ceil() as i64;
    let w: Vec<f64> = (-r..=r)
        .map(|k| (-(k * k) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|x| x / s).collect()
}

/// A flat, all-valid G-buffer.
pub(crate) fn flat(width: u32, height: u32) -> GBuffer {
    GBuffer::flat(width, height)
}
