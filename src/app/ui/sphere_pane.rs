//! The sphere pane: the unit sphere at the picked point in 3-D, with every recorded stage.

use super::super::*;
use super::PaneView;

/// What a pane of the picked point says before a pick.
pub(super) const PICK_FIRST: &str = "Click a pixel of the viewport to see its shading point here.";

/// The unit sphere at the picked point (`Inspector::sphere_pane`); its camera and layers are
/// settings kept between sessions. It remembers where it was drawn (what a screenshot or a
/// lesson frame crops to).
#[derive(Default)]
pub struct SpherePane;

impl PaneView for SpherePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label(PICK_FIRST);
            return;
        };
        app.subject_rect = Some(ui.max_rect());
        ins.sphere_pane(ui, &mut app.settings.sphere);
        app.sphere_rect = Some(ui.min_rect());
    }
}
