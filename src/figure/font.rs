//! A small stroke font for chart labels: each glyph is a few polylines on a grid, drawn as
//! tiny-skia strokes (tiny-skia draws no text).
//!
//! Glyph units: baseline at y = 0, y up, x-height 4, cap and ascender height 6, descender −2;
//! most glyphs are 4 units wide. The pixel size of a text is its em, [`EM`] units, so at 11 px
//! a capital is 7.3 px tall. Characters: digits, ASCII letters, space and
//! `. , : - + = / ( ) [ ] % _ ×`, plus `e`-notation needs nothing more; anything else draws as
//! an empty box.

use tiny_skia::{LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// Glyph units per em (the pixel size of a text).
pub const EM: f32 = 9.0;
/// Gap between glyphs, in glyph units.
const SPACING: f32 = 1.3;

/// One glyph: its advance width (without the gap) and its polylines, written as
/// `"x,y x,y …|x,y …"`.
struct Glyph {
    width: f32,
    strokes: &'static str,
}

const fn g(width: f32, strokes: &'static str) -> Glyph {
    Glyph { width, strokes }
}

/// The box drawn for a character the font lacks.
const MISSING: Glyph = g(4.0, "0,0 4,0 4,6 0,6 0,0");

fn glyph(c: char) -> Glyph {
    match c {
        ' ' => g(2.5, ""),
        '0' => g(4.0, "1,0 3,0 4,1 4,5 3,6 1,6 0,5 0,1 1,0"),
        '1' => g(4.0, "0.8,4.8 2.2,6 2.2,0|0.8,0 3.6,0"),
        '2' => g(4.0, "0,5 1,6 3,6 4,5 4,3.8 0,0 4,0"),
        '3' => g(
            4.0,
            "0,5 1,6 3,6 4,5 4,4 3,3.2 1.5,3.2|3,3.2 4,2.3 4,1 3,0 1,0 0,1",
        ),
        '4' => g(4.0, "3,0 3,6 0,1.8 4,1.8"),
        '5' => g(4.0, "4,6 0.4,6 0,3.4 3,3.6 4,2.6 4,1 3,0 1,0 0,0.8"),
        '6' => g(
            4.0,
            "3.8,5.6 3,6 1,6 0,5 0,1 1,0 3,0 4,1 4,2.6 3,3.6 1,3.6 0,2.6",
        ),
        '7' => g(4.0, "0,6 4,6 1.3,0"),
        '8' => g(
            4.0,
            "1,3.2 0.2,4.1 0.2,5.2 1,6 3,6 3.8,5.2 3.8,4.1 3,3.2 1,3.2 0,2.2 0,1 1,0 3,0 4,1 4,2.2 3,3.2",
        ),
        '9' => g(
            4.0,
            "0.2,0.4 1,0 3,0 4,1 4,5 3,6 1,6 0,5 0,3.4 1,2.4 3,2.4 4,3.4",
        ),

        'A' => g(4.4, "0,0 2.2,6 4.4,0|0.8,2.1 3.6,2.1"),
        'B' => g(
            4.0,
            "0,0 0,6 3,6 3.8,5.2 3.8,4 3,3.2 0,3.2|3,3.2 4,2.3 4,0.9 3,0 0,0",
        ),
        'C' => g(4.0, "4,5 3,6 1,6 0,5 0,1 1,0 3,0 4,1"),
        'D' => g(4.0, "0,0 0,6 2.4,6 4,4.4 4,1.6 2.4,0 0,0"),
        'E' => g(3.8, "3.8,6 0,6 0,0 3.8,0|0,3.2 3,3.2"),
        'F' => g(3.8, "3.8,6 0,6 0,0|0,3.2 3,3.2"),
        'G' => g(4.0, "4,5 3,6 1,6 0,5 0,1 1,0 3,0 4,1 4,2.8 2.2,2.8"),
        'H' => g(4.0, "0,0 0,6|4,0 4,6|0,3.2 4,3.2"),
        'I' => g(2.0, "0,0 2,0|1,0 1,6|0,6 2,6"),
        'J' => g(3.6, "3.6,6 3.6,1 2.6,0 1,0 0,1"),
        'K' => g(4.0, "0,0 0,6|4,6 0,2|1.4,3.4 4,0"),
        'L' => g(3.6, "0,6 0,0 3.6,0"),
        'M' => g(5.0, "0,0 0,6 2.5,2.6 5,6 5,0"),
        'N' => g(4.0, "0,0 0,6 4,0 4,6"),
        'O' => g(
            4.6,
            "1.1,0 3.5,0 4.6,1.1 4.6,4.9 3.5,6 1.1,6 0,4.9 0,1.1 1.1,0",
        ),
        'P' => g(4.0, "0,0 0,6 3,6 4,5 4,3.8 3,2.8 0,2.8"),
        'Q' => g(
            4.6,
            "1.1,0 3.5,0 4.6,1.1 4.6,4.9 3.5,6 1.1,6 0,4.9 0,1.1 1.1,0|2.8,1.6 4.8,-0.4",
        ),
        'R' => g(4.0, "0,0 0,6 3,6 4,5 4,3.8 3,2.8 0,2.8|2,2.8 4,0"),
        'S' => g(4.0, "4,5 3,6 1,6 0,5 0,4 1,3.1 3,2.9 4,2 4,1 3,0 1,0 0,1"),
        'T' => g(4.4, "0,6 4.4,6|2.2,6 2.2,0"),
        'U' => g(4.0, "0,6 0,1 1,0 3,0 4,1 4,6"),
        'V' => g(4.4, "0,6 2.2,0 4.4,6"),
        'W' => g(5.6, "0,6 1.3,0 2.8,4.4 4.3,0 5.6,6"),
        'X' => g(4.0, "0,0 4,6|0,6 4,0"),
        'Y' => g(4.4, "0,6 2.2,3 4.4,6|2.2,3 2.2,0"),
        'Z' => g(4.0, "0,6 4,6 0,0 4,0"),

        'a' => g(3.8, "3.8,4 3.8,0|3.8,3 2.8,4 1,4 0,3 0,1 1,0 2.8,0 3.8,1"),
        'b' => g(3.8, "0,6 0,0|0,3 1,4 2.8,4 3.8,3 3.8,1 2.8,0 1,0 0,1"),
        'c' => g(3.5, "3.5,3.3 2.7,4 1,4 0,3 0,1 1,0 2.7,0 3.5,0.7"),
        'd' => g(3.8, "3.8,6 3.8,0|3.8,3 2.8,4 1,4 0,3 0,1 1,0 2.8,0 3.8,1"),
        'e' => g(
            3.8,
            "0,2.1 3.8,2.1 3.8,3 2.8,4 1,4 0,3 0,1 1,0 2.8,0 3.6,0.6",
        ),
        'f' => g(3.0, "3,5.6 2.4,6 1.8,6 1,5.2 1,0|0,4 2.8,4"),
        'g' => g(
            3.8,
            "3.8,4 3.8,-1 2.8,-2 1,-2 0.2,-1.4|3.8,3 2.8,4 1,4 0,3 0,1 1,0 2.8,0 3.8,1",
        ),
        'h' => g(3.8, "0,6 0,0|0,3 1,4 2.8,4 3.8,3 3.8,0"),
        'i' => g(1.0, "0.5,0 0.5,4|0.5,5.4 0.5,5.7"),
        'j' => g(2.0, "1.5,4 1.5,-1.2 0.7,-2 0,-2|1.5,5.4 1.5,5.7"),
        'k' => g(3.6, "0,6 0,0|3.4,4 0,1.4|1.3,2.3 3.6,0"),
        'l' => g(1.6, "0.5,6 0.5,0.8 1.3,0"),
        'm' => g(
            5.6,
            "0,0 0,4|0,3 0.8,4 2,4 2.8,3 2.8,0|2.8,3 3.6,4 4.8,4 5.6,3 5.6,0",
        ),
        'n' => g(3.8, "0,0 0,4|0,3 1,4 2.8,4 3.8,3 3.8,0"),
        'o' => g(3.8, "1,0 2.8,0 3.8,1 3.8,3 2.8,4 1,4 0,3 0,1 1,0"),
        'p' => g(3.8, "0,4 0,-2|0,3 1,4 2.8,4 3.8,3 3.8,1 2.8,0 1,0 0,1"),
        'q' => g(3.8, "3.8,4 3.8,-2|3.8,3 2.8,4 1,4 0,3 0,1 1,0 2.8,0 3.8,1"),
        'r' => g(3.0, "0,0 0,4|0,2.6 1.4,4 3,4"),
        's' => g(
            3.6,
            "3.6,3.4 3,4 0.7,4 0,3.4 0,2.6 0.6,2.1 3,1.9 3.6,1.4 3.6,0.6 3,0 0.6,0 0,0.6",
        ),
        't' => g(3.0, "1,5.6 1,0.9 1.8,0 3,0|0,4 2.8,4"),
        'u' => g(3.8, "0,4 0,1 1,0 2.8,0 3.8,1|3.8,4 3.8,0"),
        'v' => g(4.0, "0,4 2,0 4,4"),
        'w' => g(5.4, "0,4 1.3,0 2.7,3 4.1,0 5.4,4"),
        'x' => g(3.8, "0,0 3.8,4|0,4 3.8,0"),
        'y' => g(4.0, "0,4 2,0|4,4 1.4,-1.4 0.6,-2 0,-2"),
        'z' => g(3.6, "0,4 3.6,4 0,0 3.6,0"),

        '.' => g(1.0, "0.5,0.1 0.5,0.4"),
        ',' => g(1.2, "0.9,0.5 0.9,0 0.2,-1.2"),
        ':' => g(1.0, "0.5,0.1 0.5,0.4|0.5,3.3 0.5,3.6"),
        '-' => g(3.0, "0.2,2.4 2.8,2.4"),
        '+' => g(4.0, "0,2.4 4,2.4|2,0.4 2,4.4"),
        '=' => g(4.0, "0,1.5 4,1.5|0,3.3 4,3.3"),
        '/' => g(3.0, "0,-0.8 3,6.6"),
        '(' => g(2.0, "2,6.6 0.6,4.6 0.6,0.2 2,-1.6"),
        ')' => g(2.0, "0,6.6 1.4,4.6 1.4,0.2 0,-1.6"),
        '[' => g(2.0, "2,6.6 0.4,6.6 0.4,-1.6 2,-1.6"),
        ']' => g(2.0, "0,6.6 1.6,6.6 1.6,-1.6 0,-1.6"),
        '%' => g(
            4.6,
            "0.2,0 4.4,6|1,6 1.8,5.2 1,4.4 0.2,5.2 1,6|3.6,1.6 4.4,0.8 3.6,0 2.8,0.8 3.6,1.6",
        ),
        '_' => g(4.0, "0,-1 4,-1"),
        '×' => g(3.6, "0.2,0.8 3.4,4|0.2,4 3.4,0.8"),
        _ => MISSING,
    }
}

/// The polylines of a glyph in glyph units.
fn polylines(gl: &Glyph) -> impl Iterator<Item = Vec<(f32, f32)>> + '_ {
    gl.strokes.split('|').filter(|s| !s.is_empty()).map(|s| {
        s.split_whitespace()
            .filter_map(|p| {
                let (x, y) = p.split_once(',')?;
                Some((x.parse().ok()?, y.parse().ok()?))
            })
            .collect()
    })
}

