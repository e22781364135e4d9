//! The PDF writer of a [`Figure`] (through the `pdf-writer` crate): one page, one point per
//! figure pixel, the same items as the raster and SVG back ends as vector paths, opacities as
//! graphics states and labels in Helvetica (one of PDF's standard fonts, which every reader
//! has, so nothing is embedded). Written directly from the description rather than through an
//! SVG converter: the figure is already vector data, and the converter would need the system's
//! fonts to keep the labels.

use super::description::{Figure, Item, Rgb, Shape};
use super::font::Align;
use pdf_writer::types::{LineCapStyle, LineJoinStyle};
use pdf_writer::{Content, Name, Pdf, Rect, Ref, Str};

/// Helvetica's advance widths (its AFM, in 1/1000 em) for the printable ASCII characters 32 to
/// 126, to align labels centred or right.
const HELVETICA: [u16; 95] = [
    278, 278, 355, 556, 556, 889, 667, 191, 333, 333, 389, 584, 278, 333, 278, 278, 556, 556, 556,
    556, 556, 556, 556, 556, 556, 556, 278, 278, 584, 584, 584, 556, 1015, 667, 667, 722, 722, 667,
    611, 778, 722, 278, 500, 667, 556, 833, 722, 778, 667, 778, 722, 667, 611, 722, 667, 944, 667,
    667, 611, 278, 278, 278, 469, 556, 333, 556, 556, 500, 556, 556, 278, 556, 556, 222, 222, 500,
    222, 833, 556, 556, 556, 556, 333, 500, 278, 556, 500, 722, 500, 500, 500, 334, 260, 334, 584,
];

/// `text` in WinAnsi bytes (Latin-1 letters and signs as they are, a few typographic ones
/// mapped, anything else '?').
fn win_ansi(text: &str) -> Vec<u8> {
    text.chars()
        .map(|c| match c {
            ' '..='~' => c as u8,
            '\u{a0}'..='\u{ff}' => c as u32 as u8,
            '–' => 0x96,
            '—' => 0x97,
            '•' => 0x95,
            '−' => b'-',
            _ => b'?',
        })
        .collect()
}

/// Width of WinAnsi bytes in em (characters outside ASCII taken as a digit's width).
fn width_em(bytes: &[u8]) -> f32 {
    bytes
        .iter()
        .map(|&b| match b {
            32..=126 => HELVETICA[(b - 32) as usize] as f32,
            _ => 556.0,
        })
        .sum::<f32>()
        / 1000.0
}

fn rgb(c: Rgb) -> (f32, f32, f32) {
    (
        c[0] as f32 / 255.0,
        c[1] as f32 / 255.0,
        c[2] as f32 / 255.0,
    )
}

/// The shape as path operators (y already flipped by the page's matrix).
fn path(content: &mut Content, shape: &Shape) {
    match shape {
        Shape::Path(subpaths) => {
            for sp in subpaths.iter().filter(|s| !s.points.is_empty()) {
                let (x, y) = sp.points[0];
                content.move_to(x, y);
                for &(x, y) in &sp.points[1..] {
                    content.line_to(x, y);
                }
                if sp.closed {
                    content.close_path();
                }
            }
        }
        Shape::Circle { centre, radius } => {
            // Four cubic Béziers, control points at k = 4/3 (√2 − 1) of the radius.
            let (cx, cy, r) = (centre.0, centre.1, *radius);
            let k = 0.552_284_8 * r;
            content.move_to(cx + r, cy);
            content.cubic_to(cx + r, cy + k, cx + k, cy + r, cx, cy + r);
            content.cubic_to(cx - k, cy + r, cx - r, cy + k, cx - r, cy);
            content.cubic_to(cx - r, cy - k, cx - k, cy - r, cx, cy - r);
            content.cubic_to(cx + k, cy - r, cx + r, cy - k, cx + r, cy);
            content.close_path();
        }
    }
}

