//! One frame of the workbench: the bars, the tiles with each pane drawn by its own type
//! ([`super::Panes`]), the help window; and the state's per-frame work (the viewport's texture,
//! pending screenshots).

use super::super::*;

impl WorkbenchApp {
    /// One frame of the whole UI (also driven by the headless tests).
    pub fn frame_ui(&mut self, ui: &mut Ui) {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f64();
        self.last_frame = now;
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * dt * 1e3;
        let ctx = ui.ctx().clone();
        self.handle_input(&ctx);
        if let Some(ins) = &mut self.inspector
            && ins.tick(dt)
        {
            ctx.request_repaint();
        }
        if self.inspector.as_ref().is_some_and(|i| i.playing) {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        self.update_texture(&ctx);

        egui::Panel::top("menu").show(ui, |ui| self.menu_ui(ui));
        if let Some(view) = self.app.pending_figure.take() {
            self.export_figure_dialog(view);
        }
        egui::Panel::bottom("status").show(ui, |ui| self.status_ui(ui));
        self.follow_step();
        egui::CentralPanel::default().show(ui, |ui| match self.maximised {
            Some(pane) => {
                ui.horizontal(|ui| {
                    ui.strong(pane.title());
                    if ui.small_button("restore (Esc)").clicked() {
                        self.run_command(Command::Restore);
                    }
                });
                self.pane_ui(ui, pane);
            }
            None => {
                let mut tree = std::mem::replace(
                    &mut self.tree,
                    egui_tiles::Tree::empty(egui::Id::unique("penumbra_tiles_swap")),
                );
                let mut host = panes::PaneHost {
                    app: self,
                    maximise: None,
                };
                tree.ui(&mut host, ui);
                let maximise = host.maximise;
                self.tree = tree;
                if maximise.is_some() {
                    self.maximised = maximise;
                }
            }
        });
        if self.show_help {
            egui::Window::new("Help").open(&mut self.show_help).show(&ctx, |ui| {
                ui.label(RichText::new("Keyboard and mouse").strong());
                egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                    for (k, what) in command::help_rows() {
                        ui.monospace(k);
                        ui.label(what);
                        ui.end_row();
                    }
                });
                ui.label("Drop a .toml/.obj scene, a debug dump or bench .json, or a reference .pfm on the window.");
            });
        }
        self.palette_ui(&ctx);
        if let Some(text) = self.clipboard.take() {
            ctx.copy_text(text);
        }
        self.maybe_request();
        self.maybe_repick_for_derivative();
        self.worker.tick();
        self.maybe_auto_pick();
        self.take_pending_screenshot(&ctx);
        self.advance_lesson_capture(&ctx);
        #[cfg(target_arch = "wasm32")]
        self.log_milestones();
        // In the browser the render advances a time slice per frame, so the frames must keep
        // coming while it runs. The native render thread wakes the UI itself with each frame
        // it publishes and when it stops: polling would only take time from it.
        #[cfg(target_arch = "wasm32")]
        if self.worker.is_busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// Draws one pane of the tile tree: the pane's own type, over the app's state.
    pub(crate) fn pane_ui(&mut self, ui: &mut Ui, pane: Pane) {
        let WorkbenchApp { app, panes } = self;
        let view = panes.get(pane);
        match pane {
            // Drawn to the tile's size, or scrolled by their own widgets.
            Pane::Viewport | Pane::Sphere | Pane::Hemisphere | Pane::Planar => view.ui(ui, app),
            // Text that wraps to the tile: scrolled vertically only.
            Pane::Stages => {
                egui::ScrollArea::vertical()
                    .id_salt("stages_scroll")
                    .auto_shrink([false, false])
                    .show(ui, |ui| view.ui(ui, app));
            }
            _ => scrolled(ui, super::scroll_id(pane), |ui| view.ui(ui, app)),
        }
    }
}

