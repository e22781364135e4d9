//! The projected-plane pane: the set differences of the picked point (000 Sect. 4.3), phase
//! by phase.

use super::super::*;
use super::PaneView;
use super::sphere_pane::PICK_FIRST;

/// Draws the recorded set differences; no state of its own.
#[derive(Default)]
pub struct PlanarPane;

impl PaneView for PlanarPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label(PICK_FIRST);
            return;
        };
        app.subject_rect = Some(ui.max_rect());
        ins.planar_pane(ui);
    }
}
