//! The launcher of the workbench: `penumbra gui`'s options, opening the window, and the
//! headless harnesses that drive the real window (`--screenshot`, `--measure`,
//! `--measure-drag`).

use super::*;

/// What the workbench does at start besides showing the window: `penumbra gui`'s flags, read
/// by the command line (`cli/gui.rs`, which documents each), or the defaults.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// A scene file, OBJ, glTF or embedded scene name (default: the last one used).
    pub scene: Option<String>,
    /// Save a screenshot of the window here once the render has finished, then quit.
    pub screenshot: Option<PathBuf>,
    /// With `screenshot`: take it after at most this many seconds.
    pub after: f64,
    /// Write a [`Measurement`] of responsiveness here as JSON, then quit.
    pub measure: Option<PathBuf>,
    /// Write a [`DragMeasurement`] of moving the picked point's occluder here, then quit.
    pub measure_drag: Option<PathBuf>,
    /// Pick the pixel at these fractions of the viewport first.
    pub pick: Option<(f64, f64)>,
    /// With `pick`: step to this stage (gh, labels, visible, ltc, silhouette:LIGHT, a number).
    pub step: Option<String>,
    /// Open these files at start (bench JSON, reference PFM, debug dump).
    pub open: Vec<PathBuf>,
    pub method: Option<RenderMethod>,
    pub env_method: Option<crate::environment::EnvMethod>,
    /// Light the scene with this environment: sky, sky-sh, an .hdr/.exr file, none.
    pub env: Option<String>,
    /// Select this object (by name or index): its move handles show in the viewport.
    pub select: Option<String>,
    /// Show this light (by object name) in the light structure view.
    pub light: Option<String>,
    /// Compute every silhouette at its point instead of reading it from a BSP tree.
    pub no_trees: bool,
    /// Zoom the sphere view's flat hemisphere to fit the polygons drawn.
    pub fit: bool,
    pub preset: Option<Preset>,
    /// Export the lesson of the picked point into this directory once rendered, then quit.
    pub export_lesson: Option<PathBuf>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            scene: None,
            screenshot: None,
            after: DEFAULT_SCREENSHOT_WAIT,
            measure: None,
            measure_drag: None,
            pick: None,
            step: None,
            open: Vec::new(),
            method: None,
            env_method: None,
            env: None,
            select: None,
            light: None,
            no_trees: false,
            fit: false,
            preset: None,
            export_lesson: None,
        }
    }
}

/// Seconds a screenshot waits at most for the render to finish.
pub const DEFAULT_SCREENSHOT_WAIT: f64 = 30.0;

/// Opens the workbench window.
pub fn run(opts: RunOptions, prepare: crate::shading::PrepareConfig) -> eframe::Result {
    // The glow (OpenGL) painter by default: on machines without a GPU (Mesa llvmpipe) it
    // paints a 1280×800 window several times faster than wgpu's GL backend (measured with
    // `penumbra gui --measure`, docs/workbench.md). PENUMBRA_RENDERER=wgpu picks wgpu.
    let renderer = match std::env::var("PENUMBRA_RENDERER").as_deref() {
        Ok("wgpu") => eframe::Renderer::Wgpu,
        _ => eframe::Renderer::Glow,
    };
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("penumbra")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer,
        ..Default::default()
    };
    eframe::run_native(
        "penumbra",
        options,
        Box::new(move |cc| {
            let mut app = WorkbenchApp::from_creation_context(cc, prepare);
            if let Some(p) = opts.preset {
                app.set_preset(p);
            }
            if opts.no_trees {
                app.set_use_trees(false);
            }
            if let Some(s) = &opts.scene {
                app.load_scene(s);
            }
            if let Some(m) = opts.method {
                app.settings.method = m;
            }
            if opts.env.is_some() || opts.env_method.is_some() {
                let mut choice = app.settings.environment.clone();
                if let Some(map) = &opts.env {
                    choice.map = environment_panel::MapChoice::parse(map);
                }
                if let Some(m) = opts.env_method {
                    choice.method = m;
                }
                app.set_environment(choice);
            }
            if opts.fit {
                app.settings.sphere.fit = true;
            }
            if let Some(name) = &opts.light {
                app.select_light(name);
            }
            if let Some(spec) = &opts.select {
                app.select_object(spec);
            }
            for p in &opts.open {
                app.open_path(p);
            }
            Ok(if let Some(path) = opts.measure_drag.clone() {
                Box::new(MeasureDrag {
                    app,
                    path,
                    phase: DragPhase::Warmup(Instant::now()),
                    result: DragMeasurement::default(),
                    object: None,
                }) as Box<dyn eframe::App>
            } else if let Some(path) = opts.measure.clone() {
                Box::new(Measure {
                    app,
                    path,
                    phase: MeasurePhase::Warmup(Instant::now()),
                    result: Measurement::default(),
                    last: None,
                }) as Box<dyn eframe::App>
            } else if opts.screenshot.is_some() || opts.export_lesson.is_some() {
                Box::new(AutoScreenshot {
                    app,
                    path: opts.screenshot.clone(),
                    lesson: opts.export_lesson.clone(),
                    after: opts.after,
                    start: Instant::now(),
                    state: 0,
                    pick: opts.pick,
                    step: opts.step.clone(),
                })
            } else {
                Box::new(app)
            })
        }),
    )
}

