//! A tile's camera samples found before it is shaded: their primary hits, and the regions
//! (balls) holding its shading points, one per object and block of pixels, which the shading
//! stages share work within (`geometry::silhouettes::tile_candidates`).

use super::{PrimaryHit, RenderContext, SampleGrid, TileBounds, Tiles};
use crate::geometry::TileRegion;
use crate::scene::camera::CameraBasis;
use crate::shading::ShadingScratch;
use glam::DVec3;

/// Pixels per side of the blocks a tile's regions are cut by. What a region shares (the edges
/// that can be a contour edge from some point of it) grows with its size: on
/// tests/data/blender/suzanne.toml at 256 × 256 `--aa 4`, blocks of 1, 2, 4 and 16 pixels took
/// 12.1, 12.0, 13.1 and (at 128 × 128, 7.0 s against 3.7 s alone) far more
/// (docs/silhouettes.md, "Candidates shared by a tile").
const BLOCK: u32 = 2;

/// What one worker thread of the analytic renderer reuses from tile to tile.
#[derive(Default)]
pub(super) struct TileScratch {
    pub(super) shading: ShadingScratch,
    pub(super) hits: TileHits,
}

/// The primary hits of one tile, sample after sample, row by row, and their regions.
#[derive(Default)]
pub(super) struct TileHits {
    origin: (u32, u32),
    width: u32,
    samples: u32,
    /// Per camera sample: its hit, and the index of its object's region (receivers only).
    hits: Vec<Option<(PrimaryHit, Option<u32>)>>,
    /// Per object and block met: both (as one key) and the box of its receiving points.
    boxes: Vec<((u32, u32), DVec3, DVec3)>,
    regions: Vec<TileRegion>,
}

impl RenderContext {
    /// The region the renderer puts the first camera sample of pixel (x, y) in, on an image of
    /// `w` × `h` pixels with `aa` × `aa` samples each (what the probe shades its point
    /// through); `None` off the image, where nothing is hit, or for a point that is not shaded.
    pub(crate) fn tile_region_of(
        &self,
        basis: &CameraBasis,
        (w, h, aa): (u32, u32, u32),
        (x, y): (u32, u32),
    ) -> Option<TileRegion> {
        if x >= w || y >= h || aa == 0 {
            return None;
        }
        let tiles = Tiles::new(w, h);
        let t = (y / Tiles::SIDE) * w.div_ceil(Tiles::SIDE) + x / Tiles::SIDE;
        let mut hits = TileHits::default();
        let grid = SampleGrid::full(w, h, aa);
        hits.find(self, basis, tiles.bounds(t as usize), &grid);
        hits.hit(x, y, 0).and_then(|(_, region)| region)
    }
}

impl TileHits {
    /// Finds the hits of every camera sample of `grid` in the tile `bounds` (of the image
    /// `grid` renders) and the regions of its objects.
    /// Memory: one hit per sample of one tile (16 × 16 × aa² of them), reused.
    pub(super) fn find(
        &mut self,
        ctx: &RenderContext,
        basis: &CameraBasis,
        ((x0, y0), (x1, y1)): TileBounds,
        grid: &SampleGrid,
    ) {
        let t = self;
        t.origin = (x0, y0);
        t.width = x1 - x0;
        t.samples = grid.samples();
        t.hits.clear();
        t.boxes.clear();
        for y in y0..y1 {
            for x in x0..x1 {
                for ray in grid.rays(basis, x, y) {
                    let hit = ctx.primary_hit(&ray).map(|hit| {
                        let region = (hit.receiver).then(|| {
                            let block = ((y - y0) / BLOCK) * Tiles::SIDE + (x - x0) / BLOCK;
                            let key = (hit.point.object.unwrap_or(u32::MAX), block);
                            let p = hit.point.position;
                            // Searched from the newest: a block's samples come together.
                            match t.boxes.iter().rposition(|b| b.0 == key) {
                                Some(i) => {
                                    let b = &mut t.boxes[i];
                                    (b.1, b.2) = (b.1.min(p), b.2.max(p));
                                    i as u32
                                }
                                None => {
                                    t.boxes.push((key, p, p));
                                    (t.boxes.len() - 1) as u32
                                }
                            }
                        });
                        (hit, region)
                    });
                    t.hits.push(hit);
                }
            }
        }
        t.regions.clear();
        t.regions.extend(
            t.boxes
                .iter()
                .map(|&(_, lo, hi)| TileRegion::around(lo, hi)),
        );
    }
}

impl TileHits {
    /// Sample `k` of pixel (x, y) of the tile last found: its hit and its object's region.
    #[inline]
    pub(super) fn hit(
        &self,
        x: u32,
        y: u32,
        k: usize,
    ) -> Option<(&PrimaryHit, Option<TileRegion>)> {
        let pixel = (y - self.origin.1) * self.width + (x - self.origin.0);
        let i = pixel as usize * self.samples as usize + k;
        let (hit, region) = self.hits.get(i)?.as_ref()?;
        Some((hit, region.map(|r| self.regions[r as usize])))
    }
}
