//! egui's back end of a [`Figure`]: the workbench paints the same description the command
//! line writes as SVG, PDF or PNG, so that what a pane shows is what its export holds. Fills
//! of any polygon (non-convex, with holes, nonzero rule) are tessellated by lyon into one
//! egui mesh each; strokes, circles and labels are egui shapes.

use crate::figure::font::{Align, TextStyle};
use crate::figure::{Figure, Item, Rgb, Shape};
use egui::{Color32, Painter, Pos2, Rect, Stroke};
use lyon_tessellation::math::point;
use lyon_tessellation::path::Path;
use lyon_tessellation::{BuffersBuilder, FillOptions, FillRule, FillTessellator, VertexBuffers};

/// How the figure's pixels land in a rectangle of the screen (uniform scale from its corner).
#[derive(Clone, Copy, Debug)]
pub struct FigureRect {
    pub origin: Pos2,
    /// Points per figure pixel.
    pub scale: f32,
}

impl FigureRect {
    /// The figure drawn to fill `rect`'s width.
    pub(crate) fn fit(figure: &Figure, rect: Rect) -> Self {
        FigureRect {
            origin: rect.min,
            scale: rect.width() / figure.width.max(1) as f32,
        }
    }

    pub fn to_screen(&self, p: (f32, f32)) -> Pos2 {
        Pos2::new(
            self.origin.x + p.0 * self.scale,
            self.origin.y + p.1 * self.scale,
        )
    }
}

fn colour(c: Rgb, opacity: f32) -> Color32 {
    Color32::from_rgba_unmultiplied(c[0], c[1], c[2], (opacity.clamp(0.0, 1.0) * 255.0) as u8)
}

/// Paints `figure` (background included) with its pixel (0, 0) at `at.origin`.
pub fn paint(painter: &Painter, figure: &Figure, at: FigureRect) {
    let rect = Rect::from_min_max(
        at.to_screen((0.0, 0.0)),
        at.to_screen((figure.width as f32, figure.height as f32)),
    );
    painter.rect_filled(rect, 0.0, colour(figure.background, 1.0));
    let mut tess = FillTessellator::new();
    for item in &figure.items {
        match item {
            Item::Fill {
                shape,
                color,
                opacity,
            } => fill(painter, &mut tess, shape, colour(*color, *opacity), at),
            Item::Stroke {
                shape,
                color,
                width,
                opacity,
                clip,
            } => {
                let painter = match clip {
                    Some([l, t, r, b]) => painter.with_clip_rect(
                        Rect::from_min_max(at.to_screen((*l, *t)), at.to_screen((*r, *b)))
                            .intersect(painter.clip_rect()),
                    ),
                    None => painter.clone(),
                };
                let stroke = Stroke::new(width * at.scale, colour(*color, *opacity));
                match shape {
                    Shape::Circle { centre, radius } => {
                        painter.circle_stroke(at.to_screen(*centre), radius * at.scale, stroke);
                    }
                    Shape::Path(subpaths) => {
                        for sp in subpaths.iter().filter(|s| s.points.len() >= 2) {
                            let pts: Vec<Pos2> =
                                sp.points.iter().map(|p| at.to_screen(*p)).collect();
                            painter.add(if sp.closed {
                                egui::Shape::closed_line(pts, stroke)
                            } else {
                                egui::Shape::line(pts, stroke)
                            });
                        }
                    }
                }
            }
            Item::Text {
                text,
                at: pos,
                style,
            } => label(painter, text, *pos, style, at),
        }
    }
}

/// A filled shape: a circle as egui's, a path tessellated (nonzero rule).
fn fill(painter: &Painter, tess: &mut FillTessellator, shape: &Shape, c: Color32, at: FigureRect) {
    let subpaths = match shape {
        Shape::Circle { centre, radius } => {
            painter.circle_filled(at.to_screen(*centre), radius * at.scale, c);
            return;
        }
        Shape::Path(s) => s,
    };
    let mut b = Path::builder();
    for sp in subpaths.iter().filter(|s| s.points.len() >= 3) {
        let q = at.to_screen(sp.points[0]);
        b.begin(point(q.x, q.y));
        for p in &sp.points[1..] {
            let q = at.to_screen(*p);
            b.line_to(point(q.x, q.y));
        }
        b.end(true);
    }
    let path = b.build();
    let mut out: VertexBuffers<Pos2, u32> = VertexBuffers::new();
    let options = FillOptions::default()
        .with_fill_rule(FillRule::NonZero)
        .with_tolerance(0.05);
    let built = tess.tessellate_path(
        &path,
        &options,
        &mut BuffersBuilder::new(&mut out, |v: lyon_tessellation::FillVertex| {
            let p = v.position();
            Pos2::new(p.x, p.y)
        }),
    );
    // A polygon lyon cannot tessellate (degenerate input) is left unfilled; its outline is
    // still drawn by the stroke that follows every region.
    if built.is_err() || out.indices.is_empty() {
        return;
    }
    let mut mesh = egui::Mesh::default();
    for p in out.vertices {
        mesh.colored_vertex(p, c);
    }
    mesh.indices = out.indices;
    painter.add(egui::Shape::mesh(mesh));
}

/// A label with its baseline through `pos`, in egui's proportional face (the raster back
/// end's, so the figure's label metrics hold).
fn label(painter: &Painter, text: &str, pos: (f32, f32), style: &TextStyle, at: FigureRect) {
    let size = style.size * at.scale;
    let font = egui::FontId::proportional(size);
    let c = colour(style.color, 1.0);
    let galley = painter.layout_no_wrap(text.to_string(), font, c);
    let w = galley.size().x;
    let dx = match style.align {
        Align::Left => 0.0,
        Align::Center => -0.5 * w,
        Align::Right => -w,
    };
    // The galley's top left, from the baseline: one row's ascent above it.
    let ascent = galley
        .rows
        .first()
        .map_or(0.8 * size, |r| r.row.height() * 0.8);
    let angle = style.rotate.to_radians();
    let anchor = at.to_screen(pos);
    let (sin, cos) = angle.sin_cos();
    let (ox, oy) = (dx, -ascent);
    let top_left = Pos2::new(
        anchor.x + ox * cos - oy * sin,
        anchor.y + ox * sin + oy * cos,
    );
    painter.add(egui::epaint::TextShape::new(top_left, galley, c).with_angle(angle));
}
