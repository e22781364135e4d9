//! The scene pane: the scene's name, its objects (select, undo, redo, save) and its notes.

use super::super::*;
use super::PaneView;

/// Draws the scene and its edits from the app's state; no state of its own.
#[derive(Default)]
pub struct ScenePane;

impl PaneView for ScenePane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        ui.heading("Scene");
        ui.label(&app.settings.scene);
        if let Some(e) = &app.scene_error {
            ui.colored_label(Color32::LIGHT_RED, e);
        }
        let mut use_trees = app.use_trees;
        ui.checkbox(&mut use_trees, "silhouettes from BSP trees")
            .on_hover_text(
                "Off: every silhouette is computed at its point, and the sphere view can show \
                 the contour pieces the exact silhouette's ray test rejected there (a tree \
                 stores only the result).",
            );
        if use_trees != app.use_trees {
            app.set_use_trees(use_trees);
        }
        let Some(ctx) = app.ctx.clone() else {
            return;
        };
        ui.horizontal(|ui| {
            if ui
                .add_enabled(app.editor.can_undo(), egui::Button::new("undo"))
                .on_hover_text(Command::Undo.shortcut_text())
                .clicked()
            {
                app.run_command(Command::Undo);
            }
            if ui
                .add_enabled(app.editor.can_redo(), egui::Button::new("redo"))
                .on_hover_text(Command::Redo.shortcut_text())
                .clicked()
            {
                app.run_command(Command::Redo);
            }
            let why_not = crate::app::platform::unavailable_here("saving a scene (three files)");
            if ui
                .add_enabled(why_not.is_none(), egui::Button::new("Save scene…"))
                .on_disabled_hover_text(why_not.unwrap_or_default())
                .clicked()
            {
                app.run_command(Command::SaveScene);
            }
        });
        ui.small(
            "Select an object (here, or double-click it in the viewport), then drag its arrows \
             to move it or its ring to turn it.",
        );
        egui::ScrollArea::vertical()
            .id_salt("objects")
            .max_height(260.0)
            .show(ui, |ui| app.editor.list_ui(ui, &ctx));
        derivative_axis_ui(ui, app);
        for w in ctx
            .scene
            .warnings
            .iter()
            .cloned()
            .chain(ctx.prepared.report.lines())
        {
            ui.small(w);
        }
    }
}

/// The gizmo's active axis, which the derivative AOV differentiates along (dragging a handle
/// makes its axis the active one), and a switch to the derivative AOV.
pub(super) fn derivative_axis_ui(ui: &mut Ui, app: &mut AppState) {
    use crate::Choice;
    use crate::shading::derivative::Axis;
    ui.horizontal(|ui| {
        ui.label("derivative along");
        let now = app.editor.axis();
        for axis in [Axis::Tx, Axis::Ty, Axis::Tz, Axis::Ry] {
            if ui
                .selectable_label(now == axis, axis.name())
                .on_hover_text(axis.summary())
                .clicked()
            {
                app.editor.set_axis(axis);
            }
        }
        let mut on = app.settings.aov == Aov::Derivative;
        if ui
            .checkbox(&mut on, "show")
            .on_hover_text("The derivative AOV: the image's derivative in the viewport")
            .changed()
        {
            app.settings.aov = if on { Aov::Derivative } else { Aov::Final };
        }
    });
}
