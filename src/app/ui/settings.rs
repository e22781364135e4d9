//! The workbench's the settings pane: method, budget, tone mapping.

use super::super::*;

impl WorkbenchApp {
    pub(in crate::app) fn settings_ui(&mut self, ui: &mut Ui) {
        ui.heading("Render");
        egui::ComboBox::from_label("method")
            .selected_text(self.state.method.name())
            .show_ui(ui, |ui| {
                for m in RenderMethod::ALL {
                    ui.selectable_value(&mut self.state.method, m, m.name());
                }
            });
        if self.state.method.is_stochastic() {
            ui.add(
                egui::Slider::new(&mut self.state.spp, 1..=256)
                    .logarithmic(true)
                    .text("spp per pass"),
            );
            ui.add(
                egui::Slider::new(&mut self.state.passes, 1..=1024)
                    .logarithmic(true)
                    .text("passes"),
            );
        }
        ui.add(egui::Slider::new(&mut self.state.aa, 1..=4).text("AA (N×N)"));
        ui.add(egui::Slider::new(&mut self.state.resolution, 0.25..=1.0).text("resolution"));
        ui.separator();
        ui.heading("Display");
        egui::ComboBox::from_label("AOV")
            .selected_text(self.state.aov.label())
            .show_ui(ui, |ui| {
                for a in Aov::ALL {
                    ui.selectable_value(&mut self.state.aov, a, a.label());
                }
            });
        ui.add(egui::Slider::new(&mut self.state.exposure, -8.0..=8.0).text("exposure (stops)"));
        ui.horizontal(|ui| {
            ui.label("tone map");
            ui.selectable_value(&mut self.state.tonemap, ToneMap::Clamp, "clamp");
            ui.selectable_value(&mut self.state.tonemap, ToneMap::Reinhard, "Reinhard");
        });
        if let Some((lo, hi)) = self.scalar_range
            && !self.state.aov.is_radiance()
        {
            ui.label(format!("false colour: {lo:.3} … {hi:.3}"));
        }
        let current = ASPECTS
            .iter()
            .find(|a| (a.0 - self.state.aspect).abs() < 1e-3)
            .map_or("custom", |a| a.1);
        egui::ComboBox::from_label("image aspect")
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (a, name) in ASPECTS {
                    ui.selectable_value(&mut self.state.aspect, a, name);
                }
            });
    }
}
