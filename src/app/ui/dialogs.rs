//! The workbench's file dialogs (open, save image, save dump, screenshot, save scene, export
//! lesson): a path on the desktop, the browser's picker and downloads on the web
//! (`app::platform`).

use super::super::platform::{self, SaveTarget};
use super::super::*;

/// What the Open dialog offers.
const OPENABLE: [&str; 9] = [
    "toml", "obj", "mtl", "glb", "gltf", "json", "pfm", "hdr", "exr",
];

impl AppState {
    pub(in crate::app) fn open_dialog(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        if let Some(p) = platform::pick_file("penumbra files", &OPENABLE) {
            self.open_path(&p);
        }
        #[cfg(target_arch = "wasm32")]
        self.inbox
            .pick(self.wake.clone(), "penumbra files", &OPENABLE);
    }

    pub(in crate::app) fn save_image_dialog(&mut self) {
        let Some(frame) = self.worker.latest() else {
            return;
        };
        if let Some(target) = platform::save_as("image", &["png", "pfm", "exr"], "render.png") {
            let (image, exposure) = (&frame.frame.output.image, self.settings.exposure);
            self.status = target.write(
                |p| files::save_image(image, p, exposure),
                || files::png_bytes(image, exposure),
            );
        }
    }

    pub(in crate::app) fn save_dump_dialog(&mut self) {
        let Some(ins) = &self.inspector else {
            return;
        };
        if let Some(target) = platform::save_as("debug dump", &["json"], "probe.json") {
            let mut probe = ins.probe.clone();
            probe.monte_carlo = self.monte_carlo;
            self.status = target.write(
                |p| files::save_dump(&probe, p),
                || Ok(serde_json::to_vec_pretty(&probe)?),
            );
        }
    }

    /// Asks for a file and takes a screenshot of the window (or of `crop`, in points).
    pub(in crate::app) fn screenshot_dialog(&mut self, crop: Option<egui::Rect>) {
        if let Some(target) = platform::save_as("PNG", &["png"], "penumbra.png") {
            self.pending_screenshot = Some((target, crop));
        }
    }

    /// Asks for a file and saves the scene as it is now (moved objects included): a TOML file
    /// with its OBJ and MTL beside it, so the desktop's only.
    pub(in crate::app) fn save_scene_dialog(&mut self) {
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        if let Some(why) = platform::unavailable_here("saving a scene (three files)") {
            self.status = why;
            return;
        }
        if let Some(SaveTarget::Path(p)) = platform::save_as("scene", &["toml"], "scene.toml") {
            let cam = self.orbit.camera();
            self.status = match crate::scene::save::save_scene(&ctx.scene, Some(&cam), &p) {
                Ok(saved) => format!(
                    "wrote {} ({} and {} beside it)",
                    saved.toml.display(),
                    saved.obj.display(),
                    saved.mtl.display()
                ),
                Err(e) => e.to_string(),
            };
        }
    }

    /// Asks for a folder and exports the picked point's lesson into it (`export_lesson`); a
    /// folder of frames, so the desktop's only.
    pub(in crate::app) fn export_lesson_dialog(&mut self) {
        if self.inspector.is_none() {
            self.status = "pick a point before exporting its lesson".into();
            return;
        }
        if self.lesson_capture.is_some() {
            self.status = "a lesson is being exported".into();
            return;
        }
        match platform::unavailable_here("exporting a lesson") {
            Some(why) => self.status = why,
            None =>
            {
                #[cfg(not(target_arch = "wasm32"))]
                if let Some(dir) = platform::pick_folder() {
                    self.export_lesson(dir);
                }
            }
        }
    }
}
