//! The projection plane of 000 (Alg. 1 lines 6–12) at the picked point: the light polygon
//! before a set difference, the occluder, the result, and the Greiner–Hormann phases one at a
//! time — all read from the recording. Homogeneous vertices (x, y, w) are drawn at (x/w, y/w);
//! points at infinity (horizon vertices, w = 0) are drawn far out along their direction.

use super::sphere_view::colours;
use crate::geometry::PlanarPolygon;
use crate::geometry::set_difference::{GreinerHormannSteps, Operand, Transition};
use crate::shading::SetDifferenceRecord;
use crate::views::stages::GhPhase;
use crate::views::{self, warp};
use egui::{Color32, Ui};
use egui_plot::{Legend, Line, MarkerShape, Plot, PlotPoint, PlotPoints, Points, Text};
use glam::DVec3;

/// Points along the segment a→b of the plane, warped ([`views::warp`]); `a` included.
fn segment(a: DVec3, b: DVec3, out: &mut Vec<[f64; 2]>) {
    out.extend(views::warped_loop(&[a, b]).into_iter().take(24));
}

fn loop_lines(poly: &PlanarPolygon, name: &str, colour: Color32, width: f32) -> Vec<Line<'static>> {
    poly.loops()
        .map(|lp| {
            let mut pts = views::warped_loop(lp);
            if let Some(&first) = pts.first() {
                pts.push(first);
            }
            Line::new(name.to_string(), PlotPoints::from(pts))
                .color(colour)
                .width(width)
        })
        .collect()
}

/// Draws one recorded set difference, or one of its GH phases.
pub fn planar_ui(
    ui: &mut Ui,
    sd: &SetDifferenceRecord,
    occluder: &str,
    phase: Option<GhPhase>,
    width: f32,
) {
    let steps: Option<&GreinerHormannSteps> = sd.steps.as_ref();
    ui.small("The projection plane, compressed radially (q -> q/(1+|q|)): the rim is the horizon.");
    Plot::new("planar_view")
        .data_aspect(1.0)
        .width(width.max(200.0))
        .legend(Legend::default())
        .height(ui.available_height().max(200.0))
        .show(ui, |plot| {
            for l in loop_lines(&sd.before, "light (subject)", colours::LIGHT_CLIPPED, 2.0) {
                plot.line(l);
            }
            for l in loop_lines(
                &sd.clip,
                &format!("occluder {occluder} (clip)"),
                colours::OCCLUDER,
                2.0,
            ) {
                plot.line(l);
            }
            let show_result = phase.is_none() || phase == Some(GhPhase::Traversal);
            if show_result {
                for l in loop_lines(&sd.after, "result", colours::VISIBLE, 3.5) {
                    plot.line(l);
                }
            }
            let Some(st) = steps else {
                return;
            };
            match phase {
                Some(GhPhase::Intersections) | None => {
                    let pts: Vec<[f64; 2]> =
                        st.intersections.iter().map(|i| warp(i.position)).collect();
                    plot.points(
                        Points::new("intersections", PlotPoints::from(pts))
                            .shape(MarkerShape::Circle)
                            .radius(5.0)
                            .color(Color32::WHITE),
                    );
                    for (k, i) in st.intersections.iter().enumerate() {
                        let [x, y] = warp(i.position);
                        plot.text(Text::new(
                            "intersections",
                            PlotPoint::new(x, y),
                            format!("  {k}: {:?}", i.kind),
                        ));
                    }
                }
                Some(GhPhase::Labels) => {
                    for (name, want, shape, colour) in [
                        (
                            "entry",
                            Some(Transition::Entry),
                            MarkerShape::Up,
                            Color32::LIGHT_GREEN,
                        ),
                        (
                            "exit",
                            Some(Transition::Exit),
                            MarkerShape::Down,
                            Color32::LIGHT_RED,
                        ),
                        ("no transition", None, MarkerShape::Diamond, Color32::GRAY),
                    ] {
                        let pts: Vec<[f64; 2]> = st
                            .labels
                            .iter()
                            .filter(|l| l.transition == want)
                            .map(|l| warp(l.position))
                            .collect();
                        plot.points(
                            Points::new(name, PlotPoints::from(pts))
                                .shape(shape)
                                .radius(6.0)
                                .color(colour),
                        );
                    }
                    for l in &st.labels {
                        let [x, y] = warp(l.position);
                        let side = match l.operand {
                            Operand::Subject => "S",
                            Operand::Clip => "C",
                        };
                        plot.text(Text::new(
                            "labels",
                            PlotPoint::new(x, y),
                            format!("  {side}{}: {:?}", l.edge, l.label),
                        ));
                    }
                }
                Some(GhPhase::Traversal) => {
                    for (k, lp) in st.traversal.iter().enumerate() {
                        for (j, s) in lp.steps.iter().enumerate() {
                            let mut pts = Vec::new();
                            segment(s.from, s.to, &mut pts);
                            pts.push(warp(s.to));
                            let (a, b) = (pts[0], pts[pts.len() - 1]);
                            let colour = match s.operand {
                                Operand::Subject => colours::LIGHT,
                                Operand::Clip => colours::OCCLUDER_CLIPPED,
                            };
                            plot.line(
                                Line::new(format!("output loop {k}"), PlotPoints::from(pts))
                                    .color(colour)
                                    .width(4.0),
                            );
                            let mid = PlotPoint::new(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]));
                            plot.text(Text::new(
                                format!("output loop {k}"),
                                mid,
                                format!("{k}.{j}"),
                            ));
                        }
                    }
                }
            }
        });
}
