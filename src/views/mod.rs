//! The debugger's views as figures ([`crate::figure::Figure`]): plain data built from a
//! recording only (a probe, live or read from a dump), so that the command line, and later a
//! Python module, draw what the workbench shows without a window. One function per view.
//!
//! - [`stages`]: the stepper's numbering of a recording (000 Alg. 1, stage by stage).
//! - `plane`: the projected plane of one set difference (000 Alg. 1 line 12).

pub mod labels;
pub mod light;
pub(crate) mod plane;
pub(crate) mod recording_figure;
pub mod sphere;
pub mod stages;

pub use plane::{plane_figure, warp, warped_loop};
pub use recording_figure::{FigureRequest, current_stage, recording_figure};
pub use sphere::figure::{SphereCamera, hemisphere_figure, sphere_figure};

/// Colours for a screen (dark background) or for print (light background, and colours that
/// stay apart in greyscale: the light's region light, the occluder's dark, the answer mid-dark
/// and outlined).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Screen,
    Print,
}

impl Style {
    pub fn from_name(name: &str) -> Option<Style> {
        match name {
            "screen" => Some(Style::Screen),
            "print" => Some(Style::Print),
            _ => None,
        }
    }

    pub(crate) fn background(self) -> [u8; 3] {
        match self {
            Style::Screen => [24, 24, 28],
            Style::Print => [255, 255, 255],
        }
    }

    pub(crate) fn ink(self) -> [u8; 3] {
        match self {
            Style::Screen => [220, 220, 220],
            Style::Print => [30, 30, 30],
        }
    }

    /// A layer's colour as drawn on this style's background: unchanged on screen; in print,
    /// colours too light to read on white (contour edges, escaped rays) darkened.
    pub(crate) fn on_background(self, c: [u8; 3]) -> [u8; 3] {
        let luma = 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
        match self {
            Style::Print if luma > 200.0 => c.map(|v| (v as f32 * 0.45) as u8),
            _ => c,
        }
    }

    pub(crate) fn faint(self) -> [u8; 3] {
        match self {
            Style::Screen => [80, 80, 88],
            Style::Print => [190, 190, 190],
        }
    }
}

/// The light's region (the subject of the difference): yellow, light in greyscale.
pub(crate) const LIGHT: [u8; 3] = [240, 200, 40];
/// The occluder's region (the clip): vermillion, dark in greyscale.
pub(crate) const OCCLUDER: [u8; 3] = [200, 60, 20];
/// What the point sees of the light (the answer): bluish green, outlined.
pub(crate) const VISIBLE: [u8; 3] = [0, 150, 110];
