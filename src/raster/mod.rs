//! Images as every layer above needs them: a linear-radiance [`Image`], Rec. 709
//! `luminance`, the G-buffer the denoisers and the environment's filter read
//! ([`gbuffer`]), and image files ([`io`]: PFM, OpenEXR, PNG).

pub mod gbuffer;
pub mod io;

use glam::DVec3;

/// Rec. 709 luminance of a linear RGB triple (weights of the BT.709 primaries).
#[inline]
pub(crate) fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// A linear-radiance image, row 0 at the top.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<DVec3>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![DVec3::ZERO; width as usize * height as usize],
        }
    }

    #[inline]
    pub fn at(&self, x: u32, y: u32) -> DVec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Pixels as f32 triples, for the image writers.
    pub fn to_rgb32(&self) -> Vec<[f32; 3]> {
        self.pixels
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect()
    }

    /// Counts of (NaN, infinite, negative) pixel channels.
    pub fn invalid_counts(&self) -> (usize, usize, usize) {
        let mut c = (0, 0, 0);
        for p in &self.pixels {
            for v in p.to_array() {
                if v.is_nan() {
                    c.0 += 1;
                } else if v.is_infinite() {
                    c.1 += 1;
                } else if v < 0.0 {
                    c.2 += 1;
                }
            }
        }
        c
    }
}
