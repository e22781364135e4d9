//! penumbra from Python: the library without its window (default features off), behind a
//! small PyO3 module. Each function prepares and renders through the same library calls as
//! the command line (`render::request`), so that equal settings give equal images bit for bit.
//! Errors are Python exceptions carrying the library's message (file and line where it has
//! them); long renders release the interpreter.

use numpy::{IntoPyArray, PyReadonlyArray3};
use penumbra::render::request::{self, EnvironmentOptions, RenderRequest};
use std::sync::Arc;
use penumbra::shading::PrepareConfig;
use penumbra::shading::tree_cache::CacheVars;
use penumbra::render::{RenderMethod, RenderSettings};
use penumbra::scene::environment_spec::EnvironmentOverrides;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A method by the name `penumbra render --method` takes.
fn method_by_name(name: &str) -> PyResult<RenderMethod> {
    use penumbra::Choice;
    RenderMethod::named(name).ok_or_else(|| {
        let names: Vec<&str> = RenderMethod::names().collect();
        value_error(format!(
            "method {name:?}: expected one of {}",
            names.join(", ")
        ))
    })
}

/// A camera: eye, target, up (world units) and the vertical field of view (degrees).
#[pyclass(module = "penumbra", get_all, set_all)]
#[derive(Clone)]
struct Camera {
    eye: (f64, f64, f64),
    target: (f64, f64, f64),
    up: (f64, f64, f64),
    fov_deg: f64,
}

#[pymethods]
impl Camera {
    #[new]
    #[pyo3(signature = (eye, target, up=(0.0, 1.0, 0.0), fov_deg=45.0))]
    fn new(
        eye: (f64, f64, f64),
        target: (f64, f64, f64),
        up: (f64, f64, f64),
        fov_deg: f64,
    ) -> Self {
        Camera {
            eye,
            target,
            up,
            fov_deg,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Camera(eye={:?}, target={:?}, up={:?}, fov_deg={})",
            self.eye, self.target, self.up, self.fov_deg
        )
    }
}

fn to_dvec3(v: (f64, f64, f64)) -> glam::DVec3 {
    glam::DVec3::new(v.0, v.1, v.2)
}