/// `penumbra --screenshot FILE`: waits for the render to finish (or `after` seconds), saves a
/// screenshot of the window and quits. Used by the CI smoke test and to make the user guide's
/// pictures.
struct AutoScreenshot {
    app: WorkbenchApp,
    path: Option<PathBuf>,
    /// `--export-lesson DIR`.
    lesson: Option<PathBuf>,
    after: f64,
    start: Instant,
    state: u32,
    pick: Option<(f64, f64)>,
    step: Option<String>,
}

impl AutoScreenshot {
    /// Applies `--pick` and `--step`.
    fn prepare(&mut self) {
        if let Some((fx, fy)) = self.pick {
            let (w, h) = self.app.render_size;
            self.app
                .pick((fx * w as f64).floor(), (fy * h as f64).floor());
        }
        let (Some(step), Some(ins)) = (&self.step, &mut self.app.inspector) else {
            return;
        };
        let find = |f: &dyn Fn(&crate::views::stages::StepKind) -> bool| {
            ins.steps.iter().position(|s| f(&s.kind))
        };
        ins.step = match step.as_str() {
            "gh" => find(&|k| {
                matches!(
                    k,
                    crate::views::stages::StepKind::SetDifference {
                        phase: Some(crate::views::stages::GhPhase::Traversal),
                        ..
                    }
                )
            })
            .or_else(|| {
                find(&|k| matches!(k, crate::views::stages::StepKind::SetDifference { .. }))
            }),
            "labels" => find(&|k| {
                matches!(
                    k,
                    crate::views::stages::StepKind::SetDifference {
                        phase: Some(crate::views::stages::GhPhase::Labels),
                        ..
                    }
                )
            }),
            "visible" => find(&|k| *k == crate::views::stages::StepKind::Visible),
            "ltc" => find(&|k| matches!(k, crate::views::stages::StepKind::LtcClipped { .. })),
            n if n.starts_with("silhouette:") => {
                let name = &n["silhouette:".len()..];
                let light = ins.probe.lights.iter().find(|l| l.name == name);
                ins.steps.iter().position(|s| {
                    s.kind == crate::views::stages::StepKind::LightSilhouette
                        && light
                            .is_some_and(|l| ins.probe.recording.lights[s.record].light == l.light)
                })
            }
            n => n.parse::<usize>().ok().filter(|&i| i < ins.steps.len()),
        };
    }
}

impl eframe::App for AutoScreenshot {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.app.ui(ui, frame);
        let t = self.start.elapsed().as_secs_f64();
        match self.state {
            0 if self.app.render_finished() || t > self.after => {
                self.prepare();
                if self.app.panes.light_structure.light.is_some() {
                    layout::reveal(&mut self.app.tree, Pane::LightStructure);
                }
                self.state = 1;
            }
            // A few frames for the panels to lay out what was picked, and the render of the
            // (possibly resized) viewport to finish again.
            1..=4 => self.state += 1,
            5 if !self.app.render_finished() && t < self.after + 60.0 => {}
            5 => {
                if let Some(dir) = self.lesson.take()
                    && self.app.export_lesson(dir)
                {
                    self.state = 100;
                    return;
                }
                if let Some(path) = self.path.clone() {
                    self.app.screenshot_to(path, None);
                }
                self.state = 6;
            }
            // The lesson export runs; then the screenshot, if one was asked for too.
            100 if self.app.exporting_lesson() => {}
            100 => {
                eprintln!("{}", self.app.status);
                self.state = 5;
            }
            6..=15 => self.state += 1,
            16 => ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close),
            _ => {}
        }
        // While the render runs, the window is left alone, as a person's idle window is: the
        // render thread wakes it with each frame and when it stops, and the deadline wakes it
        // otherwise. A driver that repainted every frame would take the render's cores.
        let deadline = match self.state {
            0 => Some(self.after),
            5 => Some(self.after + 60.0),
            _ => None,
        };
        match deadline {
            Some(d) => ui
                .ctx()
                .request_repaint_after(std::time::Duration::from_secs_f64((d - t).max(0.01))),
            None => ui.ctx().request_repaint(),
        }
    }
}

