//! The hemisphere pane: the picked point's hemisphere seen from above, where projected solid
//! angle is area (the Nusselt disk).

use super::sphere_view::{SphereFigure, canvas, picked};
use crate::app::ui::PaneView;
use crate::app::*;

/// Draws the picked point's recording on the Nusselt disk; its layers are the sphere's
/// ([`super::SphereView`]).
#[derive(Default)]
pub struct HemispherePane;

impl PaneView for HemispherePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some((ins, view)) = picked(ui, app) else {
            return;
        };
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
