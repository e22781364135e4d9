//! The workbench's lesson mode's capture of frames and the stepper following the play.

use super::super::*;

impl AppState {
    /// One frame of a lesson export (after the tiles are drawn).
    pub(in crate::app) fn advance_lesson_capture(&mut self, ctx: &egui::Context) {
        use lesson_export::CaptureAction;
        let Some(capture) = &mut self.lesson_capture else {
            return;
        };
        ctx.request_repaint();
        match capture.advance() {
            CaptureAction::Show(i) => {
                if let Some(ins) = &mut self.inspector {
                    ins.step = Some(i);
                    ins.playing = false;
                }
            }
            CaptureAction::Capture(i) => {
                let receive = capture.receiver(i, self.subject_rect, ctx.pixels_per_point());
                ctx.request_screenshot(receive);
            }
            CaptureAction::Wait => {}
            CaptureAction::Write(frames) => {
                let dir = capture.dir.clone();
                let seconds = capture.seconds;
                self.lesson_capture = None;
                self.status = match lesson_export::write_lesson(&dir, &frames, seconds) {
                    Ok(f) => format!(
                        "wrote {} frames, {} and {}",
                        f.frames.len(),
                        f.gif.display(),
                        f.text.display()
                    ),
                    Err(e) => format!("{e:#}"),
                };
            }
        }
    }

    /// Starts exporting every stage (group) of the picked point into `dir` (frames, GIF, text): the
    /// stepper walks the stages one frame after another and each is captured from the
    /// sphere's tile. `false` when nothing is picked.
    pub fn export_lesson(&mut self, dir: PathBuf) -> bool {
        let Some(ins) = &self.inspector else {
            self.status = "pick a point before exporting its lesson".into();
            return false;
        };
        // One frame per group of the stepper: a mesh taken face by face is one frame.
        let labels = ins
            .groups
            .iter()
            .map(|g| {
                let s = &ins.steps[g.last()];
                (g.last(), g.label.clone(), lesson::lesson(&ins.probe, s))
            })
            .collect();
        self.maximised = None;
        if !layout::is_shown(&self.tree, Pane::Planar) {
            layout::reveal(&mut self.tree, Pane::Sphere);
        }
        self.lesson_capture = Some(lesson_export::LessonCapture::new(dir, 1.5, labels));
        true
    }

    /// Brings the planar view forward when the stepper reaches a set difference, and the
    /// sphere back after it (only where they share a tab container: a layout the user made
    /// with both in sight is left alone).
    pub(in crate::app) fn follow_step(&mut self) {
        let Some(ins) = &self.inspector else {
            return;
        };
        if ins.step == self.shown_step {
            return;
        }
        self.shown_step = ins.step;
        let (want, other) = if ins.at_set_difference() {
            (Pane::Planar, Pane::Sphere)
        } else {
            (Pane::Sphere, Pane::Planar)
        };
        let (Some(w), Some(o)) = (
            layout::find(&self.tree, want),
            layout::find(&self.tree, other),
        ) else {
            return;
        };
        if self.tree.tiles.parent_of(w) == self.tree.tiles.parent_of(o)
            && self.tree.active_tiles().contains(&o)
        {
            self.tree.make_active(|id, _| id == w);
        }
    }
}