/// Responsiveness of the workbench, measured in the real window while it renders.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Measurement {
    pub window: (f32, f32),
    pub render_size: (u32, u32),
    pub method: String,
    /// Seconds from a camera change to the first (coarse) image of the new view, per change.
    pub first_image_seconds: Vec<f64>,
    /// Intervals between UI frames (ms) while a render was running, repainting continuously.
    pub frame_ms: Vec<f64>,
    pub frame_ms_mean: f64,
    pub frame_ms_p95: f64,
    pub frame_ms_max: f64,
    pub first_image_max_seconds: f64,
    /// Time spent in the workbench's own UI code per frame while rendering (ms): layout,
    /// texture updates; the rest of a frame is egui's tessellation and the GL painting.
    pub ui_code_ms_mean: f64,
    pub ui_code_ms_max: f64,
    /// Frame intervals (ms) with no render running, for comparison (the cost of painting the
    /// window on this machine's GL).
    pub idle_frame_ms_mean: f64,
    #[serde(skip)]
    ui_code_ms: Vec<f64>,
    #[serde(skip)]
    idle_ms: Vec<f64>,
}

enum MeasurePhase {
    Warmup(Instant),
    /// Change k was made at the instant; waiting for its first image.
    Waiting(u32, Instant, u64),
    /// Change k's first image arrived; timing frames while the render runs.
    Rendering(u32, Instant),
    Done(u32),
}

/// `penumbra gui --measure FILE`: after the first render finishes, turns the camera 12 times;
/// for each change records the time to the first coarse image and the UI frame intervals
/// while the new render runs; writes the figures as JSON and quits.
struct Measure {
    app: WorkbenchApp,
    path: PathBuf,
    phase: MeasurePhase,
    result: Measurement,
    last: Option<Instant>,
}

impl eframe::App for Measure {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let now = Instant::now();
        self.app.ui(ui, frame);
        let code_ms = now.elapsed().as_secs_f64() * 1e3;
        ui.ctx().request_repaint();
        let busy = self.app.worker.is_busy();
        if let Some(prev) = self.last {
            if busy {
                self.result.ui_code_ms.push(code_ms);
            } else {
                self.result.idle_ms.push((now - prev).as_secs_f64() * 1e3);
            }
        }
        match self.phase {
            MeasurePhase::Warmup(t0) => {
                if self.app.render_finished() || t0.elapsed().as_secs_f64() > 60.0 {
                    self.app.orbit.orbit(15.0, 0.0);
                    self.phase = MeasurePhase::Waiting(0, now, self.app.worker.generation());
                }
            }
            MeasurePhase::Waiting(k, t0, generation) => {
                // The request goes out at the end of the frame that changed the camera.
                let newest = self.app.worker.generation();
                if newest > generation && self.app.worker.latest().is_some() {
                    self.result
                        .first_image_seconds
                        .push(t0.elapsed().as_secs_f64());
                    self.phase = MeasurePhase::Rendering(k, now);
                }
            }
            MeasurePhase::Rendering(k, t0) => {
                if let Some(prev) = self.last
                    && busy
                {
                    self.result.frame_ms.push((now - prev).as_secs_f64() * 1e3);
                }
                if !busy || t0.elapsed().as_secs_f64() > 3.0 {
                    if k + 1 == 12 {
                        self.phase = MeasurePhase::Done(0);
                    } else {
                        self.app.orbit.orbit(15.0, 0.0);
                        self.phase =
                            MeasurePhase::Waiting(k + 1, now, self.app.worker.generation());
                    }
                }
            }
            MeasurePhase::Done(n) => {
                if n == 0 {
                    let r = &mut self.result;
                    r.window = (
                        ui.ctx().content_rect().width(),
                        ui.ctx().content_rect().height(),
                    );
                    r.render_size = self.app.render_size;
                    r.method = self.app.settings.method.name().into();
                    let mut v = r.frame_ms.clone();
                    v.sort_by(f64::total_cmp);
                    if !v.is_empty() {
                        r.frame_ms_mean = v.iter().sum::<f64>() / v.len() as f64;
                        r.frame_ms_p95 = v[(v.len() * 95 / 100).min(v.len() - 1)];
                        r.frame_ms_max = *v.last().unwrap_or(&0.0);
                    }
                    r.first_image_max_seconds =
                        r.first_image_seconds.iter().copied().fold(0.0, f64::max);
                    let mean = |v: &[f64]| {
                        if v.is_empty() {
                            0.0
                        } else {
                            v.iter().sum::<f64>() / v.len() as f64
                        }
                    };
                    r.ui_code_ms_mean = mean(&r.ui_code_ms);
                    r.ui_code_ms_max = r.ui_code_ms.iter().copied().fold(0.0, f64::max);
                    r.idle_frame_ms_mean = mean(&r.idle_ms);
                    write_measurement(&self.path, r);
                }
                if n > 2 {
                    ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                }
                self.phase = MeasurePhase::Done(n + 1);
            }
        }
        self.last = Some(now);
    }
}