/// Width in pixels of `text` drawn at pixel size `size`.
pub fn text_width(text: &str, size: f32) -> f32 {
    let units: f32 = text.chars().map(|c| glyph(c).width + SPACING).sum();
    (units - SPACING).max(0.0) * size / EM
}

/// Height in pixels of a capital at pixel size `size`.
pub fn cap_height(size: f32) -> f32 {
    6.0 * size / EM
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
    /// Stroke width in pixels.
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
            weight: (size * 0.1).max(1.0),
            color,
            align: Align::Left,
            rotate: 0.0,
        }
    }

    pub fn align(self, align: Align) -> Self {
        TextStyle { align, ..self }
    }

    pub fn rotate(self, degrees: f32) -> Self {
        TextStyle {
            rotate: degrees,
            ..self
        }
    }

    pub fn weight(self, weight: f32) -> Self {
        TextStyle { weight, ..self }
    }
}

/// Draws `text` with its baseline through the anchor (`x`, `y`) in pixels. Non-finite anchors
/// draw nothing.
pub fn draw_text(pixmap: &mut Pixmap, text: &str, x: f32, y: f32, style: &TextStyle) {
    if !(x.is_finite() && y.is_finite() && style.size.is_finite() && style.size > 0.0) {
        return;
    }
    let s = style.size / EM;
    let width = text_width(text, style.size);
    let mut pen = match style.align {
        Align::Left => 0.0,
        Align::Center => -0.5 * width,
        Align::Right => -width,
    };
    let mut pb = PathBuilder::new();
    for c in text.chars() {
        let gl = glyph(c);
        for line in polylines(&gl) {
            for (k, &(gx, gy)) in line.iter().enumerate() {
                let (px, py) = (pen + gx * s, -gy * s);
                if k == 0 {
                    pb.move_to(px, py);
                } else {
                    pb.line_to(px, py);
                }
            }
        }
        pen += (gl.width + SPACING) * s;
    }
    let Some(path) = pb.finish() else {
        return;
    };
    let mut paint = Paint::default();
    let [r, g, b] = style.color;
    paint.set_color_rgba8(r, g, b, 255);
    paint.anti_alias = true;
    let stroke = Stroke {
        width: style.weight,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    };
    let transform =
        Transform::from_translate(x, y).pre_concat(Transform::from_rotate(style.rotate));
    pixmap.stroke_path(&path, &paint, &stroke, transform, None);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every character the charts need has a real glyph with well-formed polylines inside the
    /// glyph's box (a little overhang allowed for brackets and descenders).
    #[test]
    fn glyphs_are_well_formed() {
        let wanted = ('0'..='9')
            .chain('a'..='z')
            .chain('A'..='Z')
            .chain(".-+/()%×:_,=[]".chars());
        for c in wanted {
            let gl = glyph(c);
            assert!(!std::ptr::eq(gl.strokes, MISSING.strokes), "{c:?} missing");
            let lines: Vec<_> = polylines(&gl).collect();
            let written: Vec<usize> = gl
                .strokes
                .split('|')
                .map(|s| s.split_whitespace().count())
                .collect();
            let parsed: Vec<usize> = lines.iter().map(Vec::len).collect();
            assert_eq!(parsed, written, "{c:?}: a point does not parse");
            for line in &lines {
                assert!(line.len() >= 2, "{c:?}: {line:?}");
                for &(x, y) in line {
                    assert!((-0.5..=gl.width + 0.5).contains(&x), "{c:?} x {x}");
                    assert!((-2.0..=6.6).contains(&y), "{c:?} y {y}");
                }
            }
        }
        assert_eq!(text_width("", 11.0), 0.0);
        assert!(text_width("mm", 11.0) > text_width("ii", 11.0));
    }

    /// Text lands where it is anchored: right-aligned text ends at the anchor.
    #[test]
    fn alignment() {
        let mut pm = Pixmap::new(100, 30).unwrap();
        let style = TextStyle::new(11.0, [0, 0, 0]).align(Align::Right);
        draw_text(&mut pm, "HH", 60.0, 20.0, &style);
        let inked = |x: u32| (0..30).any(|y| pm.pixel(x, y).unwrap().alpha() > 0);
        assert!(inked(59) && !inked(62));
        assert!(!inked(60 - text_width("HH", 11.0) as u32 - 3));
        draw_text(&mut pm, "x", f32::NAN, 1.0, &style);
    }
}
