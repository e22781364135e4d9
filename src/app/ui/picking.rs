//! The workbench's picking a pixel: the probe of the picked point (`inspect::probe_method`)
//! and its Monte Carlo check.

use super::super::*;

impl AppState {
    /// Picks pixel (x, y) of the full-resolution image: the same primary hit and `shade` as
    /// the renderer, with the recorder on.
    pub fn pick(&mut self, x: f64, y: f64) {
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        // What the pick records is the library's decision (`inspect::probe_method`), as for
        // `penumbra probe`; a stochastic method is said plainly, and its analytic stages shown.
        let s = self.settings();
        let (method, correction, note) = match probe_method(
            self.settings.method,
            s.spp,
            s.seed,
            (x, y),
            self.render_size.0,
        ) {
            Ok((m, c)) => (m, c, None),
            Err(why) => (Method::Analytic, None, Some(why)),
        };
        let cam = self.orbit.camera();
        // With the derivative AOV shown, the point is shaded as its renderer shades it: the
        // same stages with each edge's rate (`inspect::probe_full`).
        let motion = self.derivative_motion().ok().flatten();
        match probe_full(
            &ctx,
            &self.settings.scene,
            &cam,
            self.render_size,
            (x, y),
            method,
            correction,
            true,
            motion.as_ref(),
        ) {
            Ok(p) => {
                self.status = format!(
                    "picked ({x:.0}, {y:.0}): {}",
                    p.object_name.clone().unwrap_or_else(|| "background".into())
                );
                if let Some(why) = note {
                    self.status = format!("{}; {why}: the analytic stages are shown", self.status);
                }
                self.inspector = Some(Inspector::new(p));
                self.picked_motion = Some(motion);
                // A new point: the sphere frames its lights again.
                self.settings.sphere.camera = None;
                self.monte_carlo = None;
            }
            Err(e) => self.status = format!("pick failed: {e}"),
        }
    }

    /// Probes the picked point again when the derivative AOV's motion changed since it was
    /// picked (the AOV shown or hidden, another object selected, another axis): its recording
    /// then holds the moving edges of the motion shown. The stage shown stays where the new
    /// recording has it.
    pub(in crate::app) fn maybe_repick_for_derivative(&mut self) {
        let Some(picked) = self.picked_motion else {
            return;
        };
        let want = self.derivative_motion().ok().flatten();
        if want == picked {
            return;
        }
        // Once, whatever the new probe does (a failed one is not tried again every frame).
        self.picked_motion = Some(want);
        let Some(ins) = &self.inspector else {
            return;
        };
        if ins.probe.scene != self.settings.scene || ins.probe.size != self.render_size {
            return;
        }
        let (x, y) = ins.probe.pixel;
        let step = ins.step;
        let status = self.status.clone();
        self.pick(x, y);
        self.status = status;
        if let Some(ins) = &mut self.inspector {
            ins.step = step.filter(|&s| s < ins.steps.len());
        }
    }

    /// Before anything is picked, picks a penumbra pixel chosen by
    /// [`crate::inspect::interesting_pixel`], so that the sphere is never empty on first start.
    pub(in crate::app) fn maybe_auto_pick(&mut self) {
        if !self.auto_pick || self.render_size.0 == 0 {
            return;
        }
        self.auto_pick = false;
        if self.inspector.is_some() {
            return;
        }
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        let t = Instant::now();
        match crate::inspect::interesting_pixel(&ctx, &self.orbit.camera(), self.render_size, 24) {
            Some((x, y)) => {
                self.pick(x, y);
                self.status = format!(
                    "{} — a penumbra point picked to start with ({:.0} ms); click to pick another",
                    self.status,
                    t.elapsed().as_secs_f64() * 1e3
                );
            }
            None => {
                self.status = format!("{} — click a pixel to inspect it", self.status);
            }
        }
    }

    /// The Monte Carlo check of the picked point, computed on demand.
    pub(crate) fn run_monte_carlo(&mut self, samples: u32) {
        let (Some(ctx), Some(ins)) = (&self.ctx, &self.inspector) else {
            return;
        };
        if let (Some(sp), Some(m)) = (ins.probe.point, ins.probe.material.as_ref()) {
            self.monte_carlo = Some(monte_carlo(ctx, &sp, m, samples, 7));
        }
    }
}
