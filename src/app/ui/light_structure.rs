//! The workbench's the light-structure pane (the BSP of a non-convex light).

use super::super::*;

impl WorkbenchApp {
    pub(in crate::app) fn light_structure_ui(&mut self, ui: &mut Ui) {
        let Some(ctx) = &self.ctx else {
            return;
        };
        let names: Vec<String> = ctx
            .prepared
            .lights
            .iter()
            .map(|&(id, _)| ctx.prepared.objects[id as usize].name.clone())
            .collect();
        egui::ComboBox::from_label("light")
            .selected_text(
                self.selected_light
                    .and_then(|l| names.get(l).cloned())
                    .unwrap_or_else(|| "none".into()),
            )
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.selected_light, None, "none");
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(&mut self.selected_light, Some(i), n);
                }
            });
        if let Some(l) = self.selected_light
            && let Some(&(id, _)) = ctx.prepared.lights.get(l)
        {
            let obj = &ctx.prepared.objects[id as usize];
            let probe = self.inspector.as_ref().map(|i| &i.probe);
            let point = probe.and_then(|p| p.point).map(|p| p.position);
            // The light's record taken whole (a light taken face by face has no outline).
            let record = probe.and_then(|p| {
                p.recording
                    .lights
                    .iter()
                    .find(|r| r.light == l && r.piece.is_none())
            });
            self.light_view.ui(ui, obj, point, record);
        }
    }
}
