//! The workbench's the scene pane: objects, trees, moving and saving.

use super::super::*;

impl WorkbenchApp {
    pub(in crate::app) fn scene_ui(&mut self, ui: &mut Ui) {
        ui.heading("Scene");
        ui.label(&self.state.scene);
        if let Some(e) = &self.scene_error {
            ui.colored_label(Color32::LIGHT_RED, e);
        }
        let mut use_trees = self.use_trees;
        ui.checkbox(&mut use_trees, "silhouettes from BSP trees")
            .on_hover_text(
                "Off: every silhouette is computed at its point, and the sphere view can show \
                 the contour pieces the exact silhouette's ray test rejected there (a tree \
                 stores only the result).",
            );
        if use_trees != self.use_trees {
            self.set_use_trees(use_trees);
        }
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        ui.horizontal(|ui| {
            if ui
                .add_enabled(self.editor.can_undo(), egui::Button::new("undo"))
                .on_hover_text(Command::Undo.shortcut_text())
                .clicked()
            {
                self.run_command(Command::Undo);
            }
            if ui
                .add_enabled(self.editor.can_redo(), egui::Button::new("redo"))
                .on_hover_text(Command::Redo.shortcut_text())
                .clicked()
            {
                self.run_command(Command::Redo);
            }
            if ui.button("Save scene…").clicked() {
                self.save_scene_dialog();
            }
        });
        ui.small(
            "Select an object (here, or double-click it in the viewport), then drag its arrows \
             to move it or its ring to turn it.",
        );
        egui::ScrollArea::vertical()
            .id_salt("objects")
            .max_height(260.0)
            .show(ui, |ui| self.editor.list_ui(ui, &ctx));
        for w in ctx.scene.warnings.iter().chain(&ctx.prepared.notes) {
            ui.small(w);
        }
    }
}
