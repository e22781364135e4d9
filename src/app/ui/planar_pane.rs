//! The projected-plane pane: the set differences of the picked point (000 Sect. 4.3), phase
//! by phase.

use super::super::*;
use super::{PICK_FIRST, PaneView};
use crate::shading::SetDifferenceRecord;
use crate::views::stages::{GhPhase, plane_subject};
use crate::views::{Style, plane_figure};
use figure_painter::FigureRect;

/// Draws the recorded set differences; no state of its own (the step shown is the
/// inspector's).
#[derive(Default)]
pub struct PlanarPane;

impl PaneView for PlanarPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label(PICK_FIRST);
            return;
        };
        app.subject_rect = Some(ui.max_rect());
        if subject(ins).is_none() {
            ui.label("No occluder is subtracted at this point (Alg. 1 line 12 does not run).");
            return;
        }
        ui.small(
            "The projection plane, compressed radially (q -> q/(1+|q|)): the rim is the horizon.",
        );
        let style = if ui.visuals().dark_mode {
            Style::Screen
        } else {
            Style::Print
        };
        let avail = ui.available_size();
        let side = avail.x.min(avail.y).max(160.0);
        let (rect, _) = ui.allocate_exact_size(egui::Vec2::splat(side), egui::Sense::hover());
        if let Some(fig) = PlanarPane::figure(ins, side.round() as u32, style) {
            figure_painter::paint(ui.painter(), &fig, FigureRect::fit(&fig, rect));
        }
    }
}

impl PlanarPane {
    /// The projected plane of the set difference at the inspector's step (the last one
    /// before it, or the first), `side` pixels square; `None` when no occluder is subtracted.
    /// What the pane paints and Export ▸ Figure writes.
    pub(crate) fn figure(
        ins: &Inspector,
        side: u32,
        style: Style,
    ) -> Option<crate::figure::Figure> {
        let (sd, phase) = subject(ins)?;
        let name = ins
            .probe
            .occluder_names
            .get(sd.occluder)
            .cloned()
            .unwrap_or_default();
        Some(plane_figure(sd, &name, phase, side, style))
    }
}

/// The set difference the pane shows: the current step's, else the last one at or before the
/// current step, else the first one recorded; with the GH phase stepped.
fn subject(ins: &Inspector) -> Option<(&SetDifferenceRecord, Option<GhPhase>)> {
    plane_subject(&ins.probe, &ins.steps, ins.step)
}