/// `figure` as a one-page PDF document. Deterministic: no dates, the same bytes for the same
/// figure.
pub fn to_pdf(figure: &Figure) -> Vec<u8> {
    let (w, h) = (figure.width as f32, figure.height as f32);
    let catalog_id = Ref::new(1);
    let pages_id = Ref::new(2);
    let page_id = Ref::new(3);
    let content_id = Ref::new(4);
    let font_id = Ref::new(5);
    let bold_id = Ref::new(6);
    let first_state = 7;
    // One graphics state per distinct (stroke, fill) opacity pair.
    let mut alphas: Vec<(u16, u16)> = Vec::new();
    let key = |o: f32| (o.clamp(0.0, 1.0) * 1000.0).round() as u16;
    for item in &figure.items {
        let pair = match item {
            Item::Stroke { opacity, .. } => (key(*opacity), 1000),
            Item::Fill { opacity, .. } => (1000, key(*opacity)),
            Item::Text { .. } => (1000, 1000),
        };
        if !alphas.contains(&pair) {
            alphas.push(pair);
        }
    }
    let state_name = |k: usize| format!("G{k}");

    let mut c = Content::new();
    // Figure pixels, y down: flip the page's y axis once.
    c.transform([1.0, 0.0, 0.0, -1.0, 0.0, h]);
    let (r, g, b) = rgb(figure.background);
    c.set_fill_rgb(r, g, b);
    c.rect(0.0, 0.0, w, h);
    c.fill_nonzero();
    c.set_line_cap(LineCapStyle::ButtCap);
    c.set_line_join(LineJoinStyle::RoundJoin);
    let set_state = |c: &mut Content, pair: (u16, u16)| {
        let k = alphas.iter().position(|p| *p == pair).unwrap_or(0);
        let name = state_name(k);
        c.set_parameters(Name(name.as_bytes()));
    };
    for item in &figure.items {
        match item {
            Item::Stroke {
                shape,
                color,
                width,
                opacity,
                clip,
            } => {
                c.save_state();
                if let Some([l, t, r, b]) = clip {
                    c.rect(*l, *t, r - l, b - t);
                    c.clip_nonzero();
                    c.end_path();
                }
                set_state(&mut c, (key(*opacity), 1000));
                let (r, g, b) = rgb(*color);
                c.set_stroke_rgb(r, g, b);
                c.set_line_width(*width);
                path(&mut c, shape);
                c.stroke();
                c.restore_state();
            }
            Item::Fill {
                shape,
                color,
                opacity,
            } => {
                c.save_state();
                set_state(&mut c, (1000, key(*opacity)));
                let (r, g, b) = rgb(*color);
                c.set_fill_rgb(r, g, b);
                path(&mut c, shape);
                c.fill_nonzero();
                c.restore_state();
            }
            Item::Text { text, at, style } => {
                let bytes = win_ansi(text);
                let size = style.size;
                let bold = style.bold();
                let advance = width_em(&bytes) * size;
                let shift = match style.align {
                    Align::Left => 0.0,
                    Align::Center => -0.5 * advance,
                    Align::Right => -advance,
                };
                // Text space: x along the label (rotated clockwise on screen by `rotate`), y
                // up on screen, in the flipped page.
                let (sin, cos) = style.rotate.to_radians().sin_cos();
                let (x, y) = (at.0 + shift * cos, at.1 + shift * sin);
                let (r, g, b) = rgb(style.color);
                c.set_fill_rgb(r, g, b);
                c.begin_text();
                c.set_font(Name(if bold { b"F2" } else { b"F1" }), size);
                c.set_text_matrix([cos, sin, sin, -cos, x, y]);
                c.show(Str(&bytes));
                c.end_text();
            }
        }
    }

    let mut pdf = Pdf::new();
    pdf.catalog(catalog_id).pages(pages_id);
    pdf.pages(pages_id).kids([page_id]).count(1);
    {
        let mut page = pdf.page(page_id);
        page.media_box(Rect::new(0.0, 0.0, w, h))
            .parent(pages_id)
            .contents(content_id);
        let mut resources = page.resources();
        resources
            .fonts()
            .pair(Name(b"F1"), font_id)
            .pair(Name(b"F2"), bold_id);
        let mut states = resources.ext_g_states();
        for k in 0..alphas.len() {
            let name = state_name(k);
            states.pair(Name(name.as_bytes()), Ref::new(first_state + k as i32));
        }
    }
    pdf.type1_font(font_id)
        .base_font(Name(b"Helvetica"))
        .encoding_predefined(Name(b"WinAnsiEncoding"));
    pdf.type1_font(bold_id)
        .base_font(Name(b"Helvetica-Bold"))
        .encoding_predefined(Name(b"WinAnsiEncoding"));
    for (k, (stroke, fill)) in alphas.iter().enumerate() {
        pdf.ext_graphics(Ref::new(first_state + k as i32))
            .stroking_alpha(*stroke as f32 / 1000.0)
            .non_stroking_alpha(*fill as f32 / 1000.0);
    }
    pdf.stream(content_id, &c.finish());
    pdf.finish()
}
