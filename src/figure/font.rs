//! Labels in a real typeface: Ubuntu Light, egui's own proportional face (from the
//! `epaint_default_fonts` crate), read by `ab_glyph` and filled by tiny-skia as glyph outlines.
//! The workbench (egui), the PNG back end and the label metrics (widths for alignment and
//! for placing labels apart) therefore use one face; the SVG names it first in its font list.
//!
//! Sizes are ems in pixels: a label of size 12 has 12 px from one em's top to its bottom (a
//! capital is about 0.69 em tall).

use ab_glyph::{Font, FontRef, GlyphId, OutlineCurve};
use std::sync::OnceLock;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// The face, parsed once.
fn face() -> &'static FontRef<'static> {
    static FACE: OnceLock<FontRef<'static>> = OnceLock::new();
    FACE.get_or_init(|| {
        FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT)
            .expect("the embedded Ubuntu Light parses")
    })
}

/// Font units per em.
fn units_per_em() -> f32 {
    face().units_per_em().unwrap_or(1000.0)
}

/// The glyphs of `text` with the pen position (font units) each starts at, and the advance of
/// the whole text; kerning applied.
fn layout(text: &str) -> (Vec<(GlyphId, f32)>, f32) {
    let f = face();
    let mut pen = 0.0;
    let mut prev: Option<GlyphId> = None;
    let mut out = Vec::with_capacity(text.len());
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            pen += f.kern_unscaled(p, id);
        }
        out.push((id, pen));
        pen += f.h_advance_unscaled(id);
        prev = Some(id);
    }
    (out, pen)
}

/// Width in pixels of `text` drawn at pixel size `size`.
pub fn text_width(text: &str, size: f32) -> f32 {
    layout(text).1 * size / units_per_em()
}

/// Height in pixels of a capital (the face's H) at pixel size `size`.
pub(crate) fn cap_height(size: f32) -> f32 {
    let f = face();
    // The highest point of the H's outline curves (font units, y up).
    let h = f
        .outline(f.glyph_id('H'))
        .map_or(0.69 * units_per_em(), |o| {
            o.curves
                .iter()
                .flat_map(|c| match c {
                    OutlineCurve::Line(a, b) => vec![a.y, b.y],
                    OutlineCurve::Quad(a, b, c) => vec![a.y, b.y, c.y],
                    OutlineCurve::Cubic(a, b, c, d) => vec![a.y, b.y, c.y, d.y],
                })
                .fold(0.0, f32::max)
        });
    h * size / units_per_em()
}

/// Depth in pixels of the face's descender below the baseline at pixel size `size`.
pub(crate) fn descent(size: f32) -> f32 {
    -face().descent_unscaled() * size / units_per_em()
}

/// Horizontal placement of a text relative to its anchor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    Left,
    Center,
    Right,
}

/// How a text is drawn.
#[derive(Clone, Copy, Debug)]
pub struct TextStyle {
    /// Pixel size (one em).
    pub size: f32,
    /// Above 0.12 em, the text is bold (its outline also stroked this much less 0.1 em).
    pub weight: f32,
    pub color: [u8; 3],
    pub align: Align,
    /// Degrees, clockwise on screen about the anchor (−90 reads bottom to top).
    pub rotate: f32,
}

impl TextStyle {
    pub fn new(size: f32, color: [u8; 3]) -> Self {
        TextStyle {
            size,
            weight: 0.1 * size,
            color,
            align: Align::Left,
            rotate: 0.0,
        }
    }

    pub(crate) fn align(self, align: Align) -> Self {
        TextStyle { align, ..self }
    }

    pub(crate) fn rotate(self, degrees: f32) -> Self {
        TextStyle {
            rotate: degrees,
            ..self
        }
    }

    pub(crate) fn weight(self, weight: f32) -> Self {
        TextStyle { weight, ..self }
    }

    /// Whether the text is drawn bold.
    pub(crate) fn bold(&self) -> bool {
        self.weight > 0.12 * self.size
    }
}

