//! The workbench's file dialogs (open, save image, save dump, screenshot, save scene).

use super::super::*;

impl AppState {
    pub(in crate::app) fn open_dialog(&mut self) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter(
                "penumbra files",
                &["toml", "obj", "glb", "gltf", "json", "pfm", "hdr", "exr"],
            )
            .pick_file()
        {
            self.open_path(&p);
        }
    }

    pub(in crate::app) fn save_image_dialog(&mut self) {
        let Some(frame) = self.worker.latest() else {
            return;
        };
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("image", &["png", "pfm", "exr"])
            .set_file_name("render.png")
            .save_file()
        {
            self.status =
                match files::save_image(&frame.frame.output.image, &p, self.settings.exposure) {
                    Ok(()) => format!("wrote {}", p.display()),
                    Err(e) => format!("{e:#}"),
                };
        }
    }

    pub(in crate::app) fn save_dump_dialog(&mut self) {
        let Some(ins) = &self.inspector else {
            return;
        };
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("debug dump", &["json"])
            .set_file_name("probe.json")
            .save_file()
        {
            let mut probe = ins.probe.clone();
            probe.monte_carlo = self.monte_carlo;
            self.status = match files::save_dump(&probe, &p) {
                Ok(()) => format!("wrote {}", p.display()),
                Err(e) => format!("{e:#}"),
            };
        }
    }

    /// Asks for a file and takes a screenshot of the window (or of `crop`, in points).
    pub(in crate::app) fn screenshot_dialog(&mut self, crop: Option<egui::Rect>) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("PNG", &["png"])
            .set_file_name("penumbra.png")
            .save_file()
        {
            self.pending_screenshot = Some((p, crop));
        }
    }

    /// Asks for a file and saves the scene as it is now (moved objects included).
    pub(in crate::app) fn save_scene_dialog(&mut self) {
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("scene", &["toml"])
            .set_file_name("scene.toml")
            .save_file()
        {
            let cam = self.orbit.camera();
            self.status = match crate::scene::save::save_scene(&ctx.scene, Some(&cam), &p) {
                Ok(saved) => format!(
                    "wrote {} ({} and {} beside it)",
                    saved.toml.display(),
                    saved.obj.display(),
                    saved.mtl.display()
                ),
                Err(e) => e,
            };
        }
    }
}
