//! The projected plane of one set difference (000 Alg. 1 line 12): the light's region, the
//! occluder's and what is left, in the plane the occluder was projected to.

use super::labels::LabelPlacer;
use super::sphere::colours;
use super::stages::GhPhase;
use super::{LIGHT, OCCLUDER, Style, VISIBLE};
use crate::figure::font::{self, Align, TextStyle};
use crate::figure::{Figure, Item, Shape, Subpath};
use crate::geometry::PlanarPolygon;
use crate::geometry::spherical::set_difference::{Operand, Transition};
use crate::shading::SetDifferenceRecord;
use glam::DVec3;

/// Where a homogeneous point (x, y, w), w ≥ 0, of the projection plane is drawn: the plane
/// point q = (x/w, y/w) compressed radially to q / (1 + |q|), i.e. (x, y) / (w + |(x, y)|). The
/// whole plane fits in the unit disk, points at infinity (horizon vertices, w = 0) land on its
/// rim, and the map is one-to-one, so crossings, containment and orientation read exactly as
/// in the plane.
pub fn warp(p: DVec3) -> [f64; 2] {
    let d = p.x.hypot(p.y);
    let den = p.z.abs() + d;
    if den > 0.0 {
        [p.x / den, p.y / den]
    } else {
        [0.0, 0.0]
    }
}

/// The warped loop of a polygon: each projective edge a→b (the convex combination of the
/// homogeneous vectors) sampled at 24 points, so that edges through infinity bend as they do
/// in the disk.
pub fn warped_loop(lp: &[DVec3]) -> Vec<[f64; 2]> {
    let n = 24;
    let mut out = Vec::with_capacity(n * lp.len());
    for k in 0..lp.len() {
        let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
        for i in 0..n {
            let t = i as f64 / n as f64;
            out.push(warp(a * (1.0 - t) + b * t));
        }
    }
    out
}

