//! The egui workbench: a progressive viewport, the picked point's stages on the unit sphere,
//! plots and exports. It draws what the library computed (the renderer's frames, the
//! recording of `shade` at the picked point); it computes no geometry of its own.
//!
//! * [`viewport`]: the render thread (progressive, cancelled on every change).
//! * [`tonemap`]: AOVs and display colours.
//! * [`orbit`]: the orbit camera.
//! * [`inspector`], [`stages`], [`sphere_view`], [`planar_view`]: the picked point.
//! * [`files`]: scenes, dumps, bench reports, images, the CLI command.

pub mod bench_job;
pub mod environment_panel;
pub mod files;
pub mod inspector;
pub mod light_view;
pub mod orbit;
pub mod planar_view;
pub mod sphere_view;
pub mod stages;
pub mod tonemap;
pub mod viewport;

use crate::bench::BenchReport;
use crate::inspect::{MonteCarloEstimate, correction_stream, monte_carlo, probe_corrected};
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::scene_file;
use crate::shading::{CorrectionSampling, Method};
use egui::{Color32, Key, RichText, Sense, TextureHandle, TextureOptions, Ui};
use files::Opened;
use inspector::Inspector;
use orbit::OrbitCamera;
use sphere_view::SphereView;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use tonemap::{Aov, ToneMap};
use viewport::{RenderWorker, frame_image};

/// What is kept between sessions.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Persisted {
    pub scene: String,
    pub orbit: Option<OrbitCamera>,
    pub method: RenderMethod,
    pub spp: u32,
    pub passes: u32,
    pub aa: u32,
    pub exposure: f64,
    pub tonemap: ToneMap,
    pub aov: Aov,
    pub resolution: f32,
    pub dark: bool,
    pub recent: Vec<String>,
    pub sphere: SphereView,
    /// The environment panel's choice (a scene file's `[environment]` replaces the map,
    /// rotation and scale when it loads; a scene without one starts with none).
    #[serde(default)]
    pub environment: environment_panel::EnvironmentChoice,
}

impl Default for Persisted {
    fn default() -> Self {
        Persisted {
            scene: "default".into(),
            orbit: None,
            method: RenderMethod::Analytic,
            spp: 4,
            passes: 64,
            aa: 1,
            exposure: 0.0,
            tonemap: ToneMap::Clamp,
            aov: Aov::Final,
            resolution: 1.0,
            dark: true,
            recent: Vec::new(),
            sphere: SphereView::default(),
            environment: Default::default(),
        }
    }
}

/// Progressive error against a loaded reference, over time.
#[derive(Default)]
struct ErrorTrace {
    reference: Option<Image>,
    /// (seconds since the render started, RMSE) per frame at full resolution.
    points: Vec<(f64, f64)>,
    generation: u64,
}

/// The workbench.
pub struct WorkbenchApp {
    pub state: Persisted,
    ctx: Option<Arc<RenderContext>>,
    scene_error: Option<String>,
    orbit: OrbitCamera,
    worker: RenderWorker,
    requested: Option<(u64, String)>,
    scene_generation: u64,
    texture: Option<TextureHandle>,
    /// (generation, scale, passes, display key) of the frame in the texture.
    shown: Option<(u64, u32, u32, String)>,
    scalar_range: Option<(f64, f64)>,
    render_size: (u32, u32),
    pub inspector: Option<Inspector>,
    monte_carlo: Option<MonteCarloEstimate>,
    bench: Option<BenchReport>,
    trace: ErrorTrace,
    pub status: String,
    show_help: bool,
    show_plots: bool,
    last_frame: Instant,
    /// UI frame times (ms), for the status bar.
    frame_ms: f64,
    pending_screenshot: Option<(PathBuf, Option<egui::Rect>)>,
    sphere_rect: Option<egui::Rect>,
    /// Where the viewport was drawn in the last frame (points).
    pub viewport_rect: Option<egui::Rect>,
    bench_job: Option<bench_job::BenchJob>,
    bench_size: (u32, u32),
    /// The light whose polyhedron the structure view shows (index into the prepared lights).
    selected_light: Option<usize>,
    pub light_view: light_view::LightView,
    /// Scroll the settings panel to the light structure view in the next frame (it sits at the
    /// bottom of a long panel, out of sight in a window of ordinary height).
    reveal_light: bool,
    /// Scroll the inspector panel to the sphere (or planar) view in the next frame.
    reveal_views: bool,
    /// Read silhouettes from the BSP trees (as the renderer does by default); off, every
    /// silhouette is computed at its point, and the recording then holds the contour pieces
    /// the exact silhouette's ray test rejected there.
    pub use_trees: bool,
    env_panel: environment_panel::EnvironmentPanel,
    env_maps: environment_panel::MapCache,
}

