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
        match probe_corrected(
            &ctx,
            &self.settings.scene,
            &cam,
            self.render_size,
            (x, y),
            method,
            correction,
            true,
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
                // A new point: the sphere frames its lights again.
                self.settings.sphere.camera = None;
                self.monte_carlo = None;
            }
            Err(e) => self.status = format!("pick failed: {e}"),
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