fn from_dvec3(v: glam::DVec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

/// What `Scene::render` computed: an image (float32, as the PFM), or an image, its derivative
/// and its mask (float64).
enum Rendered {
    Image(Vec<f32>),
    Derivative(Vec<f64>, Vec<f64>, Vec<f64>),
}

/// A scene: its objects, its camera and its environment, loaded once; renders leave it as
/// it is, so two scenes (or two renders of one) live side by side.
#[pyclass(module = "penumbra")]
struct Scene {
    name: String,
    scene: penumbra::scene::Scene,
    /// The camera renders use: the scene's own until set (`aspect` follows the scene's).
    camera: Option<penumbra::scene::Camera>,
    /// The scene prepared for the last request, kept for the next render or probe whose
    /// preparation would be the same (same image size, sub-pixel positions, seed and
    /// environment; a move forgets it): the trees are built once, not per call.
    prepared: std::sync::Mutex<Option<(PrepareKey, Arc<request::PreparedRender>)>>,
    /// How many times the scene was prepared (`preparations`).
    preparations: Arc<std::sync::atomic::AtomicU32>,
}

/// What a preparation depends on besides the scene: the cost model's camera rays (size and
/// sub-pixel positions), and the environment's seed and options.
#[derive(Clone, PartialEq)]
struct PrepareKey {
    size: (u32, u32),
    aa: u32,
    seed: u64,
    env: Option<String>,
    spp: Option<u32>,
}

#[pymethods]
impl Scene {
    /// How many times the scene was prepared for a render or probe: a call whose preparation
    /// would be the one kept from the last call (same size, sub-pixel positions, seed and
    /// environment, no move since) reuses it.
    #[getter]
    fn preparations(&self) -> u32 {
        self.preparations.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The names of the scene's objects, in file order.
    #[getter]
    fn objects(&self) -> Vec<String> {
        self.scene.objects.iter().map(|o| o.name.clone()).collect()
    }

    /// The camera renders use (None if the scene has none and none was set).
    #[getter]
    fn get_camera(&self) -> Option<Camera> {
        self.camera.map(|c| Camera {
            eye: from_dvec3(c.eye),
            target: from_dvec3(c.target),
            up: from_dvec3(c.up),
            fov_deg: c.fov_deg,
        })
    }

    #[setter]
    fn set_camera(&mut self, cam: Camera) -> PyResult<()> {
        let c = penumbra::scene::Camera {
            eye: to_dvec3(cam.eye),
            target: to_dvec3(cam.target),
            up: to_dvec3(cam.up),
            fov_deg: cam.fov_deg,
            // A field of view given by hand is vertical, as `--fov` is.
            aspect: None,
        };
        c.basis().map_err(value_error)?;
        self.camera = Some(c);
        Ok(())
    }

    /// Moves one object rigidly, as `penumbra edit` does: rotated by `rotate_y` degrees about
    /// +y through `pivot` (the object's own pivot by default), then translated. `name` is an
    /// object's name or index.
    #[pyo3(signature = (name, translate=(0.0, 0.0, 0.0), rotate_y=0.0, pivot=None))]
    fn r#move(
        &mut self,
        name: &str,
        translate: (f64, f64, f64),
        rotate_y: f64,
        pivot: Option<(f64, f64, f64)>,
    ) -> PyResult<()> {
        *self.prepared.lock().unwrap_or_else(|e| e.into_inner()) = None;
        penumbra::scene::edit::move_object(
            &mut self.scene,
            name,
            to_dvec3(translate),
            rotate_y,
            pivot.map(to_dvec3),
        )
        .map_err(value_error)?;
        Ok(())
    }

    /// Renders the scene: a float32 array of shape (h, w, 3), linear radiance, equal bit for
    /// bit to the PFM `penumbra render` writes with the same settings.
    ///
    /// With `derivative=(object, axis)` (an object's name or index; `axis` one of tx, ty, tz,
    /// ry, as `penumbra render --derivative` takes), returns `(image, derivative)` instead:
    /// float64 arrays of shape (h, w, 3), the image and its exact derivative along the motion
    /// (per scene unit, or per radian for ry; docs/derivatives.md), with `method="analytic"`
    /// only. `mask=True` adds a third array, float64 (h, w), 1 where a pixel is masked.
    #[pyo3(signature = (method="analytic", size=(320, 240), aa=1, spp=None, seed=1, env=None, derivative=None, mask=false))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        method: &str,
        size: (u32, u32),
        aa: u32,
        spp: Option<u32>,
        seed: u64,
        env: Option<String>,
        derivative: Option<(String, String)>,
        mask: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let key = PrepareKey {
            size,
            aa,
            seed,
            env: env.clone(),
            spp,
        };
        let request = request_of(method, size, aa, spp, seed, env)?;
        let camera = self.camera_or_error()?;
        let kept = self.kept(&key);
        let count = self.preparations.clone();
        let mut scene = self.scene.clone();
        let (w, h) = (size.0 as usize, size.1 as usize);
        // The long part without the interpreter (other Python threads run meanwhile), and
        // stopped by Ctrl-C.
        let done = interruptible(py, move |cancel| -> penumbra::Result<_> {
            let prepared = match kept {
                Some(p) => p,
                None => {
                    count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    Arc::new(request.prepare(&mut scene)?)
                }
            };
            let images = match &derivative {
                None => {
                    let out = prepared
                        .ctx
                        .render_full(&camera, &request.settings, Some(cancel))?;
                    Rendered::Image(out.image.to_rgb32().into_iter().flatten().collect())
                }
                Some((object, axis)) => {
                    let ctx = &prepared.ctx;
                    let motion = penumbra::render::derivative::parse_motion(
                        ctx,
                        &format!("{object}:{axis}"),
                    )?;
                    let out =
                        ctx.render_derivative(&camera, &request.settings, &motion, Some(cancel))?;
                    let flat = |i: &penumbra::raster::Image| -> Vec<f64> {
                        i.pixels.iter().flat_map(|p| p.to_array()).collect()
                    };
                    Rendered::Derivative(
                        flat(&out.image),
                        flat(&out.derivative),
                        out.mask.pixels.iter().map(|p| p.x).collect(),
                    )
                }
            };
            Ok((images, prepared))
        })?;
        let (images, prepared) = done.map_err(value_error)?;
        self.keep(key, prepared);
        use numpy::ndarray::{Array2, Array3};
        match images {
            Rendered::Image(rgb) => {
                let array = Array3::from_shape_vec((h, w, 3), rgb).map_err(value_error)?;
                Ok(array.into_pyarray(py).into_any())
            }
            Rendered::Derivative(image, rate, masked) => {
                let image = Array3::from_shape_vec((h, w, 3), image).map_err(value_error)?;
                let rate = Array3::from_shape_vec((h, w, 3), rate).map_err(value_error)?;
                let (image, rate) = (image.into_pyarray(py), rate.into_pyarray(py));
                if mask {
                    let m = Array2::from_shape_vec((h, w), masked).map_err(value_error)?;
                    Ok((image, rate, m.into_pyarray(py))
                        .into_pyobject(py)?
                        .into_any())
                } else {
                    Ok((image, rate).into_pyobject(py)?.into_any())
                }
            }
        }
    }

    /// The recording of the shading point at pixel (x, y) of an image of `size`, as
    /// `penumbra probe --gh-steps` writes it (equal to its JSON dump): every stage of the
    /// analytic pipeline there, with a Monte Carlo check.
    #[pyo3(signature = (x, y, method="analytic", size=(320, 240), spp=None, seed=1, env=None))]
    #[allow(clippy::too_many_arguments)]
    fn probe(
        &self,
        py: Python<'_>,
        x: f64,
        y: f64,
        method: &str,
        size: (u32, u32),
        spp: Option<u32>,
        seed: u64,
        env: Option<String>,
    ) -> PyResult<Recording> {
        let key = PrepareKey {
            size,
            aa: 1,
            seed,
            env: env.clone(),
            spp,
        };
        let request = request_of(method, size, 1, spp, seed, env)?;
        let camera = self.camera_or_error()?;
        let kept = self.kept(&key);
        let count = self.preparations.clone();
        let mut scene = self.scene.clone();
        let name = self.name.clone();
        let recorded = py.detach(move || -> penumbra::Result<_> {
            let prepared = match kept {
                Some(p) => p,
                None => {
                    count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    Arc::new(request.prepare(&mut scene)?)
                }
            };
            let probe = penumbra::inspect::debug_dump(
                &prepared.ctx,
                &name,
                &camera,
                &request.settings,
                (x, y),
                true,
            )?;
            Ok((probe, prepared))
        });
        let (probe, prepared) = recorded.map_err(value_error)?;
        self.keep(key, prepared.clone());
        Ok(Recording {
            probe,
            prepared,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}, {} objects)",
            self.name,
            self.scene.objects.len()
        )
    }
}

