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
pub mod command;
pub mod environment_panel;
pub mod files;
pub mod gizmo;
pub mod inspector;
mod launch;
pub mod layout;
pub mod lesson;
pub mod lesson_export;
pub mod light_view;
pub mod orbit;
pub mod panes;
pub mod planar_view;
pub mod scene_edit;
pub mod sphere_view;
pub mod stages;
pub mod tonemap;
pub mod viewport;

use crate::bench::BenchReport;
use crate::inspect::{MonteCarloEstimate, monte_carlo, probe_corrected, probe_method};
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::scene_file;
use crate::shading::Method;
use command::Command;
use egui::{Color32, RichText, Sense, TextureHandle, TextureOptions, Ui};
use files::Opened;
use inspector::Inspector;
use layout::{Pane, Preset};
use orbit::OrbitCamera;
use sphere_view::SphereView;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use tonemap::{Aov, ToneMap};
use viewport::{RenderWorker, frame_image};

pub use launch::{DragMeasurement, Measurement, RunOptions, run};

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
    /// The arrangement of the tiles as the user left it (`None`: the preset's).
    #[serde(default)]
    pub layout: Option<egui_tiles::Tree<Pane>>,
    #[serde(default = "default_preset")]
    pub preset: Preset,
    /// Width / height of the rendered image; the viewport keeps it in any tile (0: fill the
    /// tile).
    #[serde(default = "default_aspect")]
    pub aspect: f32,
}

fn default_preset() -> Preset {
    Preset::Explore
}

fn default_aspect() -> f32 {
    4.0 / 3.0
}

