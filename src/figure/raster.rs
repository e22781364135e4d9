//! The raster back end of a [`Figure`]: tiny-skia, anti-aliased, labels in the stroke font of
//! [`super::font`].

use super::description::{Figure, Item, Rgb, Shape};
use super::font;
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Mask, Paint, Path, PathBuilder, Pixmap, Rect, Stroke,
    Transform,
};

/// The largest side a figure is drawn at.
pub(crate) const MAX_SIDE: u32 = 16384;

/// Draws `figure` into a pixmap of its size (each side clamped to 1..=`MAX_SIDE`).
pub fn render(figure: &Figure) -> Pixmap {
    let (w, h) = (
        figure.width.clamp(1, MAX_SIDE),
        figure.height.clamp(1, MAX_SIDE),
    );
    let mut pm = Pixmap::new(w, h).expect("a size within tiny-skia's limits");
    let [r, g, b] = figure.background;
    pm.fill(Color::from_rgba8(r, g, b, 255));
    for item in &figure.items {
        match item {
            Item::Stroke {
                shape,
                color,
                width,
                opacity,
                clip,
            } => {
                let Some(path) = path_of(shape) else {
                    continue;
                };
                let mask = clip.and_then(|[l, t, r, b]| {
                    let mut mask = Mask::new(w, h)?;
                    let rect = Rect::from_ltrb(l, t, r, b)?;
                    let p = PathBuilder::from_rect(rect);
                    mask.fill_path(&p, FillRule::Winding, false, Transform::identity());
                    Some(mask)
                });
                let stroke = Stroke {
                    width: *width,
                    line_cap: LineCap::Butt,
                    line_join: LineJoin::Round,
                    ..Stroke::default()
                };
                let mut p = paint(*color);
                p.set_color_rgba8(color[0], color[1], color[2], alpha(*opacity));
                pm.stroke_path(&path, &p, &stroke, Transform::identity(), mask.as_ref());
            }
            Item::Fill {
                shape,
                color,
                opacity,
            } => {
                if let Some(path) = path_of(shape) {
                    let mut p = paint(*color);
                    p.set_color_rgba8(color[0], color[1], color[2], alpha(*opacity));
                    pm.fill_path(&path, &p, FillRule::Winding, Transform::identity(), None);
                }
            }
            Item::Text { text, at, style } => font::draw_text(&mut pm, text, at.0, at.1, style),
        }
    }
    pm
}

/// An opacity (0 to 1) as an 8-bit alpha.
fn alpha(opacity: f32) -> u8 {
    (opacity.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn paint(color: Rgb) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(color[0], color[1], color[2], 255);
    p.anti_alias = true;
    p
}

fn path_of(shape: &Shape) -> Option<Path> {
    let mut pb = PathBuilder::new();
    match shape {
        Shape::Circle { centre, radius } => pb.push_circle(centre.0, centre.1, *radius),
        Shape::Path(subpaths) => {
            for s in subpaths {
                let Some((first, rest)) = s.points.split_first() else {
                    continue;
                };
                pb.move_to(first.0, first.1);
                for p in rest {
                    pb.line_to(p.0, p.1);
                }
                if s.closed {
                    pb.close();
                }
            }
        }
    }
    pb.finish()
}