impl Scene {
    /// The preparation kept for `key`, if the last one was for the same.
    fn kept(&self, key: &PrepareKey) -> Option<Arc<request::PreparedRender>> {
        let kept = self.prepared.lock().unwrap_or_else(|e| e.into_inner());
        kept.as_ref()
            .filter(|(k, _)| k == key)
            .map(|(_, p)| p.clone())
    }

    /// Keeps `prepared` for the next call with the same `key`.
    fn keep(&self, key: PrepareKey, prepared: Arc<request::PreparedRender>) {
        *self.prepared.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, prepared));
    }

    fn camera_or_error(&self) -> PyResult<penumbra::scene::Camera> {
        self.camera.ok_or_else(|| {
            value_error(format!(
                "{}: the scene has no camera: set scene.camera",
                self.name
            ))
        })
    }
}

/// Runs `work` on a thread of its own while this one waits without the interpreter, looking
/// for Ctrl-C every 50 ms: on an interrupt, `work`'s cancel flag is raised and the
/// KeyboardInterrupt returned once it has stopped (renders check the flag tile by tile).
fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let cancel = AtomicBool::new(false);
    std::thread::scope(|s| {
        let handle = s.spawn(|| work(&cancel));
        loop {
            let finished = py.detach(|| {
                let start = Instant::now();
                while !handle.is_finished() && start.elapsed() < Duration::from_millis(50) {
                    std::thread::sleep(Duration::from_millis(2));
                }
                handle.is_finished()
            });
            if finished {
                return handle
                    .join()
                    .map_err(|_| PyRuntimeError::new_err("penumbra panicked: please report it"));
            }
            if let Err(interrupt) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                let _ = handle.join();
                return Err(interrupt);
            }
        }
    })
}

