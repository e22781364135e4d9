//! Which camera samples of an image a render computes: all of them, or, for a progressive
//! preview, one sample of every `stride`-th pixel, which the finer levels then take over
//! instead of computing it again (interlaced progressive rendering).
//!
//! A preview at stride `s` of a `w` × `h` image with `aa` × `aa` samples per pixel has
//! ⌈w/s⌉ × ⌈h/s⌉ pixels; its pixel (i, j) is sample 0 of the full image's pixel (s·i, s·j),
//! computed by the same stages along the same camera ray. The strides of the progressive
//! levels (8, 4, 2, 1) divide each other, so each level's samples contain the coarser levels':
//! all levels together cost one full image, and the last is the full image bit for bit.

use super::{Image, RenderOutput, subpixel_rays};
use crate::accel::Ray;
use crate::scene::camera::CameraBasis;
use glam::DVec3;

/// The camera samples of one render (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SampleGrid {
    /// The full image's size.
    pub width: u32,
    pub height: u32,
    /// The full image's `aa` × `aa` samples per pixel.
    pub aa: u32,
    /// 1: every sample of every pixel; s > 1: sample 0 of every s-th pixel each way.
    pub stride: u32,
}

impl SampleGrid {
    /// Every sample of a `width` × `height` image with `aa` × `aa` samples per pixel.
    pub(crate) fn full(width: u32, height: u32, aa: u32) -> Self {
        SampleGrid {
            width,
            height,
            aa,
            stride: 1,
        }
    }

    /// The size of the image this grid renders.
    pub fn size(&self) -> (u32, u32) {
        let s = self.stride.max(1);
        (self.width.div_ceil(s), self.height.div_ceil(s))
    }

    /// Samples per rendered pixel: all of a full pixel's, or one for a preview.
    pub(crate) fn samples(&self) -> u32 {
        if self.stride <= 1 {
            self.aa * self.aa
        } else {
            1
        }
    }

    /// The camera rays of the rendered pixel (i, j), in sample order.
    pub(crate) fn rays<'a>(
        &self,
        basis: &'a CameraBasis,
        i: u32,
        j: u32,
    ) -> impl Iterator<Item = Ray> + 'a {
        let s = self.stride.max(1);
        subpixel_rays(basis, i * s, j * s, self.aa, self.width, self.height)
            .take(self.samples() as usize)
    }
}

/// A coarser level of the same image (a preview at `stride`, a multiple of the grid's own),
/// whose pixels are samples the grid's render takes over.
#[derive(Clone, Copy)]
pub(crate) struct Coarser<'a> {
    pub stride: u32,
    pub output: &'a RenderOutput,
}

impl Coarser<'_> {
    /// Sample 0 of the rendered pixel (i, j) of `grid`, when this level computed it.
    #[inline]
    pub(crate) fn sample(&self, grid: &SampleGrid, i: u32, j: u32) -> Option<DVec3> {
        let q = self.ratio(grid)?;
        if !i.is_multiple_of(q) || !j.is_multiple_of(q) {
            return None;
        }
        let img: &Image = &self.output.image;
        let (ci, cj) = (i / q, j / q);
        (ci < img.width && cj < img.height).then(|| img.pixels[(cj * img.width + ci) as usize])
    }

    /// How many of `grid`'s pixels one of this level's spans each way; `None` when the levels
    /// do not nest (this one is not a coarser multiple of the grid, or of another image).
    fn ratio(&self, grid: &SampleGrid) -> Option<u32> {
        let s = grid.stride.max(1);
        let nested = self.stride > s && self.stride.is_multiple_of(s);
        let q = self.stride / s;
        let expected = SampleGrid {
            stride: self.stride,
            ..*grid
        }
        .size();
        let img = &self.output.image;
        (nested && (img.width, img.height) == expected).then_some(q)
    }

    /// Adds this level's counts (violations and fallbacks) to `out`, a render of `grid` that
    /// took this level's samples over: the totals then cover every sample of the image.
    pub(crate) fn add_counts_to(&self, grid: &SampleGrid, out: &mut RenderOutput) {
        let Some(q) = self.ratio(grid) else {
            return;
        };
        out.violations += self.output.violations;
        out.fallbacks.degenerate += self.output.fallbacks.degenerate;
        out.fallbacks.bounds_crossed += self.output.fallbacks.bounds_crossed;
        for &[x, y, n] in &self.output.violation_pixels {
            let (x, y) = (x * q, y * q);
            match out
                .violation_pixels
                .iter_mut()
                .find(|p| p[0] == x && p[1] == y)
            {
                Some(p) => p[2] += n,
                None => out.violation_pixels.push([x, y, n]),
            }
        }
        out.violation_pixels.sort_by_key(|p| (p[1], p[0]));
    }
}
