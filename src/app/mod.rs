//! The egui workbench: a progressive viewport, the picked point's stages on the unit sphere,
//! plots and exports. It draws what the library computed (the renderer's frames, the
//! recording of `shade` at the picked point); it computes no geometry of its own.
//!
//! * [`viewport`]: the render thread (progressive, cancelled on every change).
//! * [`tonemap`]: AOVs and display colours.
//! * [`orbit`]: the orbit camera.
//! * [`inspector`]: the picked point and where the stepper stands.
//! * [`ui`]: the panes, each drawing itself (the sphere's in `ui/sphere/`), and the bars.
//! * [`command`]: every action a key, a menu entry or a button starts.
//! * [`files`]: scenes, dumps, bench reports, images, the CLI command.

pub mod bench_job;
pub mod command;
pub mod environment_panel;
pub mod figure_export;
pub mod figure_painter;
pub mod files;
pub mod gizmo;
pub mod inspector;
#[cfg(not(target_arch = "wasm32"))]
mod launch;
pub mod layout;
pub mod lesson;
pub mod lesson_export;
pub mod light_view;
pub mod orbit;
pub mod panes;
pub mod platform;
pub mod scene_edit;
pub mod tonemap;
pub mod ui;
pub mod viewport;
#[cfg(target_arch = "wasm32")]
pub mod viewport_web;

use crate::bench::table::BenchReport;
use crate::inspect::{MonteCarloEstimate, monte_carlo, probe_full, probe_method};
use crate::render::request::RenderRequest;
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::scene_file;
use crate::shading::Method;
use command::Command;
use egui::{Color32, RichText, Sense, TextureHandle, TextureOptions, Ui};
use files::Opened;
use inspector::Inspector;
use layout::{Pane, Preset};
use orbit::OrbitCamera;
use std::path::PathBuf;
use std::sync::Arc;
use tonemap::{Aov, ToneMap};
use ui::SphereView;
#[cfg(not(target_arch = "wasm32"))]
use viewport::RenderWorker;
use viewport::frame_image;
#[cfg(target_arch = "wasm32")]
use viewport_web::RenderWorker;
use web_time::Instant;

#[cfg(not(target_arch = "wasm32"))]
pub use launch::{DEFAULT_SCREENSHOT_WAIT, DragMeasurement, Measurement, RunOptions, run};
#[cfg(target_arch = "wasm32")]
pub mod web;

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

/// Samples per pixel in one pass of a stochastic method, as the workbench starts. The viewport
/// renders pass after pass and averages them (`settings.passes`), so a pass is kept short: the
/// first image comes soon and a camera move restarts quickly. A one-shot render (the command
/// line's, [`RenderRequest::default`]) takes all its samples in one pass and defaults higher.
pub(crate) const INTERACTIVE_SPP: u32 = 4;