impl AppState {
    /// Uploads the newest frame (or re-maps the shown one after a display change).
    pub(in crate::app) fn update_texture(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.worker.latest() else {
            return;
        };
        let display_key = format!(
            "{:?}|{}|{:?}",
            self.settings.aov, self.settings.exposure, self.settings.tonemap
        );
        let key = (
            frame.generation,
            frame.frame.scale,
            frame.frame.passes,
            display_key.clone(),
        );
        if self.shown.as_ref() == Some(&key) {
            return;
        }
        let want = viewport::Display {
            aov: self.settings.aov,
            exposure: self.settings.exposure,
            tonemap: self.settings.tonemap,
        };
        *self
            .worker
            .display
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = want;
        // Mapped on the render thread when the settings match; here only after a change.
        let shown = match &frame.display {
            Some((d, img, range)) if *d == want => Some((img.clone(), *range)),
            _ => frame_image(&frame.frame, want.aov, want.exposure, want.tonemap)
                .or_else(|| frame_image(&frame.frame, Aov::Final, want.exposure, want.tonemap)),
        };
        if let Some((img, range)) = shown {
            let opts = if frame.frame.scale > 1 {
                TextureOptions::NEAREST
            } else {
                TextureOptions::LINEAR
            };
            match &mut self.texture {
                Some(t) => t.set(img, opts),
                None => self.texture = Some(ctx.load_texture("viewport", img, opts)),
            }
            self.scalar_range = range;
        }
        // Error against a loaded reference of the same size.
        if frame.frame.scale == 1
            && let Some(r) = &self.trace.reference
            && r.width == frame.frame.output.image.width
            && r.height == frame.frame.output.image.height
            && frame.generation == self.trace.generation
        {
            let c = crate::render::compare::compare(
                &frame.frame.output.image.to_rgb32(),
                &r.to_rgb32(),
                None,
            );
            self.trace.points.push((frame.frame.elapsed, c.rmse));
        }
        self.shown = Some(key);
    }

    pub(in crate::app) fn take_pending_screenshot(&mut self, ctx: &egui::Context) {
        let Some((target, crop)) = self.pending_screenshot.take() else {
            return;
        };
        let ppp = ctx.pixels_per_point();
        ctx.request_screenshot(move |img| {
            let img = match crop {
                Some(r) => img.region(&r, Some(ppp)),
                None => (*img).clone(),
            };
            let status = target.write(
                |p| files::save_screenshot(&img, p),
                || files::screenshot_png_bytes(&img),
            );
            if !status.starts_with("wrote") && !status.starts_with("downloaded") {
                eprintln!("screenshot: {status}");
            }
        });
        self.status = "screenshot requested".into();
    }
}

#[cfg(target_arch = "wasm32")]
impl AppState {
    /// The browser's record of what happened (its console): the status line when it changes,
    /// the first image with where the viewport is, and each recording with where the sphere
    /// is (in CSS pixels). The browser test reads these; a user sees the same in the console.
    fn log_milestones(&mut self) {
        let rect = |r: egui::Rect| {
            format!(
                "({:.0}, {:.0}, {:.0}×{:.0})",
                r.min.x,
                r.min.y,
                r.width(),
                r.height()
            )
        };
        let log = &mut self.web_log;
        if log.status != self.status {
            log.status = self.status.clone();
            platform::note(&format!("status: {}", self.status));
        }
        if !log.first_image
            && self.texture.is_some()
            && let Some(v) = self.viewport_rect
        {
            log.first_image = true;
            platform::note(&format!(
                "first image after {:.2} s; viewport at {}",
                self.started.elapsed().as_secs_f64(),
                rect(v)
            ));
        }
        let selected = self.editor.selected;
        if log.selected != selected {
            log.selected = selected;
            let arrow = match (&self.ctx, self.viewport_rect) {
                (Some(ctx), Some(v)) => self
                    .editor
                    .gizmo(ctx, &self.orbit.camera(), v)
                    .and_then(|g| g.arrow(0)),
                _ => None,
            };
            if let Some((from, to)) = arrow {
                platform::note(&format!(
                    "handles: the x arrow from ({:.0}, {:.0}) to ({:.0}, {:.0})",
                    from.x, from.y, to.x, to.y
                ));
            }
        }
        let log = &mut self.web_log;
        let recording = self
            .inspector
            .as_ref()
            .map(|i| (i.probe.pixel, i.steps.len()));
        if recording.is_some()
            && log.recording != recording
            && let Some(s) = self.sphere_rect
        {
            log.recording = recording;
            let (pixel, stages) = recording.unwrap_or_default();
            platform::note(&format!(
                "recording of pixel ({:.0}, {:.0}): {stages} stages; sphere at {}",
                pixel.0,
                pixel.1,
                rect(s)
            ));
        }
    }
}