/// How the process's environment asks scenes to be prepared (the tree cache, the measuring
/// switches), read here since the library reads no environment; as the command line reads it.
fn prepare_config() -> PrepareConfig {
    use std::env::var_os;
    let cache = CacheVars {
        cache_dir: var_os("PENUMBRA_CACHE_DIR"),
        cache_max: std::env::var("PENUMBRA_CACHE_MAX").ok(),
        xdg_cache_home: var_os("XDG_CACHE_HOME"),
        home: var_os("HOME"),
    };
    let (config, warning) = PrepareConfig::from_vars(
        &cache,
        var_os("PENUMBRA_HOISTED_TREES").as_deref(),
        var_os("PENUMBRA_QI").as_deref(),
    );
    if let Some(w) = warning {
        eprintln!("penumbra: {w}");
    }
    config
}

/// The request of a render or probe, checked: the library's defaults (the command line's)
/// with what was given.
fn request_of(
    method: &str,
    size: (u32, u32),
    aa: u32,
    spp: Option<u32>,
    seed: u64,
    env: Option<String>,
) -> PyResult<RenderRequest> {
    let method = method_by_name(method)?;
    if size.0 == 0 || size.1 == 0 || aa == 0 {
        return Err(value_error(format!(
            "size {size:?} and aa {aa} must be positive"
        )));
    }
    let defaults = RenderRequest::default();
    let settings = RenderSettings {
        width: size.0,
        height: size.1,
        aa,
        method,
        spp: spp.unwrap_or(defaults.settings.spp),
        seed,
        light_sampling: Default::default(),
        collect_stats: false,
        exact_u: false,
    };
    let environment = EnvironmentOptions {
        overrides: EnvironmentOverrides {
            map: env,
            spp,
            ..Default::default()
        },
        ..Default::default()
    };
    Ok(RenderRequest {
        settings,
        environment,
        prepare: prepare_config(),
        ..defaults
    })
}

/// The recording of one shading point: its stages in the workbench stepper's order, its
/// numbers, and its views as figures.
#[pyclass(module = "penumbra")]
struct Recording {
    probe: penumbra::inspect::Probe,
    /// The context the recording was made in: the light and bsp views draw on its meshes
    /// and trees.
    prepared: Arc<request::PreparedRender>,
}

#[pymethods]
impl Recording {
    /// The stages, as the stepper labels them (stage N of `figure` is `stages[N - 1]`).
    #[getter]
    fn stages(&self) -> Vec<String> {
        penumbra::views::stages::probe_steps(&self.probe)
            .into_iter()
            .map(|s| s.label)
            .collect()
    }

    /// The polygon stage N (the stepper's 1 to len(stages)) produces, as a list of (n, 3)
    /// float64 arrays, one per loop: unit directions in the shading frame (z along the
    /// normal), or for a set difference the result's homogeneous points (x, y, w) in the
    /// occluder's projection plane; empty for GetBetween and the integral.
    fn polygons<'py>(
        &self,
        py: Python<'py>,
        stage: usize,
    ) -> PyResult<Vec<Bound<'py, numpy::PyArray2<f64>>>> {
        let steps = penumbra::views::stages::probe_steps(&self.probe);
        let index = penumbra::views::current_stage(&steps, Some(stage))
            .map_err(value_error)?
            .unwrap_or(0);
        penumbra::views::stages::step_polygon(&self.probe, &steps[index])
            .into_iter()
            .map(|lp| {
                let flat: Vec<f64> = lp.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
                numpy::ndarray::Array2::from_shape_vec((lp.len(), 3), flat)
                    .map(|a| a.into_pyarray(py))
                    .map_err(value_error)
            })
            .collect()
    }

    /// The pixel's radiance (r, g, b).
    #[getter]
    fn radiance(&self) -> (f64, f64, f64) {
        from_dvec3(self.probe.radiance)
    }

    /// The debug dump as JSON text, as `penumbra probe` writes it.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.probe).map_err(value_error)
    }

    /// A view of the recording as a figure: `view` is sphere, hemisphere, plane, light, bsp or
    /// environment; `stage` the stepper's number (1 to len(stages); every stage by default);
    /// `light` the light the light and bsp views show (by name; the stage's light by default).
    #[pyo3(signature = (view="sphere", stage=None, style="print", size=800, difference=0, fit=false, light=None))]
    #[allow(clippy::too_many_arguments)]
    fn figure(
        &self,
        view: &str,
        stage: Option<usize>,
        style: &str,
        size: u32,
        difference: usize,
        fit: bool,
        light: Option<String>,
    ) -> PyResult<Figure> {
        let style = penumbra::views::Style::from_name(style)
            .ok_or_else(|| value_error(format!("style {style:?}: expected print or screen")))?;
        let request = penumbra::views::FigureRequest {
            view: view.to_string(),
            stage,
            difference,
            light,
            style,
            size,
            orbit: None,
            fit,
        };
        let figure = penumbra::views::recording_figure(&self.probe, Some(&self.prepared.ctx), &request)
            .map_err(value_error)?;
        Ok(Figure { figure })
    }

    fn __repr__(&self) -> String {
        format!(
            "Recording(pixel={:?}, {} stages)",
            self.probe.pixel,
            self.stages().len()
        )
    }
}

