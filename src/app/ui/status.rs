//! The workbench's status bar.

use super::super::*;

impl AppState {
    pub(in crate::app) fn status_ui(&mut self, ui: &mut Ui) {
        ui.horizontal(|ui| {
            match self.worker.latest() {
                Some(f) => {
                    let fr = &f.frame;
                    let (w, h) = (fr.output.image.width, fr.output.image.height);
                    let px = (w * h) as f64 * fr.passes as f64;
                    let env = match (&fr.output.environment, &self.settings.environment) {
                        (Some(_), c) => format!(" + environment {}", c.method.name()),
                        _ => String::new(),
                    };
                    // The analytic methods take no samples but their camera rays'.
                    let samples = if f.settings.method.is_stochastic() {
                        format!("{} spp", fr.spp)
                    } else {
                        match fr.camera_samples {
                            1 => "1 camera ray per pixel".to_string(),
                            n => format!("{n} camera rays per pixel"),
                        }
                    };
                    // The derivative AOV's frames: what they differentiate, the colour map's
                    // scale and the pixels masked.
                    let env = match (&fr.output.derivative, self.scalar_range) {
                        (Some(d), Some((_, top))) if self.settings.aov == Aov::Derivative => {
                            format!(
                                "{env}, {} ±{top:.2e} ({} masked)",
                                self.derivative_label(&d.motion),
                                d.masked.pixels
                            )
                        }
                        _ => env,
                    };
                    ui.label(format!(
                        "{}{env} {}×{} (1/{}), pass {}, {samples}, {:.2} s, {:.0} kpixels/s{}",
                        f.settings.method.name(),
                        w,
                        h,
                        fr.scale,
                        fr.passes,
                        fr.elapsed,
                        px / fr.elapsed.max(1e-9) / 1e3,
                        if self.worker.is_busy() {
                            " — rendering"
                        } else {
                            " — done"
                        }
                    ));
                }
                None => {
                    ui.label("rendering…");
                }
            }
            ui.separator();
            ui.label(format!("UI {:.1} ms", self.frame_ms));
            ui.separator();
            ui.label(&self.status);
        });
    }
}