/// Keyboard shortcuts, listed in the help panel.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("→ / Space", "next stage"),
    ("←", "previous stage"),
    ("Home", "show all stages"),
    ("P", "play / pause the stages"),
    ("R", "reset the camera"),
    ("Ctrl+S", "save the rendered image"),
    ("Ctrl+D", "save the debug dump of the picked point"),
    ("Ctrl+O", "open a scene, dump, bench report or reference"),
    ("F12", "screenshot of the window"),
    ("F1", "this help"),
    ("drag", "orbit (left), pan (right or middle); scroll: zoom"),
    ("click", "pick a pixel"),
];

impl WorkbenchApp {
    /// A workbench on `state.scene`; `repaint` wakes the UI when a frame is ready.
    pub fn new(state: Persisted, repaint: impl Fn() + Send + Sync + 'static) -> Self {
        let mut app = WorkbenchApp {
            orbit: OrbitCamera {
                target: glam::DVec3::ZERO,
                distance: 5.0,
                yaw: 0.0,
                pitch: 0.3,
                fov_deg: 45.0,
            },
            ctx: None,
            scene_error: None,
            worker: RenderWorker::start(repaint),
            requested: None,
            scene_generation: 0,
            texture: None,
            shown: None,
            scalar_range: None,
            render_size: (0, 0),
            inspector: None,
            monte_carlo: None,
            bench: None,
            trace: ErrorTrace::default(),
            status: String::new(),
            show_help: false,
            show_plots: false,
            last_frame: Instant::now(),
            frame_ms: 0.0,
            pending_screenshot: None,
            sphere_rect: None,
            viewport_rect: None,
            bench_job: None,
            bench_size: (160, 120),
            selected_light: None,
            light_view: light_view::LightView::default(),
            reveal_light: false,
            reveal_views: false,
            use_trees: true,
            env_panel: Default::default(),
            env_maps: Default::default(),
            state,
        };
        let scene = app.state.scene.clone();
        let orbit = app.state.orbit;
        app.load_scene(&scene);
        if let Some(o) = orbit {
            app.orbit = o;
        }
        app
    }

    /// Creates the app inside eframe (restoring the persisted state).
    pub fn from_creation_context(cc: &eframe::CreationContext<'_>) -> Self {
        let state: Persisted = cc
            .storage
            .and_then(|s| eframe::get_value(s, eframe::APP_KEY))
            .unwrap_or_default();
        let ctx = cc.egui_ctx.clone();
        let app = WorkbenchApp::new(state, move || ctx.request_repaint());
        app.apply_theme(&cc.egui_ctx);
        app
    }

    fn apply_theme(&self, ctx: &egui::Context) {
        ctx.set_visuals(if self.state.dark {
            egui::Visuals::dark()
        } else {
            egui::Visuals::light()
        });
    }

    /// Loads a scene (embedded name or path) and resets the camera to the scene's.
    pub fn load_scene(&mut self, name: &str) {
        match files::load_scene(name) {
            Ok(scene) => self.set_scene(name.to_string(), scene),
            Err(e) => {
                self.scene_error = Some(format!("{e:#}"));
                self.status = format!("could not load {name}: {e:#}");
            }
        }
    }

    fn set_scene(&mut self, name: String, scene: crate::scene::Scene) {
        if let Some(cam) = scene.camera {
            self.orbit = OrbitCamera::from_camera(&cam);
        }
        self.status = format!(
            "{name}: {} objects{}",
            scene.objects.len(),
            if scene.warnings.is_empty() {
                String::new()
            } else {
                format!(", {} warnings", scene.warnings.len())
            }
        );
        self.state.environment = self.state.environment.from_spec(scene.environment.as_ref());
        self.ctx = Some(self.context(Arc::new(scene)));
        self.scene_error = None;
        self.scene_generation += 1;
        self.inspector = None;
        self.monte_carlo = None;
        self.state.recent.retain(|r| *r != name);
        self.state.recent.insert(0, name.clone());
        self.state.recent.truncate(8);
        self.state.scene = name;
    }

    /// The render context of `scene`, with or without its silhouette trees, lit by the
    /// environment panel's choice.
    fn context(&mut self, scene: Arc<crate::scene::Scene>) -> Arc<RenderContext> {
        let mut ctx = RenderContext::from_arc(scene);
        if !self.use_trees {
            ctx.prepared.drop_silhouette_trees();
        }
        if let Some((light, settings)) = self.environment_light() {
            ctx.set_environment(light, settings);
        }
        Arc::new(ctx)
    }

    /// The light and settings of the environment panel's choice (`None`: no environment, or
    /// the map failed to load, said in the panel).
    fn environment_light(
        &mut self,
    ) -> Option<(
        Arc<crate::environment::EnvironmentLight>,
        crate::render::environment::EnvironmentSettings,
    )> {
        match self.env_maps.light(&self.state.environment) {
            Ok(light) => {
                self.env_panel.error = None;
                light.map(|l| (l, self.state.environment.settings()))
            }
            Err(e) => {
                let msg = format!("environment: {e:#}");
                self.status = msg.clone();
                self.env_panel.error = Some(msg);
                None
            }
        }
    }

