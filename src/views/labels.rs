//! Labels placed so that they do not overlap: each label tries positions around its anchor,
//! nearest first, and takes the first whose box meets no box placed before it (nor a blocked
//! area such as a legend) and stays inside the figure; a label with no free position is left
//! out rather than drawn over another (the hover text still names every vertex). Greedy in the
//! order the labels come, which puts the current stage's labels first.

use crate::figure::Rect;
use crate::figure::font::text_width;

/// The box a left-aligned label of pixel size `size` covers with its baseline starting at
/// `at`: from the top of a capital (0.8 em above the baseline) to the bottom of a descender
/// (0.25 em below), as wide as the stroke font draws it.
pub(crate) fn text_box(text: &str, at: (f32, f32), size: f32) -> Rect {
    [
        at.0,
        at.1 - 0.8 * size,
        at.0 + text_width(text, size),
        at.1 + 0.25 * size,
    ]
}

/// Whether two boxes overlap (touching edges do not).
pub fn overlaps(a: &Rect, b: &Rect) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Where a label goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Placement {
    /// The left end of its baseline.
    pub at: (f32, f32),
    /// Whether it sits away from its anchor (a leader line should join them).
    pub far: bool,
}

/// The boxes taken so far, within the figure's bounds.
#[derive(Clone, Debug)]
pub(crate) struct LabelPlacer {
    bounds: Rect,
    taken: Vec<Rect>,
    /// Labels that found no free position.
    pub dropped: usize,
}

impl LabelPlacer {
    pub fn new(bounds: Rect) -> Self {
        LabelPlacer {
            bounds,
            taken: Vec::new(),
            dropped: 0,
        }
    }

    /// Marks an area labels must keep out of (a legend, a title).
    pub(crate) fn block(&mut self, area: Rect) {
        self.taken.push(area);
    }

    /// A free position for `text` (pixel size `size`) next to `anchor`, `gap` pixels away,
    /// tried in eight directions, then in eight more at three times the gap; the box is taken.
    pub(crate) fn place(
        &mut self,
        text: &str,
        anchor: (f32, f32),
        size: f32,
        gap: f32,
    ) -> Option<Placement> {
        let w = text_width(text, size);
        let (asc, desc) = (0.8 * size, 0.25 * size);
        // Baseline starts for a box to the upper right, lower right, upper left, ... of the
        // anchor, at distance d.
        let at = |d: f32, k: usize| -> (f32, f32) {
            let (x, y) = anchor;
            match k {
                0 => (x + d, y - d),
                1 => (x + d, y + d + asc),
                2 => (x - d - w, y - d),
                3 => (x - d - w, y + d + asc),
                4 => (x + d, y + 0.5 * (asc - desc)),
                5 => (x - d - w, y + 0.5 * (asc - desc)),
                6 => (x - 0.5 * w, y - d - desc),
                _ => (x - 0.5 * w, y + d + asc),
            }
        };
        for (ring, d) in [gap, 3.0 * gap].into_iter().enumerate() {
            for k in 0..8 {
                let p = at(d, k);
                let b = text_box(text, p, size);
                let inside = b[0] >= self.bounds[0]
                    && b[1] >= self.bounds[1]
                    && b[2] <= self.bounds[2]
                    && b[3] <= self.bounds[3];
                if inside && !self.taken.iter().any(|t| overlaps(t, &b)) {
                    self.taken.push(b);
                    return Some(Placement {
                        at: p,
                        far: ring > 0,
                    });
                }
            }
        }
        self.dropped += 1;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Labels at one anchor, more than fit beside it, never overlap: each takes a free
    /// position or is dropped.
    #[test]
    fn crowded_labels_do_not_overlap() {
        let mut p = LabelPlacer::new([0.0, 0.0, 200.0, 200.0]);
        p.block([0.0, 0.0, 60.0, 40.0]);
        let mut boxes = Vec::new();
        for i in 0..30 {
            let text = format!("o{i}");
            if let Some(pl) = p.place(&text, (100.0, 100.0), 11.0, 4.0) {
                boxes.push(text_box(&text, pl.at, 11.0));
            }
        }
        // At least the four diagonal places of the near ring, which cannot meet.
        assert!(boxes.len() >= 4, "{} placed", boxes.len());
        assert_eq!(boxes.len() + p.dropped, 30);
        for (i, a) in boxes.iter().enumerate() {
            assert!(!overlaps(a, &[0.0, 0.0, 60.0, 40.0]));
            for b in &boxes[i + 1..] {
                assert!(!overlaps(a, b), "{a:?} {b:?}");
            }
        }
    }
}
