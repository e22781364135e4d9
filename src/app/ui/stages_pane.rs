//! The workbench's the stages pane: the stepper over the picked point's recording.

use super::super::*;

impl WorkbenchApp {
    /// The stepper through Alg. 1 with the lesson text of the current stage.
    pub(in crate::app) fn stages_ui(&mut self, ui: &mut Ui) {
        let Some(ins) = &mut self.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        ins.stepper_ui(ui);
        ui.separator();
        ins.lesson_ui(ui);
        sphere_view::step_details_ui(ui, &ins.probe, ins.current());
        ui.separator();
        match &self.lesson_capture {
            Some(c) => {
                let (done, all) = c.progress();
                ui.label(format!("exporting the lesson: {done} of {all} frames…"));
            }
            None => {
                if ui
                    .button("Export lesson…")
                    .on_hover_text(
                        "Every stage of this point as numbered PNG frames, an animated GIF and \
                         the lesson text (lesson.md), for slides",
                    )
                    .clicked()
                    && let Some(dir) = rfd::FileDialog::new().pick_folder()
                {
                    self.export_lesson(dir);
                }
            }
        }
    }
}
