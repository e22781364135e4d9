//! The stages pane: the stepper through the picked point's recorded stages, the lesson text
//! of the current step, its details, and the lesson export.

use super::super::*;
use super::PaneView;

/// Draws the picked point's recording; the step shown lives in the inspector.
#[derive(Default)]
pub struct StagesPane;

impl PaneView for StagesPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &mut app.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        if let Some(command) = ins.stepper_ui(ui) {
            app.run_command(command);
        }
        let Some(ins) = &mut app.inspector else {
            return;
        };
        ui.separator();
        ins.lesson_ui(ui);
        sphere_view::step_details_ui(ui, &ins.probe, ins.current());
        ui.separator();
        match &app.lesson_capture {
            Some(c) => {
                let (done, all) = c.progress();
                ui.label(format!("exporting the lesson: {done} of {all} frames…"));
            }
            None => {
                let why_not = crate::app::platform::unavailable_here("exporting a lesson");
                let button = ui
                    .add_enabled(why_not.is_none(), egui::Button::new("Export lesson…"))
                    .on_hover_text(
                        "Every stage of this point as numbered PNG frames, an animated GIF and \
                         the lesson text (lesson.md), for slides",
                    )
                    .on_disabled_hover_text(why_not.unwrap_or_default());
                if button.clicked() {
                    app.run_command(Command::ExportLesson);
                }
            }
        }
    }
}