/// Writes a measurement as JSON (`--measure`, `--measure-drag`); errors go to stderr, since
/// the window is closing.
fn write_measurement(path: &std::path::Path, m: &impl serde::Serialize) {
    match serde_json::to_string_pretty(m) {
        Ok(s) => {
            if let Err(e) = std::fs::write(path, s) {
                eprintln!("{}: {e}", path.display());
            }
        }
        Err(e) => eprintln!("{e}"),
    }
}

/// Latency of moving an object in the workbench, measured in the real window
/// (`penumbra gui --measure-drag FILE`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct DragMeasurement {
    pub window: (f32, f32),
    pub render_size: (u32, u32),
    pub method: String,
    pub scene: String,
    pub object: String,
    /// `RenderContext::with_moved_object` per update (ms).
    pub prepare_ms: Vec<f64>,
    /// From the update to the end of the frame that drew the new recording (the sphere view
    /// redrawn, painted), ms.
    pub sphere_ms: Vec<f64>,
    /// From the update to the first (coarse) image of the moved scene, ms.
    pub first_image_ms: Vec<f64>,
    pub prepare_ms_max: f64,
    pub sphere_ms_max: f64,
    pub first_image_ms_max: f64,
}

enum DragPhase {
    Warmup(Instant),
    /// Update k happens at the start of the next frame.
    Step(u32),
    /// Update k was made at the instant; the frame drawing it is being painted.
    Painted(u32, Instant, u64),
    /// Waiting for update k's first image.
    Waiting(u32, Instant, u64),
    Done(u32),
}

struct MeasureDrag {
    app: WorkbenchApp,
    path: PathBuf,
    phase: DragPhase,
    result: DragMeasurement,
    object: Option<usize>,
}

impl eframe::App for MeasureDrag {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let now = Instant::now();
        ui.ctx().request_repaint();
        const UPDATES: u32 = 12;
        // An update is made at the start of a frame, so that this frame draws it.
        if let DragPhase::Step(k) = self.phase {
            let generation = self.app.worker.generation();
            if let Some(object) = self.object {
                // Back and forth along x by up to 0.12 (scene units), as a hand would drag.
                let x = 0.04 * ((k % 6) as f64 - 2.5);
                let delta = crate::scene::edit::Rigid::translation(glam::DVec3::new(x, 0.0, 0.0));
                if let Some(ms) = self.app.drag_step(object, delta) {
                    self.result.prepare_ms.push(ms);
                }
            }
            self.phase = DragPhase::Painted(k, now, generation);
        } else if let DragPhase::Painted(k, t0, generation) = self.phase {
            // This frame starts after the previous one (which drew the update) was painted.
            self.result.sphere_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            self.phase = DragPhase::Waiting(k, t0, generation);
        }
        self.app.ui(ui, frame);
        match self.phase {
            DragPhase::Warmup(t0) => {
                let ready = self.app.render_finished() && self.app.inspector.is_some();
                if ready || t0.elapsed().as_secs_f64() > 60.0 {
                    self.object = self.app.picked_occluder();
                    if let (Some(o), Some(ctx)) = (self.object, &self.app.ctx) {
                        self.result.object = ctx.scene.objects[o].name.clone();
                    }
                    self.phase = DragPhase::Step(0);
                }
            }
            DragPhase::Waiting(k, t0, generation) => {
                let arrived = self
                    .app
                    .worker
                    .latest()
                    .is_some_and(|f| f.generation > generation);
                if arrived {
                    self.result
                        .first_image_ms
                        .push(t0.elapsed().as_secs_f64() * 1e3);
                }
                if arrived || t0.elapsed().as_secs_f64() > 5.0 {
                    self.phase = if k + 1 == UPDATES {
                        self.app.editor.end_scripted_drag();
                        DragPhase::Done(0)
                    } else {
                        DragPhase::Step(k + 1)
                    };
                }
            }
            DragPhase::Done(0) => {
                let r = &mut self.result;
                r.window = (
                    ui.ctx().content_rect().width(),
                    ui.ctx().content_rect().height(),
                );
                r.render_size = self.app.render_size;
                r.method = self.app.settings.method.name().into();
                r.scene = self.app.settings.scene.clone();
                let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
                r.prepare_ms_max = max(&r.prepare_ms);
                r.sphere_ms_max = max(&r.sphere_ms);
                r.first_image_ms_max = max(&r.first_image_ms);
                write_measurement(&self.path, r);
                self.phase = DragPhase::Done(1);
            }
            DragPhase::Done(_) => ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close),
            _ => {}
        }
    }

    fn save(&mut self, _storage: &mut dyn eframe::Storage) {}
}
