//! The viewport pane: the rendered image, kept at the image's aspect in any tile; clicks pick a
//! pixel, double-clicks select an object, drags orbit and pan, and the selected object's
//! handles move it.

use super::super::*;
use super::PaneView;

/// Draws the frame the render thread delivered (`AppState::update_texture`); no state of its
/// own.
#[derive(Default)]
pub struct ViewportPane;

impl PaneView for ViewportPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        // The image keeps its aspect in any tile: the largest rectangle of that aspect,
        // centred, so that resizing a tile never stretches the camera.
        let full = ui.available_size();
        let aspect = app.settings.aspect;
        let avail = if aspect > 0.0 {
            let w = full.x.min(full.y * aspect);
            egui::vec2(w, w / aspect)
        } else {
            full
        };
        let pad = (full - avail) * 0.5;
        ui.add_space(pad.y.max(0.0));
        ui.horizontal(|ui| {
            ui.add_space(pad.x.max(0.0));
            image_ui(ui, app, avail);
        });
    }
}

/// The image in `avail` points, and the pointer on it.
fn image_ui(ui: &mut Ui, app: &mut AppState, avail: egui::Vec2) {
    let ppp = ui.ctx().pixels_per_point();
    let scale = app.settings.resolution.clamp(0.1, 1.0) * ppp;
    let size = (
        ((avail.x * scale) as u32).clamp(16, 4096),
        ((avail.y * scale) as u32).clamp(16, 4096),
    );
    app.render_size = size;
    let (resp, painter) = ui.allocate_painter(avail, Sense::click_and_drag());
    resp.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::Canvas, true, "viewport: click to pick a pixel")
    });
    let rect = resp.rect;
    app.viewport_rect = Some(rect);
    if let Some(t) = &app.texture {
        painter.image(
            t.id(),
            rect,
            egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            Color32::WHITE,
        );
    } else {
        painter.rect_filled(rect, 0.0, Color32::BLACK);
    }
    // The selected object's handles take the pointer first.
    let mut on_gizmo = false;
    if let Some(ctx) = app.ctx.clone() {
        let edit = app
            .editor
            .viewport_input(ui, &resp, &painter, &ctx, &app.orbit.camera());
        on_gizmo = edit.consumed;
        if let Some(moved) = edit.moved {
            app.scene_moved(moved);
        }
        if resp.double_clicked()
            && let Some(pos) = resp.interact_pointer_pos()
        {
            let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
            let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
            let hit = scene_edit::SceneEditor::object_at(&ctx, &app.orbit.camera(), size, x, y);
            app.editor.selected = hit;
            if let Some(i) = hit {
                app.status = format!(
                    "selected {}: drag its arrows or ring to move it",
                    ctx.scene.objects[i].name
                );
            }
        }
    }
    // Camera.
    if !on_gizmo && resp.dragged_by(egui::PointerButton::Primary) {
        let d = resp.drag_delta();
        app.orbit.orbit(d.x as f64, d.y as f64);
    }
    if resp.dragged_by(egui::PointerButton::Secondary)
        || resp.dragged_by(egui::PointerButton::Middle)
    {
        let d = resp.drag_delta();
        app.orbit.pan(d.x as f64, d.y as f64, rect.height() as f64);
    }
    if resp.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            app.orbit.zoom(scroll as f64 / 40.0);
        }
    }
    if resp.clicked()
        && !on_gizmo
        && let Some(pos) = resp.interact_pointer_pos()
    {
        let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
        let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
        app.pick(x, y);
    }
    // Mark the picked pixel.
    if let Some(ins) = &app.inspector
        && ins.probe.size == size
    {
        let (px, py) = ins.probe.pixel;
        let p = egui::pos2(
            rect.min.x + ((px as f32 + 0.5) / size.0 as f32) * rect.width(),
            rect.min.y + ((py as f32 + 0.5) / size.1 as f32) * rect.height(),
        );
        painter.circle_stroke(
            p,
            6.0,
            egui::Stroke::new(2.0, Color32::from_rgb(255, 0, 255)),
        );
    }
}
