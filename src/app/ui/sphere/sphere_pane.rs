//! The sphere pane: the unit sphere at the picked point in 3-D, with every recorded stage.

use super::sphere_view::{SphereFigure, SphereView, canvas, picked};
use crate::app::ui::PaneView;
use crate::app::*;
use crate::inspect::Probe;
use crate::views::stages::Step;

/// The unit sphere at the picked point; its camera and layers are settings kept between
/// sessions ([`SphereView`], shared with the hemisphere). The app remembers where it was drawn
/// (what a screenshot or a lesson frame crops to).
#[derive(Default)]
pub struct SpherePane;

impl PaneView for SpherePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some((ins, view)) = picked(ui, app) else {
            return;
        };
        sphere_ui(ui, view, &ins.probe, ins.current());
        app.sphere_rect = Some(ui.min_rect());
    }
}

/// The rotatable 3D unit sphere, as large as the space given (drag to rotate, scroll to zoom,
/// double-click to frame the lights again), the current step's polygons on it.
fn sphere_ui(ui: &mut Ui, view: &mut SphereView, probe: &Probe, step: Option<&Step>) {
    let (resp, painter) = canvas(ui, "unit sphere (drag to rotate)", Sense::click_and_drag());
    let mut camera = view.camera_for(probe, step);
    if resp.dragged() {
        let d = resp.drag_delta();
        camera.yaw -= d.x * 0.01;
        camera.pitch = (camera.pitch + d.y * 0.01).clamp(-1.5, 1.5);
        view.camera = Some(camera);
    }
    if resp.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom = (camera.zoom * (scroll * 0.003).exp()).clamp(0.5, 50.0);
            view.camera = Some(camera);
        }
    }
    if resp.double_clicked() {
        view.camera = None;
    }
    view.sphere_side = resp.rect.width();
    view.paint(ui, &resp, &painter, SphereFigure::Sphere, probe, step);
}