    /// Lights the scene with `choice` (the environment panel, a dropped map): the prepared
    /// scene is copied with the new light, the progressive render restarts, and the picked
    /// pixel (if any) is picked again.
    pub fn set_environment(&mut self, choice: environment_panel::EnvironmentChoice) {
        self.state.environment = choice;
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        let env = self.environment_light();
        self.ctx = Some(Arc::new(ctx.with_environment(env)));
        self.context_replaced();
    }

    /// After the render context changed under the same scene: render again, and pick the
    /// picked pixel (if any) again.
    fn context_replaced(&mut self) {
        self.scene_generation += 1;
        self.monte_carlo = None;
        if let Some(ins) = &self.inspector
            && ins.probe.scene == self.state.scene
        {
            let (x, y) = ins.probe.pixel;
            self.pick(x, y);
        }
    }

    /// Switches the silhouette trees on or off: the scene is prepared again, rendered again,
    /// and the picked pixel (if any) picked again.
    pub fn set_use_trees(&mut self, on: bool) {
        self.use_trees = on;
        let Some(scene) = self.ctx.as_ref().map(|c| c.scene.clone()) else {
            return;
        };
        self.ctx = Some(self.context(scene));
        self.context_replaced();
    }

    /// The settings of the full-resolution render.
    pub fn settings(&self) -> RenderSettings {
        RenderSettings {
            width: self.render_size.0.max(1),
            height: self.render_size.1.max(1),
            aa: self.state.aa.max(1),
            method: self.state.method,
            spp: self.state.spp.max(1),
            seed: 1,
            light_sampling: crate::stochastic::LightSampling::SolidAngle,
            collect_stats: matches!(
                self.state.aov,
                Aov::OccludersKept | Aov::SilhouetteEdges | Aov::Cost
            ),
            exact_u: false,
        }
    }

    /// Starts a new render if anything it depends on changed.
    fn maybe_request(&mut self) {
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        if self.render_size.0 == 0 {
            return;
        }
        let settings = self.settings();
        let camera = self.orbit.camera();
        let key = format!(
            "{}|{:?}|{:?}|{}",
            self.scene_generation, camera, settings, self.state.passes
        );
        if self.requested.as_ref().is_some_and(|(_, k)| *k == key) {
            return;
        }
        let generation = self
            .worker
            .request(ctx, camera, settings, self.state.passes.max(1));
        self.requested = Some((generation, key));
        self.trace.points.clear();
        self.trace.generation = generation;
    }

