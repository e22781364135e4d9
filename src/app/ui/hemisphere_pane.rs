//! The hemisphere pane: the picked point's hemisphere seen from above, where projected solid
//! angle is area (the Nusselt disk).

use super::super::*;
use super::PaneView;
use super::sphere_pane::PICK_FIRST;

/// Draws the picked point's recording on the Nusselt disk; its layers are the sphere's.
#[derive(Default)]
pub struct HemispherePane;

impl PaneView for HemispherePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label(PICK_FIRST);
            return;
        };
        app.subject_rect = Some(ui.max_rect());
        ins.hemisphere_pane(ui, &mut app.settings.sphere);
    }
}