/// Draws `text` with its baseline through the anchor (`x`, `y`) in pixels: the glyphs'
/// outlines filled (nonzero, as TrueType outlines are wound). Non-finite anchors draw nothing.
pub(crate) fn draw_text(pixmap: &mut Pixmap, text: &str, x: f32, y: f32, style: &TextStyle) {
    if !(x.is_finite() && y.is_finite() && style.size.is_finite() && style.size > 0.0) {
        return;
    }
    let k = style.size / units_per_em();
    let (glyphs, advance) = layout(text);
    let start = match style.align {
        Align::Left => 0.0,
        Align::Center => -0.5 * advance,
        Align::Right => -advance,
    };
    // Font units (y up) to the label's frame (y down), then rotated about the anchor.
    let mut pb = PathBuilder::new();
    let f = face();
    for (id, pen) in glyphs {
        let Some(outline) = f.outline(id) else {
            continue;
        };
        let at = |p: ab_glyph::Point| ((start + pen + p.x) * k, -p.y * k);
        let mut last: Option<(f32, f32)> = None;
        for curve in &outline.curves {
            let first = match curve {
                OutlineCurve::Line(p, _) | OutlineCurve::Quad(p, _, _) => *p,
                OutlineCurve::Cubic(p, _, _, _) => *p,
            };
            let p0 = at(first);
            // A curve that does not start where the last one ended starts a new contour.
            if last != Some(p0) {
                if last.is_some() {
                    pb.close();
                }
                pb.move_to(p0.0, p0.1);
            }
            let end = match curve {
                OutlineCurve::Line(_, p1) => {
                    let q = at(*p1);
                    pb.line_to(q.0, q.1);
                    q
                }
                OutlineCurve::Quad(_, c, p2) => {
                    let (c, q) = (at(*c), at(*p2));
                    pb.quad_to(c.0, c.1, q.0, q.1);
                    q
                }
                OutlineCurve::Cubic(_, c1, c2, p3) => {
                    let (c1, c2, q) = (at(*c1), at(*c2), at(*p3));
                    pb.cubic_to(c1.0, c1.1, c2.0, c2.1, q.0, q.1);
                    q
                }
            };
            last = Some(end);
        }
        if last.is_some() {
            pb.close();
        }
    }
    let Some(path) = pb.finish() else {
        return;
    };
    let mut paint = Paint::default();
    let [r, g, b] = style.color;
    paint.set_color_rgba8(r, g, b, 255);
    paint.anti_alias = true;
    let t = Transform::from_rotate(style.rotate).post_translate(x, y);
    pixmap.fill_path(&path, &paint, FillRule::Winding, t, None);
    if style.bold() {
        let stroke = Stroke {
            width: style.weight - 0.1 * style.size,
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, &paint, &stroke, t, None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The metrics scale with the size, a capital is about 0.69 em, and alignment moves the
    /// ink by the text's width: the inked columns of a right-aligned label end where a
    /// left-aligned one's start, up to anti-aliasing.
    #[test]
    fn metrics_and_alignment_agree_with_the_ink() {
        let (w12, w24) = (
            text_width("Penumbra 0.5", 12.0),
            text_width("Penumbra 0.5", 24.0),
        );
        assert!((w24 - 2.0 * w12).abs() < 1e-3, "{w12} {w24}");
        let cap = cap_height(100.0);
        assert!((60.0..80.0).contains(&cap), "{cap}");
        let ink = |align: Align| -> (usize, usize) {
            let mut pm = Pixmap::new(400, 60).unwrap();
            let style = TextStyle::new(24.0, [255, 255, 255]).align(align);
            draw_text(&mut pm, "Hello", 200.0, 40.0, &style);
            let cols: Vec<usize> = (0..400)
                .filter(|&x| (0..60).any(|y| pm.pixel(x, y).unwrap().alpha() > 128))
                .map(|x| x as usize)
                .collect();
            (cols[0], *cols.last().unwrap())
        };
        let w = text_width("Hello", 24.0);
        let (l0, l1) = ink(Align::Left);
        let (r0, r1) = ink(Align::Right);
        assert!((l0 as f32 - 200.0).abs() <= 3.0, "{l0}");
        assert!((r1 as f32 - 200.0).abs() <= 3.0, "{r1}");
        assert!(((l1 - l0) as f32 - w).abs() <= 4.0 && ((r1 - r0) as f32 - w).abs() <= 4.0);
        // A bold label inks more pixels than a regular one.
        let count = |style: TextStyle| {
            let mut pm = Pixmap::new(400, 60).unwrap();
            draw_text(&mut pm, "Hello", 10.0, 40.0, &style);
            pm.pixels().iter().filter(|p| p.alpha() > 128).count()
        };
        let regular = TextStyle::new(24.0, [255, 255, 255]);
        assert!(count(regular.weight(4.0)) > count(regular));
    }
}
