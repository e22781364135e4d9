//! A figure as plain data: what is drawn, in drawing order, in pixel coordinates (y down),
//! independent of what draws it. The raster back end ([`super::raster`]) and the SVG writer
//! ([`super::svg`]) take the same description, so that a PNG and an SVG of one figure cannot
//! disagree on what is in it.

use super::font::TextStyle;

/// An 8-bit sRGB colour.
pub type Rgb = [u8; 3];

/// A figure: its size in pixels, its background and its items, drawn in order.
#[derive(Clone, Debug)]
pub struct Figure {
    pub width: u32,
    pub height: u32,
    pub background: Rgb,
    pub items: Vec<Item>,
}

/// The outline of something drawn: subpaths of straight segments (each open or closed), or a
/// circle.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Path(Vec<Subpath>),
    Circle { centre: (f32, f32), radius: f32 },
}

/// Points joined by straight segments; `closed` joins the last to the first.
#[derive(Clone, Debug, PartialEq)]
pub struct Subpath {
    pub points: Vec<(f32, f32)>,
    pub closed: bool,
}

/// A rectangle (left, top, right, bottom) in pixels.
pub type Rect = [f32; 4];

/// One thing drawn.
#[derive(Clone, Debug)]
pub enum Item {
    /// The shape's outline: butt caps, round joins.
    Stroke {
        shape: Shape,
        color: Rgb,
        width: f32,
        /// 1 for opaque; less for what is faded (earlier stages, the far side of a sphere).
        opacity: f32,
        /// Drawn only inside this rectangle.
        clip: Option<Rect>,
    },
    /// The shape's inside (nonzero winding), `opacity` 1 for opaque.
    Fill {
        shape: Shape,
        color: Rgb,
        opacity: f32,
    },
    /// A label with its baseline through `at` (`super::font::draw_text`'s anchor).
    Text {
        text: String,
        at: (f32, f32),
        style: TextStyle,
    },
}

impl Shape {
    /// The segment from `a` to `b`.
    pub(crate) fn segment(a: (f32, f32), b: (f32, f32)) -> Shape {
        Shape::Path(vec![Subpath {
            points: vec![a, b],
            closed: false,
        }])
    }

    /// The rectangle's outline.
    pub(crate) fn rect([l, t, r, b]: Rect) -> Shape {
        Shape::Path(vec![Subpath {
            points: vec![(l, t), (r, t), (r, b), (l, b)],
            closed: true,
        }])
    }
}

impl Figure {
    /// An empty figure.
    pub fn new(width: u32, height: u32, background: Rgb) -> Self {
        Figure {
            width,
            height,
            background,
            items: Vec::new(),
        }
    }

    pub(crate) fn stroke(&mut self, shape: Shape, color: Rgb, width: f32) {
        self.faded_stroke(shape, color, width, 1.0);
    }

    /// A stroke of `opacity` (0 to 1).
    pub(crate) fn faded_stroke(&mut self, shape: Shape, color: Rgb, width: f32, opacity: f32) {
        self.items.push(Item::Stroke {
            shape,
            color,
            width,
            opacity,
            clip: None,
        });
    }

    pub(crate) fn fill(&mut self, shape: Shape, color: Rgb) {
        self.translucent(shape, color, 1.0);
    }

    /// A fill of `opacity` (0 to 1): regions that overlap show through each other.
    pub(crate) fn translucent(&mut self, shape: Shape, color: Rgb, opacity: f32) {
        self.items.push(Item::Fill {
            shape,
            color,
            opacity,
        });
    }

    pub(crate) fn text(&mut self, text: &str, at: (f32, f32), style: TextStyle) {
        self.items.push(Item::Text {
            text: text.to_string(),
            at,
            style,
        });
    }
}
