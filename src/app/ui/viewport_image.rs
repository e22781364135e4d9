//! The workbench's the viewport's image, picking and gizmos.

use super::super::*;

impl WorkbenchApp {
    pub(in crate::app) fn viewport_image_ui(&mut self, ui: &mut Ui, avail: egui::Vec2) {
        let ppp = ui.ctx().pixels_per_point();
        let scale = self.state.resolution.clamp(0.1, 1.0) * ppp;
        let size = (
            ((avail.x * scale) as u32).clamp(16, 4096),
            ((avail.y * scale) as u32).clamp(16, 4096),
        );
        self.render_size = size;
        let (resp, painter) = ui.allocate_painter(avail, Sense::click_and_drag());
        resp.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::Canvas, true, "viewport: click to pick a pixel")
        });
        let rect = resp.rect;
        self.viewport_rect = Some(rect);
        if let Some(t) = &self.texture {
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
        if let Some(ctx) = self.ctx.clone() {
            let edit = self
                .editor
                .viewport_input(ui, &resp, &painter, &ctx, &self.orbit.camera());
            on_gizmo = edit.consumed;
            if let Some(moved) = edit.moved {
                self.scene_moved(moved);
            }
            if resp.double_clicked()
                && let Some(pos) = resp.interact_pointer_pos()
            {
                let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
                let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
                let hit =
                    scene_edit::SceneEditor::object_at(&ctx, &self.orbit.camera(), size, x, y);
                self.editor.selected = hit;
                if let Some(i) = hit {
                    self.status = format!(
                        "selected {}: drag its arrows or ring to move it",
                        ctx.scene.objects[i].name
                    );
                }
            }
        }
        // Camera.
        if !on_gizmo && resp.dragged_by(egui::PointerButton::Primary) {
            let d = resp.drag_delta();
            self.orbit.orbit(d.x as f64, d.y as f64);
        }
        if resp.dragged_by(egui::PointerButton::Secondary)
            || resp.dragged_by(egui::PointerButton::Middle)
        {
            let d = resp.drag_delta();
            self.orbit.pan(d.x as f64, d.y as f64, rect.height() as f64);
        }
        if resp.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.orbit.zoom(scroll as f64 / 40.0);
            }
        }
        if resp.clicked()
            && !on_gizmo
            && let Some(pos) = resp.interact_pointer_pos()
        {
            let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
            let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
            self.pick(x, y);
        }
        // Mark the picked pixel.
        if let Some(ins) = &self.inspector
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
}
