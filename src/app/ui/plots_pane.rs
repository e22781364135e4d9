//! The plots pane: run time against error from a bench (run here or loaded), and the
//! progressive render's error against a loaded reference over time.

use super::super::*;
use super::PaneView;

/// Its own state: a bench started from here, and the image size it runs at.
pub struct PlotsPane {
    bench_job: Option<bench_job::BenchJob>,
    bench_size: (u32, u32),
}

impl Default for PlotsPane {
    fn default() -> Self {
        PlotsPane {
            bench_job: None,
            bench_size: (160, 120),
        }
    }
}

impl PaneView for PlotsPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        use egui_plot::{Legend, Line, Plot, PlotPoints, Points};
        ui.horizontal(|ui| {
            if ui.button("Load bench JSON or reference PFM…").clicked() {
                app.run_command(Command::Open);
            }
        });
        // penumbra bench on the current view, in the background.
        match &self.bench_job {
            None => {
                ui.horizontal(|ui| {
                    ui.add(
                        egui::DragValue::new(&mut self.bench_size.0)
                            .range(32..=1920)
                            .prefix("w "),
                    );
                    ui.add(
                        egui::DragValue::new(&mut self.bench_size.1)
                            .range(32..=1080)
                            .prefix("h "),
                    );
                    let why_not = crate::app::platform::unavailable_here("the bench");
                    if ui
                        .add_enabled(
                            why_not.is_none(),
                            egui::Button::new("Run bench on this view"),
                        )
                        .on_disabled_hover_text(why_not.unwrap_or_default())
                        .clicked()
                        && let Some(ctx) = app.ctx.clone()
                    {
                        self.bench_job = Some(bench_job::BenchJob::start(
                            ctx,
                            app.settings.scene.clone(),
                            app.orbit.camera(),
                            self.bench_size.0,
                            self.bench_size.1,
                        ));
                    }
                });
            }
            Some(job) => {
                let (frac, label, result) = job.poll();
                match result {
                    None => {
                        ui.add(
                            egui::ProgressBar::new(frac)
                                .show_percentage()
                                .text(format!("bench: {label}")),
                        );
                        ui.ctx()
                            .request_repaint_after(std::time::Duration::from_millis(200));
                    }
                    Some(Ok((report, files))) => {
                        app.status = format!(
                            "bench done: {}",
                            files
                                .first()
                                .map(|f| f.display().to_string())
                                .unwrap_or_default()
                        );
                        app.bench = Some(report);
                        self.bench_job = None;
                    }
                    Some(Err(e)) => {
                        app.status = format!("bench failed: {e}");
                        self.bench_job = None;
                    }
                }
            }
        }
        if let Some(r) = &app.bench {
            ui.label(format!("{}: log10 time (s) against log10 RMSE", r.scene));
            Plot::new("bench_plot")
                .legend(Legend::default())
                .height(220.0)
                .show(ui, |plot| {
                    let mut methods: Vec<&str> = Vec::new();
                    for row in &r.rows {
                        if !methods.contains(&row.method.as_str()) {
                            methods.push(&row.method);
                        }
                    }
                    for (i, m) in methods.into_iter().enumerate() {
                        let [cr, cg, cb] =
                            crate::bench::plot::PALETTE[i % crate::bench::plot::PALETTE.len()];
                        let colour = Color32::from_rgb(cr, cg, cb);
                        let pts: Vec<[f64; 2]> = r
                            .rows
                            .iter()
                            .filter(|x| x.method == m && x.seconds > 0.0 && x.rmse > 0.0)
                            .map(|x| [x.seconds.log10(), x.rmse.log10()])
                            .collect();
                        if pts.len() > 1 {
                            plot.line(
                                Line::new(m.to_string(), PlotPoints::from(pts.clone()))
                                    .color(colour),
                            );
                        }
                        plot.points(
                            Points::new(m.to_string(), PlotPoints::from(pts))
                                .radius(3.0)
                                .color(colour),
                        );
                    }
                });
        }
        if app.trace.reference.is_some() {
            ui.label("progressive render: RMSE against the loaded reference over time");
            let pts: Vec<[f64; 2]> = app
                .trace
                .points
                .iter()
                .filter(|p| p.1 > 0.0)
                .map(|&(t, e)| [t, e.log10()])
                .collect();
            Plot::new("trace_plot").height(180.0).show(ui, |plot| {
                plot.line(Line::new("log10 RMSE", PlotPoints::from(pts)));
            });
        }
    }
}
