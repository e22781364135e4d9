//! The G-buffer: per-pixel surface data of the primary hit, the only geometry the denoiser sees.

use glam::DVec3;

/// The surface seen through one pixel centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// World-space position of the hit.
    pub position: DVec3,
    /// Unit normal, turned toward the viewer.
    pub normal: DVec3,
    /// World-space size of one pixel at the hit: distance × angle of one pixel.
    pub footprint: f64,
}

/// Per-pixel surface data of the primary hit (pixel centre), row 0 at the top like
/// [`crate::render::Image`].
///
/// `valid[i]` is false for background or pixels without a receiver; the filters never mix such
/// pixels with valid ones (their other entries are not read).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub position: Vec<DVec3>,
    /// Unit normal toward the viewer.
    pub normal: Vec<DVec3>,
    /// World-space size of one pixel at that point (distance × pixel angle). Plane distances are
    /// measured in footprints, so the bilateral weights do not depend on the scene's scale.
    pub footprint: Vec<f64>,
    /// False: background / no receiver.
    pub valid: Vec<bool>,
}

impl GBuffer {
    /// A G-buffer whose pixel (x, y) sees `surface(x, y)` (`None`: invalid).
    pub(crate) fn from_fn(
        width: u32,
        height: u32,
        surface: impl Fn(u32, u32) -> Option<Surface>,
    ) -> Self {
        let n = width as usize * height as usize;
        let mut g = GBuffer {
            width,
            height,
            position: Vec::with_capacity(n),
            normal: Vec::with_capacity(n),
            footprint: Vec::with_capacity(n),
            valid: Vec::with_capacity(n),
        };
        for y in 0..height {
            for x in 0..width {
                let s = surface(x, y);
                g.valid.push(s.is_some());
                let s = s.unwrap_or(Surface {
                    position: DVec3::ZERO,
                    normal: DVec3::Z,
                    footprint: 0.0,
                });
                g.position.push(s.position);
                g.normal.push(s.normal);
                g.footprint.push(s.footprint);
            }
        }
        g
    }

    /// A fronto-parallel plane: pixel (x, y) at (x, −y, 0), normal +z, footprint 1. Every pixel
    /// is valid and every bilateral weight is 1, so the filters reduce to plain Gaussians.
    #[cfg(test)]
    pub(crate) fn flat(width: u32, height: u32) -> Self {
        GBuffer::from_fn(width, height, |x, y| {
            Some(Surface {
                position: DVec3::new(x as f64, -(y as f64), 0.0),
                normal: DVec3::Z,
                footprint: 1.0,
            })
        })
    }

    /// Number of pixels.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Panics unless every per-pixel vector holds `width × height` entries.
    pub(crate) fn check(&self) {
        let n = self.len();
        assert!(
            self.position.len() == n
                && self.normal.len() == n
                && self.footprint.len() == n
                && self.valid.len() == n,
            "GBuffer {}x{}: every per-pixel vector must hold {n} entries",
            self.width,
            self.height
        );
    }
}
