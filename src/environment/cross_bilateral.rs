//! The 5×5 cross-bilateral filter of 002 Sect. 4 (third pass): E_occluded is blurred with
//! weights from the G-buffer only, so that the noise-free E_static is never blurred and the
//! shadow does not bleed across creases and depth discontinuities.
//!
//! w(t) = exp(−k²/(2σ²)) · exp(−½ (|n_c·(p_t − p_c)| / (τ_p f_c))²) · exp(−(1 − n_c·n_t)/τ_n²)
//!
//! with k the pixel offset, σ = 1.5 pixels (a 5×5 kernel holds ±1.33σ), p, n, f the G-buffer
//! position, normal and footprint (world size of a pixel), τ_p = 1.5 footprints and τ_n = 0.3:
//! the same geometric terms as the ratio denoiser's joint-bilateral filter (docs/denoiser.md).

use crate::raster::Image;
use crate::raster::gbuffer::GBuffer;
use glam::DVec3;
use rayon::prelude::*;

const RADIUS: i32 = 2;
const SIGMA: f64 = 1.5;
const PLANE_TOLERANCE: f64 = 1.5;
const NORMAL_TOLERANCE: f64 = 0.3;

/// Filters `img` (one value per pixel of `g`); invalid pixels are copied and never used as
/// taps. Deterministic: the same input gives the same bits whatever the thread count.
pub fn cross_bilateral_5x5(img: &Image, g: &GBuffer) -> Image {
    assert_eq!(img.pixels.len(), g.len(), "image and G-buffer sizes differ");
    let (w, h) = (g.width as i32, g.height as i32);
    let pixels = (0..g.len())
        .into_par_iter()
        .map(|i| {
            if !g.valid[i] {
                return img.pixels[i];
            }
            let (cx, cy) = ((i as i32) % w, (i as i32) / w);
            let (pc, nc, fc) = (g.position[i], g.normal[i], g.footprint[i].max(1e-300));
            let mut sum = DVec3::ZERO;
            let mut weight = 0.0;
            for dy in -RADIUS..=RADIUS {
                for dx in -RADIUS..=RADIUS {
                    let (x, y) = (cx + dx, cy + dy);
                    if x < 0 || y < 0 || x >= w || y >= h {
                        continue;
                    }
                    let t = (y * w + x) as usize;
                    if !g.valid[t] {
                        continue;
                    }
                    let k2 = (dx * dx + dy * dy) as f64;
                    let plane = nc.dot(g.position[t] - pc).abs() / (PLANE_TOLERANCE * fc);
                    let normal = (1.0 - nc.dot(g.normal[t])).max(0.0);
                    let wt = (-k2 / (2.0 * SIGMA * SIGMA)
                        - 0.5 * plane * plane
                        - normal / (NORMAL_TOLERANCE * NORMAL_TOLERANCE))
                        .exp();
                    sum += img.pixels[t] * wt;
                    weight += wt;
                }
            }
            // The centre has weight 1, so `weight` ≥ 1.
            sum / weight
        })
        .collect();
    Image {
        width: img.width,
        height: img.height,
        pixels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::gbuffer::Surface;

    #[test]
    fn keeps_constants_and_does_not_cross_a_crease() {
        // A floor (left half) meeting a wall (right half) at a right angle.
        let (w, h) = (12u32, 8u32);
        let g = GBuffer::from_fn(w, h, |x, y| {
            Some(if x < 6 {
                Surface {
                    position: DVec3::new(x as f64, 0.0, y as f64),
                    normal: DVec3::Y,
                    footprint: 1.0,
                }
            } else {
                Surface {
                    position: DVec3::new(6.0, (x - 6) as f64, y as f64),
                    normal: -DVec3::X,
                    footprint: 1.0,
                }
            })
        });
        let img = Image {
            width: w,
            height: h,
            pixels: (0..w * h)
                .map(|i| if i % w < 6 { DVec3::ONE } else { DVec3::ZERO })
                .collect(),
        };
        let out = cross_bilateral_5x5(&img, &g);
        for (i, p) in out.pixels.iter().enumerate() {
            let expect = img.pixels[i].x;
            // Normal weight across the crease: exp(−1/0.09) ≈ 1.5e-5 per tap.
            assert!(
                (p.x - expect).abs() < 1e-3,
                "pixel {i}: {} vs {expect}",
                p.x
            );
        }
    }
}
