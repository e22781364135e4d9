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
    if app.settings.aov == Aov::Derivative {
        derivative_overlay(app, &painter, rect);
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

/// What the derivative AOV says over the image: "d/d<axis> of <object>" and a colour bar of
/// its diverging map with the scale (±the 99th percentile of its magnitude, per scene unit or
/// per radian; masked pixels grey), or, where there is no derivative to show, why (no object
/// selected, a method or an environment it does not cover) over the dimmed image.
fn derivative_overlay(app: &AppState, painter: &egui::Painter, rect: egui::Rect) {
    let font = egui::FontId::proportional(13.0);
    let motion = match app.derivative_motion() {
        Ok(Some(m)) => m,
        Ok(None) => return,
        Err(why) => {
            painter.rect_filled(rect, 0.0, Color32::from_black_alpha(200));
            let galley = painter.layout(
                why,
                egui::FontId::proportional(15.0),
                Color32::WHITE,
                (rect.width() - 40.0).max(60.0),
            );
            let at = rect.center() - galley.size() * 0.5;
            painter.galley(at, galley, Color32::WHITE);
            return;
        }
    };
    let label = app.derivative_label(&motion);
    let frame = app.worker.latest();
    let derivative = frame
        .as_ref()
        .and_then(|f| f.frame.output.derivative.as_ref())
        .filter(|d| d.motion == motion);
    let unit = match motion.axis {
        crate::shading::derivative::Axis::Ry => "rad",
        _ => "unit",
    };
    let text = match derivative {
        Some(d) => format!("{label} (per {unit}), {} pixels masked", d.masked.pixels),
        None => format!("{label}: rendering…"),
    };
    let galley = painter.layout_no_wrap(text, font.clone(), Color32::WHITE);
    let at = rect.min + egui::vec2(8.0, 8.0);
    painter.rect_filled(
        egui::Rect::from_min_size(at, galley.size()).expand(4.0),
        3.0,
        Color32::from_black_alpha(170),
    );
    painter.galley(at, galley, Color32::WHITE);
    let (Some(_), Some((_, top))) = (derivative, app.scalar_range) else {
        return;
    };
    // The colour bar at the right edge: +top at the top, 0 in the middle, −top at the bottom.
    let bar = egui::Rect::from_min_size(
        egui::pos2(rect.max.x - 92.0, rect.min.y + 36.0),
        egui::vec2(14.0, (rect.height() - 96.0).clamp(40.0, 260.0)),
    );
    // A veil under the bar and its labels (down to the "masked" swatch).
    let veil = egui::Rect::from_min_max(
        egui::pos2(bar.min.x - 6.0, bar.min.y - 8.0),
        egui::pos2(rect.max.x - 4.0, bar.max.y + 26.0),
    );
    painter.rect_filled(veil, 3.0, Color32::from_black_alpha(150));
    let steps = 48;
    for k in 0..steps {
        let f = k as f64 / (steps - 1) as f64;
        let [r, g, b] = crate::render::derivative::diverging_colour(top * (1.0 - 2.0 * f), top);
        let y0 = bar.min.y + bar.height() * k as f32 / steps as f32;
        let y1 = bar.min.y + bar.height() * (k + 1) as f32 / steps as f32;
        painter.rect_filled(
            egui::Rect::from_x_y_ranges(bar.x_range(), y0..=y1 + 0.5),
            0.0,
            Color32::from_rgb(r, g, b),
        );
    }
    let small = egui::FontId::proportional(11.0);
    for (f, v) in [(0.0f32, top), (0.5, 0.0), (1.0, -top)] {
        painter.text(
            egui::pos2(bar.max.x + 4.0, bar.min.y + bar.height() * f),
            egui::Align2::LEFT_CENTER,
            format!("{v:+.2e}"),
            small.clone(),
            Color32::WHITE,
        );
    }
    let grey = crate::render::derivative::MASKED_GREY;
    let swatch = egui::Rect::from_min_size(
        egui::pos2(bar.min.x, bar.max.y + 8.0),
        egui::vec2(14.0, 10.0),
    );
    painter.rect_filled(swatch, 0.0, Color32::from_rgb(grey[0], grey[1], grey[2]));
    painter.text(
        egui::pos2(swatch.max.x + 4.0, swatch.center().y),
        egui::Align2::LEFT_CENTER,
        "masked",
        small,
        Color32::WHITE,
    );
}