/// A figure: shown inline by notebooks (SVG), written as SVG, PDF or PNG.
#[pyclass(module = "penumbra")]
struct Figure {
    figure: penumbra::figure::Figure,
}

#[pymethods]
impl Figure {
    /// The figure as an SVG document.
    fn svg(&self) -> String {
        penumbra::figure::svg::to_svg(&self.figure)
    }

    fn _repr_svg_(&self) -> String {
        self.svg()
    }

    /// Writes the figure as SVG, PDF or PNG, by the path's extension.
    fn save(&self, path: std::path::PathBuf) -> PyResult<()> {
        penumbra::figure::save(&self.figure, &path)
            .map_err(|e| PyOSError::new_err(format!("{e:#}")))
    }

    /// (width, height) in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.figure.width, self.figure.height)
    }
}

/// Loads a scene: an embedded scene's name (see `penumbra scenes`) or an OBJ, glTF or TOML
/// scene file. Malformed files raise ValueError naming the file and line; a missing file
/// raises FileNotFoundError.
#[pyfunction]
fn load_scene(name_or_path: &str) -> PyResult<Scene> {
    use penumbra::scene::scene_file;
    let scene = scene_file::load_scene_by_name(name_or_path).map_err(|e| {
        let missing = !std::path::Path::new(name_or_path).exists()
            && !scene_file::embedded_scene_names().contains(&name_or_path);
        if missing {
            PyFileNotFoundError::new_err(e.to_string())
        } else {
            value_error(e)
        }
    })?;
    Ok(Scene {
        name: name_or_path.to_string(),
        camera: scene.camera,
        scene,
        prepared: Default::default(),
        preparations: Default::default(),
    })
}

/// The names of the embedded scenes.
#[pyfunction]
fn scenes() -> Vec<&'static str> {
    penumbra::scene::scene_file::embedded_scene_names().to_vec()
}

/// The error metrics of `penumbra compare` between two (h, w, 3) images.
#[pyfunction]
#[pyo3(signature = (image, reference, stderr=None))]
fn compare(
    py: Python<'_>,
    image: PyReadonlyArray3<'_, f32>,
    reference: PyReadonlyArray3<'_, f32>,
    stderr: Option<PyReadonlyArray3<'_, f32>>,
) -> PyResult<Py<PyAny>> {
    let pixels = |a: &PyReadonlyArray3<'_, f32>| -> PyResult<(Vec<usize>, Vec<[f32; 3]>)> {
        let shape = a.as_array().shape().to_vec();
        if shape.len() != 3 || shape[2] != 3 {
            return Err(value_error(format!(
                "expected an (h, w, 3) array, got {shape:?}"
            )));
        }
        let v: Vec<f32> = a.as_array().iter().copied().collect();
        Ok((shape, v.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()))
    };
    let (sa, a) = pixels(&image)?;
    let (sb, b) = pixels(&reference)?;
    if sa != sb {
        return Err(value_error(format!(
            "image is {sa:?} but reference is {sb:?}"
        )));
    }
    let s = stderr.as_ref().map(pixels).transpose()?;
    let stats = penumbra::render::compare::compare(&a, &b, s.as_ref().map(|s| &s.1[..]));
    // As `penumbra compare` prints it: its JSON, read back as a dict.
    to_python(py, &stats)
}

/// `penumbra stress`: `cases` random and adversarial configurations from `seed`, each shaded
/// analytically and by a ray-cast oracle of `rays` rays; its report as a dict (the CLI's JSON;
/// `seconds` is the run's own time). The interpreter is released while it runs, and Ctrl-C
/// stops it within a case (KeyboardInterrupt), once the trees of the thesis' polyhedra exist
/// (built on the first call of a process, in about 3 s, which Ctrl-C does not interrupt).
#[pyfunction]
#[pyo3(signature = (cases=1000, seed=1, rays=256))]
fn stress(py: Python<'_>, cases: u64, seed: u64, rays: u32) -> PyResult<Py<PyAny>> {
    let report = interruptible(py, move |cancel| {
        penumbra::stress::run(cases, seed, rays, Some(cancel), |_| {})
    })?;
    to_python(py, &report)
}

