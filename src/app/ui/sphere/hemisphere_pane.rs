//! The hemisphere pane: the picked point's hemisphere seen from above, where projected solid
//! angle is area (the Nusselt disk).

use super::sphere_view::{SphereFigure, canvas};
use crate::app::ui::{PICK_FIRST, PaneView};
use crate::app::*;

/// Draws the picked point's recording on the Nusselt disk; its layers are the sphere's
/// ([`super::SphereView`]).
#[derive(Default)]
pub struct HemispherePane;

impl PaneView for HemispherePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label(PICK_FIRST);
            return;
        };
        app.subject_rect = Some(ui.max_rect());
        let view = &mut app.settings.sphere;
        view.header_ui(ui, ins);
        // Seen from the normal, orthographically: areas are form factors.
        let (resp, painter) = canvas(ui, "hemisphere seen from the normal", Sense::hover());
        view.paint(
            ui,
            &resp,
            &painter,
            SphereFigure::Hemisphere,
            &ins.probe,
            ins.current(),
        );
    }
}