/// The image aspects offered (width / height; 0 fills the tile).
pub(crate) const ASPECTS: [(f32, &str); 5] = [
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
            spp: INTERACTIVE_SPP,
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

/// The workbench's state: the scene and its prepared context, the render, the picked point
/// and its recording, the selection and edits, and the user's settings. The panes draw from
/// it ([`ui::Panes`]); commands change it ([`AppState::run_command`]).
pub struct AppState {
    /// What the user set, kept between sessions.
    pub settings: Persisted,
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
    /// The command palette, while it is open.
    palette: Option<ui::CommandPalette>,
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
    pending_screenshot: Option<(platform::SaveTarget, Option<egui::Rect>)>,
    /// Files the browser's picker answered with (empty on the desktop, whose dialogs block).
    inbox: platform::FileInbox,
    /// When the workbench started (the browser's log times its first image from it).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    started: Instant,
    /// What the browser's console has been told (`log_milestones`).
    #[cfg(target_arch = "wasm32")]
    web_log: WebLog,
    /// Wakes the UI (a frame is ready, a picked file arrived).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    wake: Arc<dyn Fn() + Send + Sync>,
    sphere_rect: Option<egui::Rect>,
    /// The tile of the sphere, hemisphere or projected plane drawn last (what a lesson frame
    /// shows).
    subject_rect: Option<egui::Rect>,
    /// A lesson being exported, frame by frame.
    lesson_capture: Option<lesson_export::LessonCapture>,
    /// Figures are exported in the print style (else as on screen).
    pub figure_print: bool,
    /// Export ▸ Figure chosen this frame: its dialog opens once the menu has closed.
    pending_figure: Option<figure_export::FigureView>,
    /// Text a command put on the clipboard this frame (handed to egui at the frame's end).
    clipboard: Option<String>,
    /// The selected object, its handles and the edit history.
    pub editor: scene_edit::SceneEditor,
    /// Where the viewport was drawn in the last frame (points).
    pub viewport_rect: Option<egui::Rect>,
    /// Read silhouettes from the BSP trees (as the renderer does by default); off, every
    /// silhouette is computed at its point, and the recording then holds the contour pieces
    /// the exact silhouette's ray test rejected there.
    pub use_trees: bool,
    /// How scenes are prepared (the tree cache): the launch's choice.
    prepare: crate::shading::PrepareConfig,
    /// The derivative the picked point was probed with (`Some(None)`: none), to probe it again
    /// when the derivative AOV's motion changes; `None` when the point was not picked here
    /// (a debug dump replayed).
    picked_motion: Option<Option<crate::shading::derivative::Motion>>,
    /// An error from the last load of the environment's map (the environment pane shows it).
    env_error: Option<String>,
    env_maps: environment_panel::MapCache,
}

/// What the browser's console has been told.
#[cfg(target_arch = "wasm32")]
#[derive(Default)]
struct WebLog {
    status: String,
    first_image: bool,
    recording: Option<((f64, f64), usize)>,
    selected: Option<usize>,
}

impl AppState {
    /// A workbench on `state.scene`, its scenes prepared as `prepare` says; `repaint` wakes
    /// the UI when a frame is ready.
    pub(crate) fn new(
        state: Persisted,
        prepare: crate::shading::PrepareConfig,
        repaint: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        let wake: Arc<dyn Fn() + Send + Sync> = Arc::new(repaint);
        let mut app = AppState {
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
            worker: RenderWorker::start({
                let wake = wake.clone();
                move || wake()
            }),
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
            palette: None,
            tree: Preset::Explore.tree(),
            maximised: None,
            shown_step: None,
            auto_pick: true,
            last_frame: Instant::now(),
            frame_ms: 0.0,
            pending_screenshot: None,
            inbox: Default::default(),
            started: Instant::now(),
            #[cfg(target_arch = "wasm32")]
            web_log: WebLog::default(),
            wake,
            sphere_rect: None,
            subject_rect: None,
            lesson_capture: None,
            figure_print: true,
            pending_figure: None,
            clipboard: None,
            editor: Default::default(),
            viewport_rect: None,
            use_trees: true,
            prepare,
            picked_motion: None,
            env_error: None,
            env_maps: Default::default(),
            settings: state,
        };
        app.tree = match app.settings.layout.take() {
            Some(mut t) => {
                layout::add_missing_panes(&mut t);
                t
            }
            None => app.settings.preset.tree(),
        };
        let scene = app.settings.scene.clone();
        let orbit = app.settings.orbit;
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
            ..self.settings.clone()
        }
    }

    fn apply_theme(&self, ctx: &egui::Context) {
        ctx.set_visuals(if self.settings.dark {
            egui::Visuals::dark()
        } else {
            egui::Visuals::light()
        });
    }

    /// Loads a scene (embedded name or path) and resets the camera to the scene's.
    pub(crate) fn load_scene(&mut self, name: &str) {
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
        self.settings.environment = self
            .settings
            .environment
            .from_spec(scene.environment.as_ref());
        self.ctx = Some(self.context(Arc::new(scene)));
        self.scene_error = None;
        self.scene_generation += 1;
        self.editor.reset();
        self.inspector = None;
        self.monte_carlo = None;
        self.auto_pick = true;
        self.settings.recent.retain(|r| *r != name);
        self.settings.recent.insert(0, name.clone());
        self.settings.recent.truncate(8);
        self.settings.scene = name;
    }

    /// The render context of `scene`, with or without its silhouette trees, lit by the
    /// environment panel's choice. The scene is prepared once for every size the viewport
    /// will render it at (a tile resizes), so its trees keep the default budget rather than
    /// one sized for the current image ([`RenderRequest::prepare_options`]); the rest is the
    /// request's (the LTC table, the launch's preparation choices).
    fn context(&mut self, scene: Arc<crate::scene::Scene>) -> Arc<RenderContext> {
        let request = self.request();
        let options = crate::shading::PrepareOptions {
            environment: scene.environment.is_some(),
            ltc: request.ltc,
            ..request.prepare.options()
        };
        let mut ctx = RenderContext::with_options(scene, options);
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
        crate::render::environment_passes::EnvironmentSettings,
    )> {
        match self.env_maps.light(&self.settings.environment) {
            Ok(light) => {
                self.env_error = None;
                light.map(|l| (l, self.settings.environment.settings()))
            }
            Err(e) => {
                let msg = format!("environment: {e:#}");
                self.status = msg.clone();
                self.env_error = Some(msg);
                None
            }
        }
    }

    /// Lights the scene with `choice` (the environment panel, a dropped map): the prepared
    /// scene is copied with the new light, the progressive render restarts, and the picked
    /// pixel (if any) is picked again.
    pub fn set_environment(&mut self, choice: environment_panel::EnvironmentChoice) {
        self.settings.environment = choice;
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
            && ins.probe.scene == self.settings.scene
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
    pub(crate) fn undo_edit(&mut self) {
        if let Some(ctx) = self.ctx.clone()
            && let Some(moved) = self.editor.undo(&ctx)
        {
            self.scene_moved(moved);
            self.status = "undone".into();
        }
    }

    /// Redoes the last undone move.
    pub(crate) fn redo_edit(&mut self) {
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

    /// Switches the silhouette trees on or off: the scene is prepared again, rendered again,
    /// and the picked pixel (if any) picked again.
    pub(crate) fn set_use_trees(&mut self, on: bool) {
        self.use_trees = on;
        let Some(scene) = self.ctx.as_ref().map(|c| c.scene.clone()) else {
            return;
        };
        self.ctx = Some(self.context(scene));
        self.context_replaced();
    }

    /// The render the viewport asks for: [`RenderRequest::default`] with what the user set
    /// (the image's size, the method, its samples and sub-pixel positions, the statistics
    /// the AOV shows) and the launch's preparation choices.
    pub(crate) fn request(&self) -> RenderRequest {
        let defaults = RenderRequest::default();
        RenderRequest {
            settings: RenderSettings {
                width: self.render_size.0.max(1),
                height: self.render_size.1.max(1),
                aa: self.settings.aa.max(1),
                method: self.settings.method,
                spp: self.settings.spp.max(1),
                collect_stats: matches!(
                    self.settings.aov,
                    Aov::OccludersKept | Aov::SilhouetteEdges | Aov::Cost
                ),
                ..defaults.settings
            },
            prepare: self.prepare.clone(),
            ..defaults
        }
    }

    /// The settings of the full-resolution render (the request's).
    pub(crate) fn settings(&self) -> RenderSettings {
        self.request().settings
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
        // The derivative AOV renders the derivative (only then: the plain image's levels are
        // the same as without it); what keeps it from being computed, the viewport says.
        let derivative = self.derivative_motion().ok().flatten();
        let key = format!(
            "{}|{:?}|{:?}|{}|{:?}",
            self.scene_generation, camera, settings, self.settings.passes, derivative
        );
        if self.requested.as_ref().is_some_and(|(_, k)| *k == key) {
            return;
        }
        let generation = self.worker.request(
            ctx,
            camera,
            settings,
            self.settings.passes.max(1),
            derivative,
        );
        self.requested = Some((generation, key));
        self.trace.points.clear();
        self.trace.generation = generation;
    }

    /// The motion the derivative AOV differentiates along: the selected object along the
    /// gizmo's active axis. `Ok(None)` when the AOV is another; `Err` says, for the viewport,
    /// why there is no derivative to show (no object selected, or what
    /// `RenderContext::derivative_refusal` refuses).
    pub fn derivative_motion(&self) -> Result<Option<crate::shading::derivative::Motion>, String> {
        if self.settings.aov != Aov::Derivative {
            return Ok(None);
        }
        let Some(ctx) = &self.ctx else {
            return Err("no scene".into());
        };
        let Some(object) = self.editor.selected else {
            return Err(
                "derivative: select an object (in the Scene pane, or double-click it here) to \
                 see the image's derivative along its active axis"
                    .into(),
            );
        };
        ctx.derivative_refusal(self.settings.method)
            .map_err(|e| format!("derivative: {e}"))?;
        ctx.motion(object, self.editor.axis())
            .map(Some)
            .map_err(|e| format!("derivative: {e}"))
    }

    /// "d/dtx of NAME" for the derivative AOV's motion.
    pub fn derivative_label(&self, motion: &crate::shading::derivative::Motion) -> String {
        let name = self
            .ctx
            .as_ref()
            .and_then(|c| c.scene.objects.get(motion.object as usize))
            .map_or_else(|| format!("#{}", motion.object), |o| o.name.clone());
        format!("d/d{} of {name}", motion.axis.name())
    }

    /// Opens a file of any kind the workbench knows.
    pub fn open_path(&mut self, path: &std::path::Path) {
        self.take_opened(&path.display().to_string(), files::open(path));
    }

    /// Shows what was opened from the file `file`.
    fn take_opened(&mut self, file: &str, opened: crate::Result<Opened>) {
        match opened {
            Ok(Opened::Scene(name, scene)) => self.set_scene(name, scene),
            Ok(Opened::Dump(p)) => {
                self.status = format!("replaying the dump {file}");
                self.inspector = Some(Inspector::new(*p));
                self.picked_motion = None;
                self.monte_carlo = None;
            }
            Ok(Opened::Bench(r)) => {
                self.status = format!("bench report of {}", r.scene);
                self.bench = Some(*r);
                layout::reveal(&mut self.tree, Pane::Plots);
            }
            Ok(Opened::Environment(map)) => {
                let mut choice = self.settings.environment.clone();
                choice.map = map;
                self.set_environment(choice);
                self.status = match &self.env_error {
                    Some(e) => e.clone(),
                    None => format!("environment map {file}"),
                };
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

    /// Opens files handed over by content (the browser): a scene with the files it refers to
    /// among them (an OBJ's MTL, a TOML's OBJs), a dump, a bench report.
    pub(crate) fn open_contents(&mut self, contents: &[platform::FileContent]) {
        for (file, opened) in files::open_contents(contents) {
            self.take_opened(&file, opened);
        }
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        let (dropped, pressed) = ctx.input(|i| {
            (
                i.raw.dropped_files.clone(),
                Command::ALL.map(|c| c.pressed(i)),
            )
        });
        // The desktop drops paths; the browser's files are read by content and arrive in the
        // inbox, with the picker's answers, a frame or more later.
        #[cfg(not(target_arch = "wasm32"))]
        for f in dropped {
            let p = f.path().to_path_buf();
            if !p.as_os_str().is_empty() {
                self.open_path(&p);
            }
        }
        #[cfg(target_arch = "wasm32")]
        if !dropped.is_empty() {
            self.inbox.read_dropped(dropped, self.wake.clone());
        }
        let contents = self.inbox.take();
        if !contents.is_empty() {
            self.open_contents(&contents);
        }
        let typing = ctx.egui_wants_keyboard_input();
        for (c, pressed) in Command::ALL.into_iter().zip(pressed) {
            // The open palette has the keyboard: only its own shortcut closes it.
            let palette = self.palette.is_some() && c != Command::CommandPalette;
            if pressed && !palette && (!typing || c.while_typing()) {
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
                    ins.playing = false;
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
            Command::CommandPalette => {
                self.palette = match self.palette {
                    Some(_) => None,
                    None => Some(ui::CommandPalette::default()),
                }
            }
            Command::MonteCarloCheck => self.run_monte_carlo(65536),
            Command::ScreenshotSphere => self.screenshot_dialog(self.sphere_rect),
            Command::SaveScene => self.save_scene_dialog(),
            Command::ExportLesson => self.export_lesson_dialog(),
            Command::CopyCliCommand => self.copy_cli_command(),
            Command::OpenEmbedded(name) => self.load_scene(name),
            Command::OpenRecent(name) => self.load_scene(&name),
            // The dialog opens once the menu that chose the figure has closed.
            Command::ExportFigure(view) => self.pending_figure = Some(view),
            Command::Layout(preset) => self.set_preset(preset),
        }
    }

    /// Puts the command line that renders the view as it is now (the samples of every pass
    /// so far) on the clipboard, and says it in the status bar.
    fn copy_cli_command(&mut self) {
        let passes = self.worker.latest().map_or(1, |f| f.frame.passes);
        let mut s = self.settings();
        s.spp *= passes;
        let cmd = files::cli_command(
            &self.settings.scene,
            &self.orbit.camera(),
            &s,
            self.settings.exposure,
        );
        self.status = format!("copied: {cmd}");
        self.clipboard = Some(cmd);
    }

    /// Requests a screenshot to `path` (of `crop` in points, or the whole window).
    pub fn screenshot_to(&mut self, path: PathBuf, crop: Option<egui::Rect>) {
        self.pending_screenshot = Some((platform::SaveTarget::Path(path), crop));
    }

    /// Whether the help window is shown.
    pub fn help_shown(&self) -> bool {
        self.show_help
    }

    /// Whether the command palette is open.
    pub fn palette_open(&self) -> bool {
        self.palette.is_some()
    }

    /// Whether a lesson export is running.
    pub fn exporting_lesson(&self) -> bool {
        self.lesson_capture.is_some()
    }

    /// Replaces the tiles by `preset`'s.
    pub(crate) fn set_preset(&mut self, preset: Preset) {
        self.settings.preset = preset;
        self.tree = preset.tree();
        self.maximised = None;
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

/// The workbench: its state and its panes. The panes draw from the state (and the picked
/// point's recording in it) and change it through its methods and commands; each keeps only
/// its own view state (the egui demo's panels, rerun's split of data and views).
pub struct WorkbenchApp {
    pub app: AppState,
    pub panes: ui::Panes,
}

impl std::ops::Deref for WorkbenchApp {
    type Target = AppState;
    fn deref(&self) -> &AppState {
        &self.app
    }
}

impl std::ops::DerefMut for WorkbenchApp {
    fn deref_mut(&mut self) -> &mut AppState {
        &mut self.app
    }
}

impl WorkbenchApp {
    /// A workbench on `state.scene`, its scenes prepared as `prepare` says; `repaint` wakes
    /// the UI when a frame is ready.
    pub fn new(
        state: Persisted,
        prepare: crate::shading::PrepareConfig,
        repaint: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        WorkbenchApp {
            app: AppState::new(state, prepare, repaint),
            panes: ui::Panes::default(),
        }
    }

    /// Creates the app inside eframe (restoring the persisted state).
    pub(crate) fn from_creation_context(
        cc: &eframe::CreationContext<'_>,
        prepare: crate::shading::PrepareConfig,
    ) -> Self {
        let state: Persisted = cc
            .storage
            .and_then(|s| eframe::get_value(s, eframe::APP_KEY))
            .unwrap_or_default();
        let ctx = cc.egui_ctx.clone();
        let app = WorkbenchApp::new(state, prepare, move || ctx.request_repaint());
        app.apply_theme(&cc.egui_ctx);
        app
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
pub(crate) fn scrolled(ui: &mut Ui, id: &str, add: impl FnOnce(&mut Ui)) {
    egui::ScrollArea::both()
        .id_salt(id)
        .auto_shrink([false, false])
        .show(ui, add);
}
