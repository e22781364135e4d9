//! The settings pane: the render method and its samples, the display (AOV, exposure, tone
//! map, aspect).

use super::super::*;
use super::PaneView;

/// Edits the app's settings; no state of its own.
#[derive(Default)]
pub struct SettingsPane;

impl PaneView for SettingsPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        ui.heading("Render");
        egui::ComboBox::from_label("method")
            .selected_text(app.settings.method.name())
            .show_ui(ui, |ui| {
                for m in RenderMethod::ALL {
                    ui.selectable_value(&mut app.settings.method, m, m.name());
                }
            });
        if app.settings.method.is_stochastic() {
            ui.add(
                egui::Slider::new(&mut app.settings.spp, 1..=256)
                    .logarithmic(true)
                    .text("spp per pass"),
            );
            ui.add(
                egui::Slider::new(&mut app.settings.passes, 1..=1024)
                    .logarithmic(true)
                    .text("passes"),
            );
        }
        ui.add(egui::Slider::new(&mut app.settings.aa, 1..=4).text("AA (N×N)"));
        ui.add(egui::Slider::new(&mut app.settings.resolution, 0.25..=1.0).text("resolution"));
        ui.separator();
        ui.heading("Display");
        egui::ComboBox::from_label("AOV")
            .selected_text(app.settings.aov.label())
            .show_ui(ui, |ui| {
                for a in Aov::ALL {
                    ui.selectable_value(&mut app.settings.aov, a, a.label());
                }
            });
        ui.add(egui::Slider::new(&mut app.settings.exposure, -8.0..=8.0).text("exposure (stops)"));
        ui.horizontal(|ui| {
            ui.label("tone map");
            ui.selectable_value(&mut app.settings.tonemap, ToneMap::Clamp, "clamp");
            ui.selectable_value(&mut app.settings.tonemap, ToneMap::Reinhard, "Reinhard");
        });
        if app.settings.aov == Aov::Derivative {
            super::scene_pane::derivative_axis_ui(ui, app);
            match (app.derivative_motion(), app.scalar_range) {
                (Ok(Some(m)), Some((_, top))) => {
                    ui.label(format!(
                        "{}: blue −{top:.3e} … white 0 … red +{top:.3e}, masked grey",
                        app.derivative_label(&m)
                    ));
                }
                (Err(why), _) => {
                    ui.label(why);
                }
                _ => {}
            }
        } else if let Some((lo, hi)) = app.scalar_range
            && !app.settings.aov.is_radiance()
        {
            ui.label(format!("false colour: {lo:.3} … {hi:.3}"));
        }
        let current = ASPECTS
            .iter()
            .find(|a| (a.0 - app.settings.aspect).abs() < 1e-3)
            .map_or("custom", |a| a.1);
        egui::ComboBox::from_label("image aspect")
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (a, name) in ASPECTS {
                    ui.selectable_value(&mut app.settings.aspect, a, name);
                }
            });
    }
}
