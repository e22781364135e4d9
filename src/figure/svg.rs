//! The SVG writer of a [`Figure`]: the same items as the raster back end, as vector paths
//! (for papers and slides), labels as SVG text in a sans-serif face.

use super::description::{Figure, Item, Rect, Rgb, Shape};
use super::font::Align;
use std::fmt::Write;

/// `figure` as an SVG document (SVG 1.1, sizes in pixels).
pub fn to_svg(figure: &Figure) -> String {
    let (w, h) = (figure.width, figure.height);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#
    );
    // One clip path per distinct rectangle.
    let mut clips: Vec<Rect> = Vec::new();
    for item in &figure.items {
        if let Item::Stroke { clip: Some(c), .. } = item
            && !clips.contains(c)
        {
            clips.push(*c);
        }
    }
    if !clips.is_empty() {
        out.push_str("<defs>\n");
        for (k, [l, t, r, b]) in clips.iter().enumerate() {
            let _ = writeln!(
                out,
                r#"<clipPath id="clip{k}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath>"#,
                num(*l),
                num(*t),
                num(r - l),
                num(b - t)
            );
        }
        out.push_str("</defs>\n");
    }
    let _ = writeln!(
        out,
        r#"<rect width="100%" height="100%" fill="{}"/>"#,
        colour(figure.background)
    );
    for item in &figure.items {
        match item {
            Item::Stroke {
                shape,
                color,
                width,
                opacity,
                clip,
            } => {
                let clip = clip
                    .and_then(|c| clips.iter().position(|d| *d == c))
                    .map(|k| format!(r#" clip-path="url(#clip{k})""#))
                    .unwrap_or_default();
                let opacity = if *opacity < 1.0 {
                    format!(r#" stroke-opacity="{}""#, num(opacity.clamp(0.0, 1.0)))
                } else {
                    String::new()
                };
                let _ = writeln!(
                    out,
                    r#"<{} fill="none" stroke="{}" stroke-width="{}"{opacity} stroke-linecap="butt" stroke-linejoin="round"{clip}/>"#,
                    element(shape),
                    colour(*color),
                    num(*width)
                );
            }
            Item::Fill {
                shape,
                color,
                opacity,
            } => {
                let opacity = if *opacity < 1.0 {
                    format!(r#" fill-opacity="{}""#, num(opacity.clamp(0.0, 1.0)))
                } else {
                    String::new()
                };
                let _ = writeln!(
                    out,
                    r#"<{} fill="{}"{opacity} fill-rule="nonzero" stroke="none"/>"#,
                    element(shape),
                    colour(*color)
                );
            }
            Item::Text { text, at, style } => {
                let anchor = match style.align {
                    Align::Left => "start",
                    Align::Center => "middle",
                    Align::Right => "end",
                };
                let rotate = if style.rotate != 0.0 {
                    format!(
                        r#" transform="rotate({} {} {})""#,
                        num(style.rotate),
                        num(at.0),
                        num(at.1)
                    )
                } else {
                    String::new()
                };
                // The raster back end's face first (egui's own); the size is the em.
                let size = style.size;
                let weight = if style.bold() { "bold" } else { "normal" };
                let _ = writeln!(
                    out,
                    r#"<text x="{}" y="{}" font-family="Ubuntu, DejaVu Sans, Helvetica, Arial, sans-serif" font-size="{}" font-weight="{weight}" text-anchor="{anchor}" fill="{}"{rotate}>{}</text>"#,
                    num(at.0),
                    num(at.1),
                    num(size),
                    colour(style.color),
                    escape(text)
                );
            }
        }
    }
    out.push_str("</svg>\n");
    out
}

fn element(shape: &Shape) -> String {
    match shape {
        Shape::Circle { centre, radius } => format!(
            r#"circle cx="{}" cy="{}" r="{}""#,
            num(centre.0),
            num(centre.1),
            num(*radius)
        ),
        Shape::Path(subpaths) => {
            let mut d = String::new();
            for s in subpaths {
                for (k, p) in s.points.iter().enumerate() {
                    let _ = write!(
                        d,
                        "{}{} {} ",
                        if k == 0 { "M" } else { "L" },
                        num(p.0),
                        num(p.1)
                    );
                }
                if s.closed && !s.points.is_empty() {
                    d.push_str("Z ");
                }
            }
            format!(r#"path d="{}""#, d.trim_end())
        }
    }
}

/// A coordinate with two decimals (a hundredth of a pixel), without trailing zeros.
fn num(v: f32) -> String {
    if !v.is_finite() {
        return "0".into();
    }
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn colour([r, g, b]: Rgb) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