/// `penumbra bench` on `scene` through its camera, its whole report (`bench.json`) as a dict:
/// every method (by CLI name; all but `reference` by default) at each sample count of
/// `ladder` against a reference of `reference_spp` samples, each deterministic render
/// repeated `repeats` times (the fastest kept). The dict holds the scene, the size, the
/// reference's noise, the rows (scene, method, spp, seconds, mae, rmse, relative_rmse,
/// rmse_corrected, violations, fallbacks, peak_mb), the equal-time table and the speed ratios.
/// The interpreter is released while it runs, and Ctrl-C stops it within a tile of the
/// current render (KeyboardInterrupt). `penumbra.bench` gives the rows alone.
#[pyfunction]
#[pyo3(signature = (scene, size=(160, 120), ladder=vec![1, 2, 4, 8, 16, 32, 64, 128, 256], methods=None, reference_spp=4096, seed=1, repeats=2, aa=1))]
#[allow(clippy::too_many_arguments)]
fn bench_report(
    py: Python<'_>,
    scene: &Scene,
    size: (u32, u32),
    ladder: Vec<u32>,
    methods: Option<Vec<String>>,
    reference_spp: u32,
    seed: u64,
    repeats: u32,
    aa: u32,
) -> PyResult<Py<PyAny>> {
    use penumbra::bench::runner;
    let camera = scene.camera_or_error()?;
    let label = std::path::Path::new(&scene.name)
        .file_stem()
        .map_or(scene.name.clone(), |s| s.to_string_lossy().into_owned());
    let mut config = runner::BenchConfig::new(&label, camera, size.0, size.1);
    config.aa = aa;
    config.ladder = ladder;
    if let Some(names) = methods {
        config.methods = names
            .iter()
            .map(|n| method_by_name(n))
            .collect::<PyResult<_>>()?;
    }
    config.reference_spp = reference_spp;
    config.seed = seed;
    config.repeats = repeats;
    config.prepare = prepare_config();
    let loaded = scene.scene.clone();
    let report = interruptible(py, move |cancel| -> penumbra::Result<_> {
        let ctx = config.prepare(&loaded);
        let reference = runner::render_reference(&ctx, &config, Some(cancel))?;
        Ok(runner::run_bench(&ctx, &config, &reference, Some(cancel), |_, _, _| {})?.0)
    })?;
    to_python(py, &report.map_err(value_error)?)
}

/// The chart `penumbra bench` writes as `time_vs_rmse.svg`, from a `bench_report` dict:
/// RMSE against run time, log–log, one series per method, the reference's noise as a line.
#[pyfunction]
#[pyo3(signature = (report, width=900, height=600))]
fn bench_chart(
    py: Python<'_>,
    report: &Bound<'_, PyAny>,
    width: u32,
    height: u32,
) -> PyResult<Figure> {
    let json: String = py
        .import("json")?
        .call_method1("dumps", (report,))?
        .extract()?;
    let report: penumbra::bench::table::BenchReport = serde_json::from_str(&json)
        .map_err(|e| PyValueError::new_err(format!("not a bench report: {e}")))?;
    let chart = penumbra::bench::output::time_vs_rmse_chart(&report);
    Ok(Figure {
        figure: penumbra::figure::plot::chart_figure(&chart, width, height),
    })
}

/// A serialisable value as the Python object `json.loads` makes of its JSON.
fn to_python<T: serde::Serialize>(py: Python<'_>, value: &T) -> PyResult<Py<PyAny>> {
    let json = serde_json::to_string(value).map_err(value_error)?;
    Ok(py.import("json")?.call_method1("loads", (json,))?.unbind())
}

#[pymodule]
fn _penumbra(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Camera>()?;
    m.add_class::<Recording>()?;
    m.add_class::<Figure>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(stress, m)?)?;
    m.add_function(wrap_pyfunction!(bench_report, m)?)?;
    m.add_function(wrap_pyfunction!(bench_chart, m)?)?;
    Ok(())
}