    /// Picks pixel (x, y) of the full-resolution image: the same primary hit and `shade` as
    /// the renderer, with the recorder on.
    pub fn pick(&mut self, x: f64, y: f64) {
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        let method = self.state.method.analytic().unwrap_or(Method::Analytic);
        // analytic-exact records the LTC's correction too, sampled as the render's first pass
        // samples this pixel (at `--aa 1`).
        let correction = (self.state.method == RenderMethod::AnalyticExact).then(|| {
            let s = self.settings();
            CorrectionSampling {
                samples: s.spp,
                seed: s.seed,
                stream: correction_stream((x, y), self.render_size.0),
            }
        });
        let cam = self.orbit.camera();
        match probe_corrected(
            &ctx,
            &self.state.scene,
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
                self.inspector = Some(Inspector::new(p));
                self.monte_carlo = None;
            }
            Err(e) => self.status = format!("pick failed: {e}"),
        }
    }

    /// The Monte Carlo check of the picked point, computed on demand.
    pub fn run_monte_carlo(&mut self, samples: u32) {
        let (Some(ctx), Some(ins)) = (&self.ctx, &self.inspector) else {
            return;
        };
        if let (Some(sp), Some(m)) = (ins.probe.point, ins.probe.material.as_ref()) {
            self.monte_carlo = Some(monte_carlo(ctx, &sp, m, samples, 7));
        }
    }

    /// Opens a file of any kind the workbench knows.
    pub fn open_path(&mut self, path: &std::path::Path) {
        match files::open(path) {
            Ok(Opened::Scene(name, scene)) => self.set_scene(name, scene),
            Ok(Opened::Dump(p)) => {
                self.status = format!("replaying the dump {}", path.display());
                self.inspector = Some(Inspector::new(*p));
                self.monte_carlo = None;
            }
            Ok(Opened::Bench(r)) => {
                self.status = format!("bench report of {}", r.scene);
                self.bench = Some(*r);
                self.show_plots = true;
            }
            Ok(Opened::Environment(p)) => {
                let mut choice = self.state.environment.clone();
                choice.map = environment_panel::MapChoice::File(p);
                self.set_environment(choice);
            }
            Ok(Opened::Reference(img)) => {
                self.status = format!("reference {}×{} loaded", img.width, img.height);
                self.trace.reference = Some(img);
                self.trace.points.clear();
                self.show_plots = true;
            }
            Err(e) => self.status = format!("{e:#}"),
        }
    }

    /// Shows the light named `name` in the light structure view (a status message if none).
    pub fn select_light(&mut self, name: &str) {
        let found = self.ctx.as_ref().and_then(|ctx| {
            ctx.prepared
                .lights
                .iter()
                .position(|&(id, _)| ctx.prepared.objects[id as usize].name == name)
        });
        match found {
            Some(l) => {
                self.selected_light = Some(l);
                self.reveal_light = true;
            }
            None => self.status = format!("no light named '{name}'"),
        }
    }

    /// Uploads the newest frame (or re-maps the shown one after a display change).
    fn update_texture(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.worker.latest() else {
            return;
        };
        let display_key = format!(
            "{:?}|{}|{:?}",
            self.state.aov, self.state.exposure, self.state.tonemap
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
            aov: self.state.aov,
            exposure: self.state.exposure,
            tonemap: self.state.tonemap,
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

    fn handle_input(&mut self, ctx: &egui::Context) {
        let (dropped, keys) = ctx.input(|i| {
            (
                i.raw.dropped_files.clone(),
                (
                    i.key_pressed(Key::ArrowRight) || i.key_pressed(Key::Space),
                    i.key_pressed(Key::ArrowLeft),
                    i.key_pressed(Key::Home),
                    i.key_pressed(Key::P),
                    i.key_pressed(Key::R),
                    i.modifiers.command && i.key_pressed(Key::S),
                    i.modifiers.command && i.key_pressed(Key::D),
                    i.modifiers.command && i.key_pressed(Key::O),
                    i.key_pressed(Key::F12),
                    i.key_pressed(Key::F1),
                ),
            )
        });
        for f in dropped {
            let p = f.path().to_path_buf();
            if !p.as_os_str().is_empty() {
                self.open_path(&p);
            }
        }
        let typing = ctx.egui_wants_keyboard_input();
        let (next, prev, home, play, reset, save, dump, open, shot, help) = keys;
        if !typing {
            if let Some(ins) = &mut self.inspector {
                if next {
                    ins.next();
                }
                if prev {
                    ins.previous();
                }
                if home {
                    ins.step = None;
                }
                if play {
                    ins.playing = !ins.playing;
                }
            }
            if reset && let Some(cam) = self.ctx.as_ref().and_then(|c| c.scene.camera) {
                self.orbit = OrbitCamera::from_camera(&cam);
            }
        }
        if save {
            self.save_image_dialog();
        }
        if dump {
            self.save_dump_dialog();
        }
        if open {
            self.open_dialog();
        }
        if shot {
            self.screenshot_dialog(None);
        }
        if help {
            self.show_help = !self.show_help;
        }
    }

    fn open_dialog(&mut self) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter(
                "penumbra files",
                &["toml", "obj", "json", "pfm", "hdr", "exr"],
            )
            .pick_file()
        {
            self.open_path(&p);
        }
    }

    fn save_image_dialog(&mut self) {
        let Some(frame) = self.worker.latest() else {
            return;
        };
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("image", &["png", "pfm", "exr"])
            .set_file_name("render.png")
            .save_file()
        {
            self.status =
                match files::save_image(&frame.frame.output.image, &p, self.state.exposure) {
                    Ok(()) => format!("wrote {}", p.display()),
                    Err(e) => format!("{e:#}"),
                };
        }
    }

    fn save_dump_dialog(&mut self) {
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
    fn screenshot_dialog(&mut self, crop: Option<egui::Rect>) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("PNG", &["png"])
            .set_file_name("penumbra.png")
            .save_file()
        {
            self.pending_screenshot = Some((p, crop));
        }
    }

    /// Requests a screenshot to `path` (of `crop` in points, or the whole window).
    pub fn screenshot_to(&mut self, path: PathBuf, crop: Option<egui::Rect>) {
        self.pending_screenshot = Some((path, crop));
    }

    fn take_pending_screenshot(&mut self, ctx: &egui::Context) {
        let Some((path, crop)) = self.pending_screenshot.take() else {
            return;
        };
        let ppp = ctx.pixels_per_point();
        ctx.request_screenshot(move |img| {
            let img = match crop {
                Some(r) => img.region(&r, Some(ppp)),
                None => (*img).clone(),
            };
            if let Err(e) = files::save_screenshot(&img, &path) {
                eprintln!("screenshot: {e:#}");
            }
        });
        self.status = "screenshot requested".into();
    }

    fn menu_ui(&mut self, ui: &mut Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open… (Ctrl+O)").clicked() {
                    self.open_dialog();
                }
                ui.menu_button("Embedded scenes", |ui| {
                    for name in scene_file::embedded_scene_names() {
                        if ui.button(*name).clicked() {
                            self.load_scene(name);
                        }
                    }
                });
                ui.menu_button("Recent", |ui| {
                    for r in self.state.recent.clone() {
                        if ui.button(&r).clicked() {
                            self.load_scene(&r);
                        }
                    }
                });
                ui.separator();
                if ui.button("Save image… (Ctrl+S)").clicked() {
                    self.save_image_dialog();
                }
                if ui.button("Save debug dump… (Ctrl+D)").clicked() {
                    self.save_dump_dialog();
                }
                if ui.button("Screenshot of the window… (F12)").clicked() {
                    self.screenshot_dialog(None);
                }
                if ui.button("Screenshot of the sphere view…").clicked() {
                    let r = self.sphere_rect;
                    self.screenshot_dialog(r);
                }
                if ui.button("Copy CLI command").clicked() {
                    let passes = self.worker.latest().map_or(1, |f| f.frame.passes);
                    let mut s = self.settings();
                    s.spp *= passes;
                    let cmd = files::cli_command(
                        &self.state.scene,
                        &self.orbit.camera(),
                        &s,
                        self.state.exposure,
                    );
                    ui.ctx().copy_text(cmd.clone());
                    self.status = format!("copied: {cmd}");
                }
            });
            ui.menu_button("View", |ui| {
                if ui.checkbox(&mut self.state.dark, "dark theme").changed() {
                    self.apply_theme(ui.ctx());
                }
                ui.checkbox(&mut self.show_plots, "plots");
                ui.checkbox(&mut self.show_help, "help (F1)");
            });
        });
    }

    fn settings_ui(&mut self, ui: &mut Ui) {
        ui.heading("Render");
        egui::ComboBox::from_label("method")
            .selected_text(self.state.method.name())
            .show_ui(ui, |ui| {
                for m in RenderMethod::ALL {
                    ui.selectable_value(&mut self.state.method, m, m.name());
                }
            });
        if self.state.method.is_stochastic() {
            ui.add(
                egui::Slider::new(&mut self.state.spp, 1..=256)
                    .logarithmic(true)
                    .text("spp per pass"),
            );
            ui.add(
                egui::Slider::new(&mut self.state.passes, 1..=1024)
                    .logarithmic(true)
                    .text("passes"),
            );
        }
        ui.add(egui::Slider::new(&mut self.state.aa, 1..=4).text("AA (N×N)"));
        ui.add(egui::Slider::new(&mut self.state.resolution, 0.25..=1.0).text("resolution"));
        ui.separator();
        ui.heading("Display");
        egui::ComboBox::from_label("AOV")
            .selected_text(self.state.aov.label())
            .show_ui(ui, |ui| {
                for a in Aov::ALL {
                    ui.selectable_value(&mut self.state.aov, a, a.label());
                }
            });
        ui.add(egui::Slider::new(&mut self.state.exposure, -8.0..=8.0).text("exposure (stops)"));
        ui.horizontal(|ui| {
            ui.label("tone map");
            ui.selectable_value(&mut self.state.tonemap, ToneMap::Clamp, "clamp");
            ui.selectable_value(&mut self.state.tonemap, ToneMap::Reinhard, "Reinhard");
        });
        if let Some((lo, hi)) = self.scalar_range
            && !self.state.aov.is_radiance()
        {
            ui.label(format!("false colour: {lo:.3} … {hi:.3}"));
        }
        ui.separator();
        ui.heading("Environment");
        let mut choice = self.state.environment.clone();
        if self.env_panel.ui(ui, &mut choice) {
            self.set_environment(choice);
        }
        ui.separator();
        self.scene_ui(ui);
    }

    fn scene_ui(&mut self, ui: &mut Ui) {
        ui.heading("Scene");
        ui.label(&self.state.scene);
        if let Some(e) = &self.scene_error {
            ui.colored_label(Color32::LIGHT_RED, e);
        }
        let mut use_trees = self.use_trees;
        ui.checkbox(&mut use_trees, "silhouettes from BSP trees")
            .on_hover_text(
                "Off: every silhouette is computed at its point, and the sphere view can show \
                 the contour pieces the exact silhouette's ray test rejected there (a tree \
                 stores only the result).",
            );
        if use_trees != self.use_trees {
            self.set_use_trees(use_trees);
        }
        let Some(ctx) = &self.ctx else {
            return;
        };
        egui::ScrollArea::vertical()
            .id_salt("objects")
            .max_height(220.0)
            .show(ui, |ui| {
                egui::Grid::new("objects_grid")
                    .striped(true)
                    .show(ui, |ui| {
                        ui.strong("object");
                        ui.strong("flags");
                        ui.strong("shape");
                        ui.end_row();
                        for (i, o) in ctx.scene.objects.iter().enumerate() {
                            ui.label(&o.name);
                            let mut f = Vec::new();
                            if o.flags.light && o.material.is_emissive() {
                                f.push("light");
                            }
                            if o.flags.occluder {
                                f.push("occluder");
                            }
                            if o.flags.receiver {
                                f.push("receiver");
                            }
                            ui.label(f.join(", "));
                            let shape = ctx
                                .prepared
                                .objects
                                .iter()
                                .find(|p| p.object == i as u32)
                                .map(|p| p.path().label())
                                .unwrap_or("receiver only");
                            ui.label(shape);
                            ui.end_row();
                        }
                    });
            });
        for w in ctx.scene.warnings.iter().chain(&ctx.prepared.notes) {
            ui.small(w);
        }
        ui.separator();
        ui.heading("Light structure");
        let names: Vec<String> = ctx
            .prepared
            .lights
            .iter()
            .map(|&(id, _)| ctx.prepared.objects[id as usize].name.clone())
            .collect();
        egui::ComboBox::from_label("light")
            .selected_text(
                self.selected_light
                    .and_then(|l| names.get(l).cloned())
                    .unwrap_or_else(|| "none".into()),
            )
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.selected_light, None, "none");
                for (i, n) in names.iter().enumerate() {
                    ui.selectable_value(&mut self.selected_light, Some(i), n);
                }
            });
        if let Some(l) = self.selected_light
            && let Some(&(id, _)) = ctx.prepared.lights.get(l)
        {
            let obj = &ctx.prepared.objects[id as usize];
            let point = self
                .inspector
                .as_ref()
                .and_then(|i| i.probe.point)
                .map(|p| p.position);
            self.light_view.ui(ui, obj, point);
            if std::mem::take(&mut self.reveal_light) {
                ui.scroll_to_cursor_animation(
                    Some(egui::Align::Max),
                    egui::style::ScrollAnimation::none(),
                );
            }
        }
    }

    fn viewport_ui(&mut self, ui: &mut Ui) {
        let avail = ui.available_size();
        let ppp = ui.ctx().pixels_per_point();
        let scale = self.state.resolution.clamp(0.1, 1.0) * ppp;
        let size = (
            ((avail.x * scale) as u32).clamp(16, 4096),
            ((avail.y * scale) as u32).clamp(16, 4096),
        );
        self.render_size = size;
        let (resp, painter) = ui.allocate_painter(avail, Sense::click_and_drag());
        resp.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::Canvas, true, "viewport: click to pick a pixel")
        });
        let rect = resp.rect;
        self.viewport_rect = Some(rect);
        if let Some(t) = &self.texture {
            painter.image(
                t.id(),
                rect,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                Color32::WHITE,
            );
        } else {
            painter.rect_filled(rect, 0.0, Color32::BLACK);
        }
        // Camera.
        if resp.dragged_by(egui::PointerButton::Primary) {
            let d = resp.drag_delta();
            self.orbit.orbit(d.x as f64, d.y as f64);
        }
        if resp.dragged_by(egui::PointerButton::Secondary)
            || resp.dragged_by(egui::PointerButton::Middle)
        {
            let d = resp.drag_delta();
            self.orbit.pan(d.x as f64, d.y as f64, rect.height() as f64);
        }
        if resp.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.orbit.zoom(scroll as f64 / 40.0);
            }
        }
        if resp.clicked()
            && let Some(pos) = resp.interact_pointer_pos()
        {
            let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
            let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
            self.pick(x, y);
        }
        // Mark the picked pixel.
        if let Some(ins) = &self.inspector
            && ins.probe.size == size
        {
            let (px, py) = ins.probe.pixel;
            let p = egui::pos2(
                rect.min.x + ((px as f32 + 0.5) / size.0 as f32) * rect.width(),
                rect.min.y + ((py as f32 + 0.5) / size.1 as f32) * rect.height(),
            );
            painter.circle_stroke(
                p,
                6.0,
                egui::Stroke::new(2.0, Color32::from_rgb(255, 0, 255)),
            );
        }
    }

    fn status_ui(&mut self, ui: &mut Ui) {
        ui.horizontal(|ui| {
            match self.worker.latest() {
                Some(f) => {
                    let fr = &f.frame;
                    let (w, h) = (fr.output.image.width, fr.output.image.height);
                    let px = (w * h) as f64 * fr.passes as f64;
                    let env = match (&fr.output.environment, &self.state.environment) {
                        (Some(_), c) => format!(" + environment {}", c.method.name()),
                        _ => String::new(),
                    };
                    ui.label(format!(
                        "{}{env} {}×{} (1/{}), pass {}, {} spp, {:.2} s, {:.0} kpixels/s{}",
                        f.settings.method.name(),
                        w,
                        h,
                        fr.scale,
                        fr.passes,
                        fr.spp,
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

    fn inspector_ui(&mut self, ui: &mut Ui) {
        let Some(ins) = &mut self.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        ins.numbers_ui(ui, self.monte_carlo.as_ref());
        ins.environment_ui(ui);
        let mut mc = false;
        ui.horizontal(|ui| {
            mc = ui.button("Monte Carlo check (65536 samples)").clicked();
        });
        ui.separator();
        ins.stepper_ui(ui);
        ui.separator();
        let before = ui.cursor().min;
        ins.views_ui(ui, &mut self.state.sphere);
        // Room for the horizontal scroll bar, which floats over the content's bottom edge.
        ui.add_space(16.0);
        let after = ui.min_rect().max;
        self.sphere_rect = Some(egui::Rect::from_min_max(before, after));
        if std::mem::take(&mut self.reveal_views) {
            ui.scroll_to_rect_animation(
                egui::Rect::from_min_max(before, ui.cursor().min),
                Some(egui::Align::Max),
                egui::style::ScrollAnimation::none(),
            );
        }
        if mc {
            self.run_monte_carlo(65536);
        }
    }

    fn plots_ui(&mut self, ui: &mut Ui) {
        use egui_plot::{Legend, Line, Plot, PlotPoints, Points};
        ui.horizontal(|ui| {
            if ui.button("Load bench JSON or reference PFM…").clicked() {
                self.open_dialog();
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
                    if ui.button("Run bench on this view").clicked()
                        && let Some(ctx) = self.ctx.clone()
                    {
                        self.bench_job = Some(bench_job::BenchJob::start(
                            ctx,
                            self.state.scene.clone(),
                            self.orbit.camera(),
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
                        self.status = format!(
                            "bench done: {}",
                            files
                                .first()
                                .map(|f| f.display().to_string())
                                .unwrap_or_default()
                        );
                        self.bench = Some(report);
                        self.bench_job = None;
                    }
                    Some(Err(e)) => {
                        self.status = format!("bench failed: {e}");
                        self.bench_job = None;
                    }
                }
            }
        }
        if let Some(r) = &self.bench {
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
        if self.trace.reference.is_some() {
            ui.label("progressive render: RMSE against the loaded reference over time");
            let pts: Vec<[f64; 2]> = self
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
        egui::Panel::bottom("status").show(ui, |ui| self.status_ui(ui));
        egui::Panel::left("settings")
            .resizable(true)
            .default_size(260.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("settings_scroll")
                    .show(ui, |ui| self.settings_ui(ui));
            });
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(560.0)
            .min_size(460.0)
            .show(ui, |ui| {
                self.state.sphere.width = ui.available_width();
                // Scrolling both ways keeps wide tables from widening the panel (which would
                // resize the viewport and restart the render).
                egui::ScrollArea::both()
                    .id_salt("inspector_scroll")
                    .show(ui, |ui| {
                        ui.heading("Picked point");
                        self.inspector_ui(ui);
                        if self.show_plots {
                            ui.separator();
                            ui.heading("Plots");
                            self.plots_ui(ui);
                        }
                    });
            });
        egui::CentralPanel::default().show(ui, |ui| self.viewport_ui(ui));
        if self.show_help {
            egui::Window::new("Help").open(&mut self.show_help).show(&ctx, |ui| {
                ui.label(RichText::new("Keyboard and mouse").strong());
                egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                    for (k, what) in SHORTCUTS {
                        ui.monospace(*k);
                        ui.label(*what);
                        ui.end_row();
                    }
                });
                ui.label("Drop a .toml/.obj scene, a debug dump or bench .json, or a reference .pfm on the window.");
            });
        }
        self.maybe_request();
        self.take_pending_screenshot(&ctx);
        if self.worker.is_busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// The latest rendered frame, if any (for tests).
    pub fn latest_frame(&self) -> Option<Arc<viewport::ViewFrame>> {
        self.worker.latest()
    }

    /// Whether the render of the current view is complete.
    pub fn render_finished(&self) -> bool {
        self.worker.latest().is_some_and(|f| {
            f.frame.finished && self.requested.as_ref().is_some_and(|r| r.0 == f.generation)
        })
    }
}

impl eframe::App for WorkbenchApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame_ui(ui);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.state.orbit = Some(self.orbit);
        eframe::set_value(storage, eframe::APP_KEY, &self.state);
    }
}

/// What `penumbra gui` does besides showing the window (its command-line flags).
#[derive(Clone, Debug, Default, clap::Args)]
pub struct RunOptions {
    /// A scene file or embedded scene name (default: the last one used).
    pub scene: Option<String>,
    /// Save a screenshot of the window here once the render has finished, then quit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// With --screenshot: take it after at most this many seconds.
    #[arg(long, default_value_t = 30.0)]
    pub after: f64,
    /// Measure responsiveness (time to the first image after a camera change, UI frame
    /// intervals while rendering, as a `Measurement`), write it here as JSON, then quit.
    #[arg(long)]
    pub measure: Option<PathBuf>,
    /// With --screenshot: first pick the pixel at these fractions of the viewport, e.g. 0.5,0.7.
    #[arg(long, value_parser = parse_pair, allow_hyphen_values = true)]
    pub pick: Option<(f64, f64)>,
    /// With --pick: step to this stage (gh, labels, visible, ltc, silhouette:LIGHT for the
    /// silhouette of the light named LIGHT, or a stage number).
    #[arg(long)]
    pub step: Option<String>,
    /// Open these files at start (bench JSON, reference PFM, debug dump).
    #[arg(long)]
    pub open: Vec<PathBuf>,
    /// Render method at start.
    #[arg(long, value_enum)]
    pub method: Option<RenderMethod>,
    /// The environment's shadows at start (the scene needs an environment, or pass --env).
    #[arg(long, value_enum)]
    pub env_method: Option<crate::environment::EnvMethod>,
    /// Light the scene with this environment at start: sky, sky-sh, an .hdr/.exr file, none.
    #[arg(long)]
    pub env: Option<String>,
    /// Show this light (by object name) in the light structure view at start.
    #[arg(long)]
    pub light: Option<String>,
    /// Compute every silhouette at its point instead of reading it from a BSP tree.
    #[arg(long)]
    pub no_trees: bool,
    /// Zoom the sphere view's flat hemisphere to fit the polygons drawn.
    #[arg(long)]
    pub fit: bool,
}

/// Parses "X,Y" into two numbers (command-line flags).
pub fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y, got '{s}'"))?;
    let a: f64 = a.trim().parse().map_err(|e| format!("'{a}': {e}"))?;
    let b: f64 = b.trim().parse().map_err(|e| format!("'{b}': {e}"))?;
    Ok((a, b))
}

/// Opens the workbench window.
pub fn run(opts: RunOptions) -> eframe::Result {
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
            let mut app = WorkbenchApp::from_creation_context(cc);
            if opts.no_trees {
                app.set_use_trees(false);
            }
            if let Some(s) = &opts.scene {
                app.load_scene(s);
            }
            if let Some(m) = opts.method {
                app.state.method = m;
            }
            if opts.env.is_some() || opts.env_method.is_some() {
                let mut choice = app.state.environment.clone();
                if let Some(map) = &opts.env {
                    choice.map = environment_panel::MapChoice::parse(map);
                }
                if let Some(m) = opts.env_method {
                    choice.method = m;
                }
                app.set_environment(choice);
            }
            if opts.fit {
                app.state.sphere.fit = true;
            }
            if let Some(name) = &opts.light {
                app.select_light(name);
            }
            for p in &opts.open {
                app.open_path(p);
            }
            Ok(if let Some(path) = opts.measure.clone() {
                Box::new(Measure {
                    app,
                    path,
                    phase: MeasurePhase::Warmup(Instant::now()),
                    result: Measurement::default(),
                    last: None,
                }) as Box<dyn eframe::App>
            } else if let Some(path) = opts.screenshot.clone() {
                Box::new(AutoScreenshot {
                    app,
                    path,
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
    path: PathBuf,
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
        let find =
            |f: &dyn Fn(&stages::StepKind) -> bool| ins.steps.iter().position(|s| f(&s.kind));
        ins.step = match step.as_str() {
            "gh" => find(&|k| {
                matches!(
                    k,
                    stages::StepKind::SetDifference {
                        phase: Some(stages::GhPhase::Traversal),
                        ..
                    }
                )
            })
            .or_else(|| find(&|k| matches!(k, stages::StepKind::SetDifference { .. }))),
            "labels" => find(&|k| {
                matches!(
                    k,
                    stages::StepKind::SetDifference {
                        phase: Some(stages::GhPhase::Labels),
                        ..
                    }
                )
            }),
            "visible" => find(&|k| *k == stages::StepKind::Visible),
            "ltc" => find(&|k| matches!(k, stages::StepKind::LtcClipped { .. })),
            n if n.starts_with("silhouette:") => {
                let name = &n["silhouette:".len()..];
                let light = ins.probe.lights.iter().find(|l| l.name == name);
                ins.steps.iter().position(|s| {
                    s.kind == stages::StepKind::LightSilhouette
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
        if (1..=5).contains(&self.state) {
            // The picked point adds to the structure view, and its views sit at the bottom of
            // the inspector: keep both in sight until the picture is taken (they settle over
            // a few frames).
            self.app.reveal_light = self.app.selected_light.is_some();
            self.app.reveal_views = self.pick.is_some();
        }
        match self.state {
            0 if self.app.render_finished() || t > self.after => {
                self.prepare();
                self.state = 1;
            }
            // A few frames for the panels to lay out what was picked, and the render of the
            // (possibly resized) viewport to finish again.
            1..=4 => self.state += 1,
            5 if !self.app.render_finished() && t < self.after + 60.0 => {}
            5 => {
                self.app.screenshot_to(self.path.clone(), None);
                self.state = 6;
            }
            6..=15 => self.state += 1,
            16 => ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close),
            _ => {}
        }
        ui.ctx().request_repaint();
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
                    r.method = self.app.state.method.name().into();
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
                    match serde_json::to_string_pretty(r) {
                        Ok(s) => {
                            if let Err(e) = std::fs::write(&self.path, s) {
                                eprintln!("{}: {e}", self.path.display());
                            }
                        }
                        Err(e) => eprintln!("{e}"),
                    }
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