/// The projected plane of one recorded set difference, `size` pixels square: the light's
/// region before it, the occluder's, and what is left (the visible region, the answer),
/// translucent so that overlaps show, with a legend and a title naming the occluder. The
/// plane is drawn in the warped disk of [`warp`] (its rim is the horizon), framed on the
/// light's and the occluder's regions. With a Greiner–Hormann `phase` (when the recording
/// kept the steps): the intersections found (phase 1), the entry and exit labels (phase 2), or
/// the traversal's output edges in order (phase 3); the answer is shown from phase 3 on.
pub fn plane_figure(
    sd: &SetDifferenceRecord,
    occluder: &str,
    phase: Option<GhPhase>,
    size: u32,
    style: Style,
) -> Figure {
    let size = size.clamp(64, 8192);
    let mut fig = Figure::new(size, size, style.background());
    let s = size as f32;
    // The plot area under the title and legend; framed on the light's region and the
    // occluder's (the region of interest), not on the whole disk.
    let plot = [0.04 * s, 0.14 * s, 0.96 * s, 0.96 * s];
    let warped = |poly: &PlanarPolygon| -> Vec<Vec<[f64; 2]>> {
        poly.loops()
            .filter(|lp| lp.len() >= 3)
            .map(warped_loop)
            .collect()
    };
    let (before, clip, after) = (warped(&sd.before), warped(&sd.clip), warped(&sd.after));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in before.iter().chain(&clip).flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9) * 1.15;
    let side = (plot[2] - plot[0]).min(plot[3] - plot[1]);
    let scale = side as f64 / extent;
    let centre = (0.5 * (plot[0] + plot[2]), 0.5 * (plot[1] + plot[3]));
    let to_px = |q: [f64; 2]| {
        (
            centre.0 + ((q[0] - mid[0]) * scale) as f32,
            centre.1 - ((q[1] - mid[1]) * scale) as f32,
        )
    };
    let shape = |loops: &[Vec<[f64; 2]>]| {
        Shape::Path(
            loops
                .iter()
                .map(|lp| Subpath {
                    points: lp.iter().copied().map(to_px).collect(),
                    closed: true,
                })
                .collect(),
        )
    };
    // The horizon (the disk's rim) and the axes, where they cross the frame.
    let origin = to_px([0.0, 0.0]);
    let r = scale as f32;
    let guides = [
        Shape::Circle {
            centre: origin,
            radius: r,
        },
        Shape::segment((origin.0 - r, origin.1), (origin.0 + r, origin.1)),
        Shape::segment((origin.0, origin.1 - r), (origin.0, origin.1 + r)),
    ];
    for g in guides {
        fig.items.push(Item::Stroke {
            shape: g,
            color: style.faint(),
            width: 1.0,
            opacity: 1.0,
            clip: Some(plot),
        });
    }
    fig.stroke(Shape::rect(plot), style.faint(), 1.0);
    // Regions: the light, the occluder over it, the visible part over both.
    let show_result = phase.is_none() || phase == Some(GhPhase::Traversal);
    fig.translucent(shape(&before), LIGHT, 0.35);
    fig.translucent(shape(&clip), OCCLUDER, 0.35);
    if show_result {
        fig.translucent(shape(&after), VISIBLE, 0.55);
    }
    fig.stroke(shape(&before), LIGHT, 1.5);
    fig.stroke(shape(&clip), OCCLUDER, 1.5);
    if show_result {
        fig.stroke(shape(&after), VISIBLE, 2.5);
    }
    // The phase's marks, labelled without overlap (the legend and title kept clear).
    let small = 0.022 * s;
    let mut placer = LabelPlacer::new([0.0, 0.0, s, s]);
    placer.block([0.0, 0.0, s, 0.13 * s]);
    let ink = style.ink();
    let mut label = |fig: &mut Figure, text: &str, at: (f32, f32), colour: [u8; 3]| {
        if let Some(p) = placer.place(text, at, small, 4.0) {
            fig.text(text, p.at, TextStyle::new(small, colour));
        }
    };
    let px = |p: DVec3| to_px(warp(p));
    match (phase, &sd.steps) {
        (Some(GhPhase::Intersections), Some(st)) => {
            for (k, i) in st.intersections.iter().enumerate() {
                let q = px(i.position);
                fig.stroke(
                    Shape::Circle {
                        centre: q,
                        radius: 5.0,
                    },
                    ink,
                    1.5,
                );
                label(&mut fig, &format!("{k}: {:?}", i.kind), q, ink);
            }
        }
        (Some(GhPhase::Labels), Some(st)) => {
            for l in &st.labels {
                let q = px(l.position);
                // Up triangle: entry; down: exit; diamond: no transition.
                let (colour, pts) = match l.transition {
                    Some(Transition::Entry) => (
                        VISIBLE,
                        vec![
                            (q.0, q.1 - 6.0),
                            (q.0 + 6.0, q.1 + 5.0),
                            (q.0 - 6.0, q.1 + 5.0),
                        ],
                    ),
                    Some(Transition::Exit) => (
                        OCCLUDER,
                        vec![
                            (q.0, q.1 + 6.0),
                            (q.0 + 6.0, q.1 - 5.0),
                            (q.0 - 6.0, q.1 - 5.0),
                        ],
                    ),
                    None => (
                        style.faint(),
                        vec![
                            (q.0, q.1 - 6.0),
                            (q.0 + 6.0, q.1),
                            (q.0, q.1 + 6.0),
                            (q.0 - 6.0, q.1),
                        ],
                    ),
                };
                fig.fill(
                    Shape::Path(vec![Subpath {
                        points: pts,
                        closed: true,
                    }]),
                    colour,
                );
                let side = match l.operand {
                    Operand::Subject => "S",
                    Operand::Clip => "C",
                };
                let transition = match l.transition {
                    Some(Transition::Entry) => ", entry",
                    Some(Transition::Exit) => ", exit",
                    None => "",
                };
                let text = format!("{side}{}: {:?}{transition}", l.edge, l.label);
                label(&mut fig, &text, q, ink);
            }
        }
        (Some(GhPhase::Traversal), Some(st)) => {
            for (k, lp) in st.traversal.iter().enumerate() {
                for (j, step) in lp.steps.iter().enumerate() {
                    let colour = match step.operand {
                        Operand::Subject => colours::LIGHT,
                        Operand::Clip => colours::OCCLUDER_CLIPPED,
                    };
                    let pts: Vec<(f32, f32)> = warped_loop(&[step.from, step.to])
                        .into_iter()
                        // The edge a→b (the loop's first half), then b itself.
                        .take(24)
                        .map(to_px)
                        .chain(std::iter::once(px(step.to)))
                        .collect();
                    let mid = pts[pts.len() / 2];
                    fig.stroke(
                        Shape::Path(vec![Subpath {
                            points: pts,
                            closed: false,
                        }]),
                        colour,
                        4.0,
                    );
                    label(&mut fig, &format!("{k}.{j}"), mid, ink);
                }
            }
        }
        _ => {}
    }
    // Title (shrunk to fit) and legend.
    let title = match phase {
        None => format!("light minus occluder {occluder}: what the point sees"),
        Some(GhPhase::Intersections) => format!("minus {occluder}, GH phase 1: intersections"),
        Some(GhPhase::Labels) => format!("minus {occluder}, GH phase 2: entry and exit labels"),
        Some(GhPhase::Traversal) => format!("minus {occluder}, GH phase 3: traversal"),
    };
    let mut size_t = 0.03 * s;
    while size_t > 6.0 && font::text_width(&title, size_t) > 0.92 * s {
        size_t *= 0.9;
    }
    fig.text(
        &title,
        (0.5 * s, 0.05 * s),
        TextStyle::new(size_t, style.ink()).align(Align::Center),
    );
    let entries = [
        (LIGHT, 0.35, "light (before)"),
        (OCCLUDER, 0.35, "occluder"),
        (VISIBLE, 0.55, "visible (after)"),
    ];
    let small = TextStyle::new(0.024 * s, style.ink());
    for (k, (colour, opacity, label)) in entries.iter().enumerate() {
        let x = 0.04 * s + k as f32 * 0.32 * s;
        let y = 0.1 * s;
        let swatch = [x, y - 0.02 * s, x + 0.03 * s, y + 0.005 * s];
        fig.translucent(Shape::rect(swatch), *colour, *opacity);
        fig.stroke(Shape::rect(swatch), *colour, 1.0);
        fig.text(label, (x + 0.04 * s, y), small);
    }
    fig
}