/// The image aspects offered (width / height; 0 fills the tile).
pub const ASPECTS: [(f32, &str); 5] = [
    (4.0 / 3.0, "4:3"),
    (16.0 / 9.0, "16:9"),
    (3.0 / 2.0, "3:2"),
    (1.0, "1:1"),
    (0.0, "fill the tile"),
];

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
            layout: None,
            preset: Preset::Explore,
            aspect: default_aspect(),
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
    pub orbit: OrbitCamera,
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
    /// The tiles.
    pub tree: egui_tiles::Tree<Pane>,
    /// A pane shown alone over the whole window (its tab's "maximise"; Esc restores).
    pub maximised: Option<Pane>,
    /// The step shown in the last frame, to bring the planar view forward at a set difference.
    shown_step: Option<usize>,
    /// Pick a point chosen to be interesting once the first frame of a scene is shown.
    auto_pick: bool,
    last_frame: Instant,
    /// UI frame times (ms), for the status bar.
    frame_ms: f64,
    pending_screenshot: Option<(PathBuf, Option<egui::Rect>)>,
    sphere_rect: Option<egui::Rect>,
    /// The tile of the sphere, hemisphere or projected plane drawn last (what a lesson frame
    /// shows).
    subject_rect: Option<egui::Rect>,
    /// A lesson being exported, frame by frame.
    lesson_capture: Option<lesson_export::LessonCapture>,
    /// The selected object, its handles and the edit history.
    pub editor: scene_edit::SceneEditor,
    /// Where the viewport was drawn in the last frame (points).
    pub viewport_rect: Option<egui::Rect>,
    bench_job: Option<bench_job::BenchJob>,
    bench_size: (u32, u32),
    /// The light whose polyhedron the structure view shows (index into the prepared lights).
    selected_light: Option<usize>,
    pub light_view: light_view::LightView,
    /// Read silhouettes from the BSP trees (as the renderer does by default); off, every
    /// silhouette is computed at its point, and the recording then holds the contour pieces
    /// the exact silhouette's ray test rejected there.
    pub use_trees: bool,
    env_panel: environment_panel::EnvironmentPanel,
    env_maps: environment_panel::MapCache,
}

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
                aspect: None,
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
            tree: Preset::Explore.tree(),
            maximised: None,
            shown_step: None,
            auto_pick: true,
            last_frame: Instant::now(),
            frame_ms: 0.0,
            pending_screenshot: None,
            sphere_rect: None,
            subject_rect: None,
            lesson_capture: None,
            editor: Default::default(),
            viewport_rect: None,
            bench_job: None,
            bench_size: (160, 120),
            selected_light: None,
            light_view: light_view::LightView::default(),
            use_trees: true,
            env_panel: Default::default(),
            env_maps: Default::default(),
            state,
        };
        app.tree = match app.state.layout.take() {
            Some(mut t) => {
                layout::add_missing_panes(&mut t);
                t
            }
            None => app.state.preset.tree(),
        };
        let scene = app.state.scene.clone();
        let orbit = app.state.orbit;
        app.load_scene(&scene);
        if let Some(o) = orbit {
            app.orbit = o;
        }
        app
    }

    /// What is kept between runs: the settings, the camera and the tile layout.
    pub fn persisted(&self) -> Persisted {
        Persisted {
            orbit: Some(self.orbit),
            layout: Some(self.tree.clone()),
            ..self.state.clone()
        }
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
        self.editor.reset();
        self.inspector = None;
        self.monte_carlo = None;
        self.auto_pick = true;
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
            // The same stage stays shown where the new recording has it.
            let step = ins.step;
            self.pick(x, y);
            if let Some(ins) = &mut self.inspector {
                ins.step = step.filter(|&s| s < ins.steps.len());
            }
        }
    }

    /// A moved object's new context (from the scene editor): render it, and probe the picked
    /// pixel again.
    fn scene_moved(&mut self, ctx: Arc<RenderContext>) {
        let mut ctx = ctx;
        if !self.use_trees
            && let Some(c) = Arc::get_mut(&mut ctx)
        {
            c.prepared.drop_silhouette_trees();
        }
        self.ctx = Some(ctx);
        self.context_replaced();
    }

    /// Undoes the last move of an object.
    pub fn undo_edit(&mut self) {
        if let Some(ctx) = self.ctx.clone()
            && let Some(moved) = self.editor.undo(&ctx)
        {
            self.scene_moved(moved);
            self.status = "undone".into();
        }
    }

    /// Redoes the last undone move.
    pub fn redo_edit(&mut self) {
        if let Some(ctx) = self.ctx.clone()
            && let Some(moved) = self.editor.redo(&ctx)
        {
            self.scene_moved(moved);
            self.status = "redone".into();
        }
    }

    /// Moves `object` by `delta` as one edit (what a whole drag does).
    pub fn move_object(&mut self, object: usize, delta: crate::scene::edit::Rigid) -> bool {
        let Some(ctx) = self.ctx.clone() else {
            return false;
        };
        match self.editor.move_object(&ctx, object, delta) {
            Some(moved) => {
                self.scene_moved(moved);
                true
            }
            None => false,
        }
    }

    /// Selects the object `spec` names (a name or an index) for moving; the status says why not.
    pub fn select_object(&mut self, spec: &str) {
        let Some(ctx) = &self.ctx else {
            return;
        };
        match crate::scene::edit::resolve_object(&ctx.scene, spec) {
            Ok(i) => {
                self.editor.selected = Some(i);
                layout::reveal(&mut self.tree, Pane::Scene);
            }
            Err(e) => self.status = e.to_string(),
        }
    }

    /// One update of a drag driven by a program (`--measure-drag`): moves `object` to
    /// `delta` after where the drag began, renders and probes again. Returns the time
    /// `with_moved_object` took (ms).
    pub fn drag_step(&mut self, object: usize, delta: crate::scene::edit::Rigid) -> Option<f64> {
        let ctx = self.ctx.clone()?;
        let moved = self.editor.drag_to(&ctx, object, delta)?;
        self.scene_moved(moved);
        self.editor.last_timing.map(|t| t.prepare_ms)
    }

    /// The occluder subtracted first at the picked point (a scene object index).
    pub fn picked_occluder(&self) -> Option<usize> {
        let ins = self.inspector.as_ref()?;
        let ctx = self.ctx.as_ref()?;
        let sd = ins
            .probe
            .recording
            .lights
            .iter()
            .flat_map(|l| l.set_differences.iter())
            .next()?;
        Some(ctx.prepared.objects.get(sd.occluder)?.object as usize)
    }

    /// Asks for a file and saves the scene as it is now (moved objects included).
    fn save_scene_dialog(&mut self) {
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
        // What the pick records is the library's decision (`inspect::probe_method`), as for
        // `penumbra probe`; a stochastic method is said plainly, and its analytic stages shown.
        let s = self.settings();
        let (method, correction, note) =
            match probe_method(self.state.method, s.spp, s.seed, (x, y), self.render_size.0) {
                Ok((m, c)) => (m, c, None),
                Err(why) => (Method::Analytic, None, Some(why)),
            };
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
                if let Some(why) = note {
                    self.status = format!("{}; {why}: the analytic stages are shown", self.status);
                }
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
                layout::reveal(&mut self.tree, Pane::Plots);
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
                layout::reveal(&mut self.tree, Pane::Plots);
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
                layout::reveal(&mut self.tree, Pane::LightStructure);
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
        let (dropped, pressed) = ctx.input(|i| {
            (
                i.raw.dropped_files.clone(),
                Command::ALL.map(|c| c.pressed(i)),
            )
        });
        for f in dropped {
            let p = f.path().to_path_buf();
            if !p.as_os_str().is_empty() {
                self.open_path(&p);
            }
        }
        let typing = ctx.egui_wants_keyboard_input();
        for (c, pressed) in Command::ALL.into_iter().zip(pressed) {
            if pressed && (!typing || c.while_typing()) {
                self.run_command(c);
            }
        }
    }

    /// Carries out `command`, whether a key, a menu entry or a button issued it.
    pub fn run_command(&mut self, command: Command) {
        match command {
            Command::Undo => self.undo_edit(),
            Command::Redo => self.redo_edit(),
            Command::Restore => self.maximised = None,
            Command::NextStage => {
                if let Some(ins) = &mut self.inspector {
                    ins.next();
                }
            }
            Command::PreviousStage => {
                if let Some(ins) = &mut self.inspector {
                    ins.previous();
                }
            }
            Command::AllStages => {
                if let Some(ins) = &mut self.inspector {
                    ins.step = None;
                }
            }
            Command::PlayStages => {
                if let Some(ins) = &mut self.inspector {
                    ins.playing = !ins.playing;
                }
            }
            Command::ResetCamera => {
                if let Some(cam) = self.ctx.as_ref().and_then(|c| c.scene.camera) {
                    self.orbit = OrbitCamera::from_camera(&cam);
                }
            }
            Command::SaveImage => self.save_image_dialog(),
            Command::SaveDump => self.save_dump_dialog(),
            Command::Open => self.open_dialog(),
            Command::Screenshot => self.screenshot_dialog(None),
            Command::ToggleHelp => self.show_help = !self.show_help,
        }
    }

    fn open_dialog(&mut self) {
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
                if ui.button(Command::Open.menu_text("Open…")).clicked() {
                    self.run_command(Command::Open);
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
                if ui
                    .button(Command::SaveImage.menu_text("Save image…"))
                    .clicked()
                {
                    self.run_command(Command::SaveImage);
                }
                if ui
                    .button(Command::SaveDump.menu_text("Save debug dump…"))
                    .clicked()
                {
                    self.run_command(Command::SaveDump);
                }
                if ui
                    .button(Command::Screenshot.menu_text("Screenshot of the window…"))
                    .clicked()
                {
                    self.run_command(Command::Screenshot);
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
                ui.separator();
                ui.menu_button("Layout", |ui| {
                    for p in Preset::ALL {
                        if ui
                            .selectable_label(self.state.preset == p, p.name())
                            .clicked()
                        {
                            self.set_preset(p);
                        }
                    }
                });
                ui.menu_button("Panes", |ui| {
                    for p in Pane::ALL {
                        let mut shown = layout::find(&self.tree, p)
                            .is_some_and(|id| self.tree.tiles.is_visible(id));
                        if ui.checkbox(&mut shown, p.title()).changed() {
                            if shown {
                                layout::reveal(&mut self.tree, p);
                            } else if let Some(id) = layout::find(&self.tree, p) {
                                self.tree.tiles.set_visible(id, false);
                            }
                        }
                    }
                });
                ui.checkbox(&mut self.show_help, Command::ToggleHelp.menu_text("help"));
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
        let current = ASPECTS
            .iter()
            .find(|a| (a.0 - self.state.aspect).abs() < 1e-3)
            .map_or("custom", |a| a.1);
        egui::ComboBox::from_label("image aspect")
            .selected_text(current)
            .show_ui(ui, |ui| {
                for (a, name) in ASPECTS {
                    ui.selectable_value(&mut self.state.aspect, a, name);
                }
            });
    }

    fn environment_ui(&mut self, ui: &mut Ui) {
        let mut choice = self.state.environment.clone();
        if self.env_panel.ui(ui, &mut choice) {
            self.set_environment(choice);
        }
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
        let Some(ctx) = self.ctx.clone() else {
            return;
        };
        ui.horizontal(|ui| {
            if ui
                .add_enabled(self.editor.can_undo(), egui::Button::new("undo"))
                .on_hover_text(Command::Undo.shortcut_text())
                .clicked()
            {
                self.run_command(Command::Undo);
            }
            if ui
                .add_enabled(self.editor.can_redo(), egui::Button::new("redo"))
                .on_hover_text(Command::Redo.shortcut_text())
                .clicked()
            {
                self.run_command(Command::Redo);
            }
            if ui.button("Save scene…").clicked() {
                self.save_scene_dialog();
            }
        });
        ui.small(
            "Select an object (here, or double-click it in the viewport), then drag its arrows \
             to move it or its ring to turn it.",
        );
        egui::ScrollArea::vertical()
            .id_salt("objects")
            .max_height(260.0)
            .show(ui, |ui| self.editor.list_ui(ui, &ctx));
        for w in ctx.scene.warnings.iter().chain(&ctx.prepared.notes) {
            ui.small(w);
        }
    }

    fn light_structure_ui(&mut self, ui: &mut Ui) {
        let Some(ctx) = &self.ctx else {
            return;
        };
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
        }
    }

    fn viewport_ui(&mut self, ui: &mut Ui) {
        // The image keeps its aspect in any tile: the largest rectangle of that aspect,
        // centred, so that resizing a tile never stretches the camera.
        let full = ui.available_size();
        let aspect = self.state.aspect;
        let avail = if aspect > 0.0 {
            let w = full.x.min(full.y * aspect);
            egui::vec2(w, w / aspect)
        } else {
            full
        };
        let pad = (full - avail) * 0.5;
        ui.add_space(pad.y.max(0.0));
        ui.horizontal(|ui| {
            ui.add_space(pad.x.max(0.0));
            self.viewport_image_ui(ui, avail);
        });
    }

    fn viewport_image_ui(&mut self, ui: &mut Ui, avail: egui::Vec2) {
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
        // The selected object's handles take the pointer first.
        let mut on_gizmo = false;
        if let Some(ctx) = self.ctx.clone() {
            let edit = self
                .editor
                .viewport_input(ui, &resp, &painter, &ctx, &self.orbit.camera());
            on_gizmo = edit.consumed;
            if let Some(moved) = edit.moved {
                self.scene_moved(moved);
            }
            if resp.double_clicked()
                && let Some(pos) = resp.interact_pointer_pos()
            {
                let x = ((pos.x - rect.min.x) / rect.width() * size.0 as f32).floor() as f64;
                let y = ((pos.y - rect.min.y) / rect.height() * size.1 as f32).floor() as f64;
                let hit =
                    scene_edit::SceneEditor::object_at(&ctx, &self.orbit.camera(), size, x, y);
                self.editor.selected = hit;
                if let Some(i) = hit {
                    self.status = format!(
                        "selected {}: drag its arrows or ring to move it",
                        ctx.scene.objects[i].name
                    );
                }
            }
        }
        // Camera.
        if !on_gizmo && resp.dragged_by(egui::PointerButton::Primary) {
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
            && !on_gizmo
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

    /// The numbers of the picked point and the Monte Carlo check.
    fn numbers_ui(&mut self, ui: &mut Ui) {
        let Some(ins) = &mut self.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        ins.numbers_ui(ui, self.monte_carlo.as_ref());
        ins.environment_ui(ui);
        if ui.button("Monte Carlo check (65536 samples)").clicked() {
            self.run_monte_carlo(65536);
        }
    }

    /// The stepper through Alg. 1 with the lesson text of the current stage.
    fn stages_ui(&mut self, ui: &mut Ui) {
        let Some(ins) = &mut self.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        ins.stepper_ui(ui);
        ui.separator();
        ins.lesson_ui(ui);
        sphere_view::step_details_ui(ui, &ins.probe, ins.current());
        ui.separator();
        match &self.lesson_capture {
            Some(c) => {
                let (done, all) = c.progress();
                ui.label(format!("exporting the lesson: {done} of {all} frames…"));
            }
            None => {
                if ui
                    .button("Export lesson…")
                    .on_hover_text(
                        "Every stage of this point as numbered PNG frames, an animated GIF and \
                         the lesson text (lesson.md), for slides",
                    )
                    .clicked()
                    && let Some(dir) = rfd::FileDialog::new().pick_folder()
                {
                    self.export_lesson(dir);
                }
            }
        }
    }

    /// Starts exporting every stage of the picked point into `dir` (frames, GIF, text): the
    /// stepper walks the stages one frame after another and each is captured from the
    /// sphere's tile. `false` when nothing is picked.
    pub fn export_lesson(&mut self, dir: PathBuf) -> bool {
        let Some(ins) = &self.inspector else {
            self.status = "pick a point before exporting its lesson".into();
            return false;
        };
        let labels = ins
            .steps
            .iter()
            .map(|s| (s.label.clone(), lesson::lesson(&ins.probe, s)))
            .collect();
        self.maximised = None;
        if !layout::is_shown(&self.tree, Pane::Planar) {
            layout::reveal(&mut self.tree, Pane::Sphere);
        }
        self.lesson_capture = Some(lesson_export::LessonCapture::new(dir, 1.5, labels));
        true
    }

    /// Whether a lesson export is running.
    pub fn exporting_lesson(&self) -> bool {
        self.lesson_capture.is_some()
    }

    /// One frame of a lesson export (after the tiles are drawn).
    fn advance_lesson_capture(&mut self, ctx: &egui::Context) {
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

    /// Draws one pane of the tile tree.
    pub fn pane_ui(&mut self, ui: &mut Ui, pane: Pane) {
        let pick_first = "Click a pixel of the viewport to see its shading point here.";
        match pane {
            Pane::Viewport => self.viewport_ui(ui),
            Pane::Sphere => match &self.inspector {
                Some(ins) => {
                    self.subject_rect = Some(ui.max_rect());
                    ins.sphere_pane(ui, &mut self.state.sphere);
                    self.sphere_rect = Some(ui.min_rect());
                }
                None => {
                    ui.label(pick_first);
                }
            },
            Pane::Hemisphere => match &self.inspector {
                Some(ins) => {
                    self.subject_rect = Some(ui.max_rect());
                    ins.hemisphere_pane(ui, &mut self.state.sphere)
                }
                None => {
                    ui.label(pick_first);
                }
            },
            Pane::Planar => match &self.inspector {
                Some(ins) => {
                    self.subject_rect = Some(ui.max_rect());
                    ins.planar_pane(ui)
                }
                None => {
                    ui.label(pick_first);
                }
            },
            // Text that wraps to the tile: scrolled vertically only.
            Pane::Stages => {
                egui::ScrollArea::vertical()
                    .id_salt("stages_scroll")
                    .auto_shrink([false, false])
                    .show(ui, |ui| self.stages_ui(ui));
            }
            Pane::Numbers => scrolled(ui, "numbers_scroll", |ui| self.numbers_ui(ui)),
            Pane::Settings => scrolled(ui, "settings_scroll", |ui| self.settings_ui(ui)),
            Pane::Scene => scrolled(ui, "scene_scroll", |ui| self.scene_ui(ui)),
            Pane::LightStructure => scrolled(ui, "light_scroll", |ui| self.light_structure_ui(ui)),
            Pane::Plots => scrolled(ui, "plots_scroll", |ui| self.plots_ui(ui)),
            Pane::Environment => scrolled(ui, "env_scroll", |ui| self.environment_ui(ui)),
        }
    }

    /// Replaces the tiles by `preset`'s.
    pub fn set_preset(&mut self, preset: Preset) {
        self.state.preset = preset;
        self.tree = preset.tree();
        self.maximised = None;
    }

    fn plots_ui(&mut self, ui: &mut Ui) {
        use egui_plot::{Legend, Line, Plot, PlotPoints, Points};
        ui.horizontal(|ui| {
            if ui.button("Load bench JSON or reference PFM…").clicked() {
                self.run_command(Command::Open);
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
        self.follow_step();
        egui::CentralPanel::default().show(ui, |ui| match self.maximised {
            Some(pane) => {
                ui.horizontal(|ui| {
                    ui.strong(pane.title());
                    if ui.small_button("restore (Esc)").clicked() {
                        self.maximised = None;
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
        self.maybe_request();
        self.maybe_auto_pick();
        self.take_pending_screenshot(&ctx);
        self.advance_lesson_capture(&ctx);
        if self.worker.is_busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
        }
    }

    /// Before anything is picked, picks a penumbra pixel chosen by
    /// [`crate::inspect::interesting_pixel`], so that the sphere is never empty on first start.
    fn maybe_auto_pick(&mut self) {
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

    /// Brings the planar view forward when the stepper reaches a set difference, and the
    /// sphere back after it (only where they share a tab container: a layout the user made
    /// with both in sight is left alone).
    fn follow_step(&mut self) {
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

    /// The latest rendered frame, if any (for tests).
    pub fn latest_frame(&self) -> Option<Arc<viewport::ViewFrame>> {
        self.worker.latest()
    }

    /// Whether the render of the current view is complete.
    /// The prepared scene the viewport renders (`None` until a scene has loaded).
    pub fn render_context(&self) -> Option<Arc<RenderContext>> {
        self.ctx.clone()
    }

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
        eframe::set_value(storage, eframe::APP_KEY, &self.persisted());
    }
}

/// A pane's content in a vertical scroll area (panes are as tall as their tile).
fn scrolled(ui: &mut Ui, id: &str, add: impl FnOnce(&mut Ui)) {
    egui::ScrollArea::both()
        .id_salt(id)
        .auto_shrink([false, false])
        .show(ui, add);
}
