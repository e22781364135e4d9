//! One pixel under the microscope: the shading point a camera ray hits, shaded by the same
//! `shade` call as the renderer with a [`StageRecording`] attached, plus the per-light numbers
//! the workbench shows. `penumbra probe` writes a [`Probe`] as the JSON debug dump; the
//! workbench reads it back and replays the sphere view without the scene.

use crate::accel::Ray;
use crate::math::{Frame, Pcg32};
use crate::render::RenderContext;
use crate::render::environment_passes::{EnvironmentSettings, environment_pixel};
use crate::scene::{Camera, Material};
use crate::shading::derivative::{Axis, Motion, PointMotion};
use crate::shading::{
    CorrectionSampling, EnvironmentPass, EnvironmentSample, EnvironmentTerm, Method, ShadingPoint,
    ShadingScratch, ShadingStats, Stage, StageRecording, environment_integrals, shade,
    shade_corrected, shade_with_rate,
};
use crate::stochastic::{EstimatorScratch, LightSampling, direct_samples};
use glam::DVec3;

/// Numbers of one light at the probed point.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LightSummary {
    /// Index into the prepared scene's lights.
    pub light: usize,
    pub name: String,
    /// Analytic value without occluders (003's U for this light).
    pub unshadowed: DVec3,
    /// Analytic value with occluders (what the pixel gets from this light).
    pub shadowed: DVec3,
    /// Solid angle of the horizon-clipped light polygon(s), summed over pieces.
    pub solid_angle: f64,
    /// Solid angle of the visible polygon(s) after the set differences.
    pub visible_solid_angle: f64,
    /// `analytic-exact`: the sampled correction of the LTC over the visible polygon
    /// (`shadowed + correction` estimates the GGX value).
    #[serde(default)]
    pub correction: DVec3,
}

impl LightSummary {
    /// Visible share of the light's solid angle above the horizon.
    pub fn visible_fraction(&self) -> f64 {
        if self.solid_angle > 0.0 {
            self.visible_solid_angle / self.solid_angle
        } else {
            0.0
        }
    }
}

/// A Monte Carlo estimate of the shadowed direct lighting at the point (the `mc` method's
/// estimator), with its standard error.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct MonteCarloEstimate {
    pub samples: u32,
    pub mean: DVec3,
    pub stderr: DVec3,
}

/// The environment light at the probed pixel (paper 002): which light, how it is rendered,
/// and what the renderer computed there.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentProbe {
    /// The map (`sky`, `sky-sh` or a file) with its rotation about +y (degrees) and scale.
    pub label: String,
    pub rotate_deg: f64,
    pub scale: f64,
    pub settings: Option<EnvironmentSettings>,
    /// The pixel's environment radiance as `render::environment_passes` composes it before the
    /// filter: ρ/π · E on a surface, the map itself where the camera ray misses.
    pub radiance: DVec3,
    /// `rt` with the 5×5 filter: the render's pixel uses the filtered E_occluded of its
    /// neighbourhood, so it differs from `radiance` (which is the unfiltered value).
    pub filtered_in_render: bool,
    /// The renderer's numbers at the point (none where the ray misses or the surface does not
    /// receive light).
    pub sample: Option<EnvironmentSample>,
    /// E_static and E_occluded by the exact method (`environment_integrals`) at the same
    /// point, to compare a ray-traced method with.
    pub exact_static: Option<DVec3>,
    pub exact_occluded: Option<DVec3>,
    /// The exact method's terms when the render's method is not `analytic` (with `analytic`
    /// they are in `recording.environment`, recorded by the render's own call).
    pub exact_terms: Vec<EnvironmentTerm>,
    /// The map's radiance at the centres of a coarse latitude–longitude grid of the whole
    /// sphere in the shading frame: row r at θ = π(r + ½)/rows from the normal, column c at
    /// φ = 2π(c + ½)/cols from the frame's x axis; row-major. The sphere view's background.
    pub sky_rows: u32,
    pub sky_cols: u32,
    pub sky: Vec<DVec3>,
}

/// Rows and columns of [`EnvironmentProbe::sky`].
pub(crate) const SKY_GRID: (u32, u32) = (16, 32);

/// The direction of cell (r, c) of a `rows`×`cols` grid (see [`EnvironmentProbe::sky`]),
/// at fractional position (r + a, c + b), in the shading frame.
pub(crate) fn sky_grid_direction(rows: u32, cols: u32, r: f64, c: f64) -> DVec3 {
    let theta = std::f64::consts::PI * r / rows as f64;
    let phi = std::f64::consts::TAU * c / cols as f64;
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The correction of the LTC at a probed point (`analytic-exact`).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct CorrectionProbe {
    /// Directions per light piece.
    pub samples: u32,
    pub seed: u64,
    /// Summed over lights; `radiance` includes it.
    pub value: DVec3,
    pub stderr: DVec3,
}

/// The derivative a probe recorded along a rigid motion (`shading::shade_with_rate`, the
/// renderer's `render_derivative` at this point): the motion, and the point's rate. Each light
/// record of the recording holds its moving edges and its own rate.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DerivativeProbe {
    /// The moving object (its index in the scene) and its name.
    pub object: u32,
    pub object_name: String,
    pub axis: Axis,
    /// The pivot of a rotation ([`Axis::Ry`]), world space.
    pub pivot: DVec3,
    /// `d radiance / dθ` at the point (the shaded value's; what is emitted does not move).
    pub rate: DVec3,
    /// Edges of visible polygons whose support was not found though they may move (the
    /// renderer masks such a pixel).
    pub unsupported: u32,
    /// The LTC lookup lies within the finite-difference step of a table node (masked too).
    pub near_table_node: bool,
    /// The point's rates are degenerate (a grazing ray; the view along a turning normal).
    pub degenerate: bool,
}

impl DerivativeProbe {
    /// The motion the derivative follows.
    pub fn motion(&self) -> Motion {
        Motion {
            object: self.object,
            axis: self.axis,
            pivot: self.pivot,
        }
    }

    /// "d/dtx of NAME", as the workbench labels the derivative.
    pub fn label(&self) -> String {
        format!("d/d{} of {}", self.axis.name(), self.object_name)
    }
}

/// Everything known about one probed pixel: the debug dump.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Probe {
    pub scene: String,
    pub method: Option<Method>,
    /// Pixel position; the ray goes through (x + 0.5, y + 0.5).
    pub pixel: (f64, f64),
    pub size: (u32, u32),
    pub camera: Option<Camera>,
    pub point: Option<ShadingPoint>,
    pub object_name: Option<String>,
    pub material: Option<Material>,
    /// Shading frame: the normal (z), the tangent toward the view (x), and the view and mirror
    /// directions, in world space.
    pub frame_x: DVec3,
    pub frame_y: DVec3,
    pub frame_z: DVec3,
    pub emitted: DVec3,
    /// emitted + the shaded value: equals the pixel of an `--aa 1` render bit for bit.
    pub radiance: DVec3,
    pub stats: ShadingStats,
    pub lights: Vec<LightSummary>,
    /// Names of the prepared scene's occluders, by index.
    pub occluder_names: Vec<String>,
    pub recording: StageRecording,
    pub monte_carlo: Option<MonteCarloEstimate>,
    /// The environment light at the pixel, when the scene has one (absent in older dumps).
    #[serde(default)]
    pub environment: Option<EnvironmentProbe>,
    /// `analytic-exact`: how the LTC's correction was sampled, and its standard error
    /// (`radiance` then includes the correction).
    #[serde(default)]
    pub correction: Option<CorrectionProbe>,
    /// With a derivative along a rigid motion (`probe_full`'s `derivative`): the motion and
    /// the point's rate; the light records hold the moving edges.
    #[serde(default)]
    pub derivative: Option<DerivativeProbe>,
}

impl Probe {
    /// Reads a debug dump written by `penumbra probe` or the workbench. Errors name the file
    /// and, for text that is not a dump, the line and column (`name:line:column: ...`).
    pub fn from_json(text: &str, name: &str) -> crate::Result<Probe> {
        let at = |e: serde_json::Error, what: &str| {
            if e.line() > 0 {
                format!("{name}:{}:{}: {what}: {e}", e.line(), e.column())
            } else {
                format!("{name}: {what}: {e}")
            }
        };
        let probe: Probe =
            serde_json::from_str(text).map_err(|e| at(e, "not a penumbra debug dump"))?;
        probe.check().map_err(|e| format!("{name}: {e}"))?;
        Ok(probe)
    }

    /// What a replay relies on beyond the JSON's shape: directions are unit vectors (the
    /// sphere view draws them as points of the sphere), numbers are finite.
    fn check(&self) -> crate::Result<()> {
        let unit = |d: DVec3| d.is_finite() && (d.length() - 1.0).abs() <= 1e-6;
        let ok =
            |poly: &crate::geometry::SphericalPolygon| poly.vertices().iter().all(|&d| unit(d));
        for (k, l) in self.recording.lights.iter().enumerate() {
            let mut polygons = l
                .polygons
                .iter()
                .map(|(_, p)| p)
                .chain(l.occluder_polygons.iter().map(|(_, _, _, p)| p))
                .chain(l.lobes.iter().flat_map(|(_, a, b, _)| [a, b]));
            let mut edges = l.contours.iter().flat_map(|(_, e)| e.iter().flatten());
            let mut exact = l
                .exact
                .iter()
                .flat_map(|e| e.crossings.iter().chain(e.rejected.iter().flatten()));
            if !(polygons.all(ok) && edges.all(|&d| unit(d)) && exact.all(|&d| unit(d))) {
                return Err(crate::Error::from(format!(
                    "recorded light {k}: a direction is not a unit vector (the dump was edited?)"
                )));
            }
        }
        let env = &self.recording.environment;
        let exact_terms = self.environment.iter().flat_map(|e| &e.exact_terms);
        let terms_ok = env.terms.iter().chain(exact_terms).all(|t| ok(&t.polygon));
        let cones_ok = env
            .cones
            .iter()
            .chain(&env.merged_cones)
            .all(|c| unit(c.axis) && c.half_angle.is_finite());
        let rays_ok = env.rays.iter().all(|r| unit(r.dir));
        let sky_ok = self.environment.as_ref().is_none_or(|e| {
            e.sky.len() == (e.sky_rows * e.sky_cols) as usize && e.sky.iter().all(|c| c.is_finite())
        });
        if !(terms_ok && cones_ok && rays_ok && sky_ok) {
            return Err(
                "recorded environment: a direction is not a unit vector or the sky grid is \
                 malformed (the dump was edited?)"
                    .into(),
            );
        }
        Ok(())
    }
}

/// The camera ray through pixel (x, y) (centre at x + 0.5, y + 0.5).
pub(crate) fn pixel_ray(
    camera: &Camera,
    size: (u32, u32),
    pixel: (f64, f64),
) -> crate::Result<Ray> {
    let basis = camera.basis()?;
    Ok(Ray {
        origin: basis.eye,
        dir: basis.direction(pixel.0 + 0.5, pixel.1 + 0.5, size.0, size.1),
    })
}

/// Probes pixel `pixel` of a `size` image seen by `camera`: the same `primary_hit` and
/// `shade` as the renderer, recorded. `gh_steps` also records the Greiner–Hormann phases.
pub fn probe(
    ctx: &RenderContext,
    scene_name: &str,
    camera: &Camera,
    size: (u32, u32),
    pixel: (f64, f64),
    method: Method,
    gh_steps: bool,
) -> crate::Result<Probe> {
    probe_corrected(ctx, scene_name, camera, size, pixel, method, None, gh_steps)
}

/// The stream of correction samples `analytic-exact` gives pixel (x, y) of a `width`-wide
/// `--aa 1` render (`render::stochastic`), so that a probe with the render's seed and sample
/// count records the render's own value.
pub fn correction_stream(pixel: (f64, f64), width: u32) -> u64 {
    pixel.1.max(0.0) as u64 * width as u64 + pixel.0.max(0.0) as u64
}

/// What a probe of a pixel records for the render method `method`: the analytic stages that
/// method runs, and for `analytic-exact` the LTC's correction sampled as the render's first
/// pass samples the pixel (`spp` directions, `seed`, at `--aa 1` in an image `width` wide).
/// The one decision of the command line's `probe` and the workbench's pick. A stochastic
/// method has no stages to record: `Err` says so, in words for the user.
pub(crate) fn probe_method(
    method: crate::render::RenderMethod,
    spp: u32,
    seed: u64,
    pixel: (f64, f64),
    width: u32,
) -> crate::Result<(Method, Option<CorrectionSampling>)> {
    use crate::render::RenderMethod;
    match (method, method.analytic()) {
        (_, Some(m)) => Ok((m, None)),
        (RenderMethod::AnalyticExact, None) => Ok((
            Method::Analytic,
            Some(CorrectionSampling {
                samples: spp,
                seed,
                stream: correction_stream(pixel, width),
            }),
        )),
        (m, None) => Err(crate::Error::from(format!(
            "{} is stochastic: a probe records the analytic stages only (analytic, \
             analytic-exact, per-triangle or unshadowed)",
            m.name()
        ))),
    }
}

/// [`probe`], with the LTC's correction sampled as `analytic-exact` does when `correction` is
/// given (`method` is then the visibility method, `Method::Analytic`).
#[allow(clippy::too_many_arguments)]
pub fn probe_corrected(
    ctx: &RenderContext,
    scene_name: &str,
    camera: &Camera,
    size: (u32, u32),
    pixel: (f64, f64),
    method: Method,
    correction: Option<CorrectionSampling>,
    gh_steps: bool,
) -> crate::Result<Probe> {
    probe_full(
        ctx, scene_name, camera, size, pixel, method, correction, gh_steps, None,
    )
}

/// [`probe_corrected`], and with `derivative` the point shaded as the derivative's renderer
/// shades it (`shading::shade_with_rate`, the same stages with the rate of each edge): the
/// recording's light records then hold their moving edges and rates, and
/// [`Probe::derivative`] the point's rate. A derivative is computed for `Method::Analytic`
/// without a correction only (as `RenderContext::render_derivative` refuses the others);
/// for any other method `derivative` is ignored and `Probe::derivative` stays `None`.
#[allow(clippy::too_many_arguments)]
pub fn probe_full(
    ctx: &RenderContext,
    scene_name: &str,
    camera: &Camera,
    size: (u32, u32),
    pixel: (f64, f64),
    method: Method,
    correction: Option<CorrectionSampling>,
    gh_steps: bool,
    derivative: Option<&Motion>,
) -> crate::Result<Probe> {
    let derivative = derivative.filter(|_| correction.is_none() && method == Method::Analytic);
    let ray = pixel_ray(camera, size, pixel)?;
    let mut probe = Probe {
        scene: scene_name.into(),
        method: Some(method),
        pixel,
        size,
        camera: Some(*camera),
        occluder_names: ctx
            .prepared
            .occluders
            .iter()
            .map(|&o| ctx.prepared.objects[o as usize].name.clone())
            .collect(),
        ..Probe::default()
    };
    // The environment's term of the pixel: the renderer's own passes with the recorder on.
    let mut recording = StageRecording::new(gh_steps);
    let environment = match &ctx.environment {
        Some(env) => {
            let (x, y) = pixel;
            if x.fract() != 0.0 || y.fract() != 0.0 || x < 0.0 || y < 0.0 {
                return Err(crate::Error::from(format!(
                    "pixel ({x}, {y}): with an environment light the pixel must be whole \
                     (its rays' rotation is keyed by the pixel index, 002 Sect. 4)"
                )));
            }
            let basis = camera.basis()?;
            // A recording of its own: the exact method's set differences would otherwise go
            // to a light record of the area lights. Only its environment part is kept.
            let mut env_recording = StageRecording::new(false);
            let radiance = environment_pixel(
                ctx,
                env,
                &basis,
                x as u32,
                y as u32,
                size.0,
                size.1,
                &mut env_recording,
            );
            recording.environment = env_recording.environment;
            let map = &env.light.map;
            Some(EnvironmentProbe {
                label: env.light.label.clone(),
                rotate_deg: map.rotate_deg,
                scale: map.scale,
                settings: Some(env.settings),
                radiance,
                filtered_in_render: env.settings.filters(),
                sample: recording.environment.samples.first().copied(),
                ..EnvironmentProbe::default()
            })
        }
        None => None,
    };
    let env_radiance = environment.as_ref().map_or(DVec3::ZERO, |e| e.radiance);
    probe.environment = environment;
    let Some(hit) = ctx.primary_hit(&ray) else {
        probe.radiance = env_radiance;
        probe.recording = recording;
        return Ok(probe);
    };
    let sp = hit.point;
    let object = sp.object.unwrap_or(0) as usize;
    probe.point = Some(sp);
    probe.object_name = ctx.scene.objects.get(object).map(|o| o.name.clone());
    probe.emitted = hit.emitted;
    probe.radiance = hit.emitted;
    let frame = crate::math::Frame::from_normal_and_view(sp.normal, sp.view);
    probe.frame_x = frame.to_world(DVec3::X);
    probe.frame_y = frame.to_world(DVec3::Y);
    probe.frame_z = frame.to_world(DVec3::Z);
    if let (Some(env), Some(e)) = (&ctx.environment, &mut probe.environment) {
        fill_environment_probe(ctx, env, &sp, &frame, e);
    }
    if !hit.receiver {
        probe.radiance += env_radiance;
        probe.recording = recording;
        return Ok(probe);
    }
    let material = ctx.prepared.materials[object].clone();
    let mut scratch = ShadingScratch::default();
    // Through its tile, as the renderer shades it (an `--aa 1` pixel): the region of its
    // block shares what it can, and the recording says what.
    // (The derivative's renderer shades every sample on its own.)
    if ctx.prepared.tiles_share_candidates(method)
        && derivative.is_none()
        && pixel.0 >= 0.0
        && pixel.1 >= 0.0
    {
        let basis = camera.basis()?;
        let at = (pixel.0.floor() as u32, pixel.1.floor() as u32);
        scratch.share_with_tile(ctx.tile_region_of(&basis, (size.0, size.1, 1), at));
    }
    // The pixel's value: exactly what `RenderContext::radiance` computes, plus the
    // environment's term as `RenderContext::render_full` adds it.
    probe.radiance = match (&correction, derivative) {
        // `RenderContext::render_derivative`'s sample: emitted + `shade_with_rate`.
        (None, Some(motion)) => {
            let pm = PointMotion::at(motion, &sp, ray.dir);
            let (l, rate) = shade_with_rate(
                &ctx.prepared,
                &sp,
                &material,
                method,
                &pm,
                &mut scratch,
                &mut recording,
            );
            let notes = scratch.rate_notes();
            let (mut rate, degenerate) = (rate, pm.degenerate);
            let mut unsupported = notes.unsupported;
            // The environment's rate, as the renderer's sample adds it (its value is in the
            // environment's term below), on buffers of its own so that the point's counters
            // stay the area lights'.
            let mut env_scratch = ShadingScratch::default();
            if let Some(env) = ctx.environment_term_rate(&sp, &pm, &mut env_scratch) {
                rate += env.rate;
                unsupported += env.unsupported as u32;
            }
            probe.derivative = Some(DerivativeProbe {
                object: motion.object,
                object_name: ctx
                    .scene
                    .objects
                    .get(motion.object as usize)
                    .map_or_else(|| format!("#{}", motion.object), |o| o.name.clone()),
                axis: motion.axis,
                pivot: motion.pivot,
                rate,
                unsupported,
                near_table_node: notes.near_table_node,
                degenerate,
            });
            hit.emitted + l
        }
        // `RenderContext::radiance` with the correction: emitted + `shade_corrected`.
        (Some(c), _) => {
            let r = shade_corrected(
                &ctx.prepared,
                &sp,
                &material,
                method,
                c,
                &mut scratch,
                &mut recording,
            );
            probe.correction = Some(CorrectionProbe {
                samples: c.samples,
                seed: c.seed,
                value: r.correction,
                stderr: r.variance.map(f64::sqrt),
            });
            crate::shading::analytic_exact_pixel(hit.emitted, r.ltc, r.correction)
        }
        (None, None) => ctx.radiance(&ray, method, &mut scratch, &mut recording),
    } + env_radiance;
    probe.stats = scratch.stats;
    let mut unshadowed = StageRecording::new(false);
    shade(
        &ctx.prepared,
        &sp,
        &material,
        Method::Unshadowed,
        &mut scratch,
        &mut unshadowed,
    );
    probe.lights = ctx
        .prepared
        .lights
        .iter()
        .enumerate()
        .map(|(l, &(id, _))| {
            let mut s = LightSummary {
                light: l,
                name: ctx.prepared.objects[id as usize].name.clone(),
                ..LightSummary::default()
            };
            for r in recording.lights.iter().filter(|r| r.light == l) {
                s.shadowed += r.diffuse + r.specular;
                s.correction += r.correction;
                for (stage, poly) in &r.polygons {
                    match stage {
                        Stage::HorizonClipped => s.solid_angle += poly.signed_solid_angle(),
                        Stage::Visible => s.visible_solid_angle += poly.signed_solid_angle(),
                        _ => {}
                    }
                }
            }
            for r in unshadowed.lights.iter().filter(|r| r.light == l) {
                s.unshadowed += r.diffuse + r.specular;
            }
            s
        })
        .collect();
    probe.material = Some(material);
    probe.recording = recording;
    Ok(probe)
}

/// The parts of an [`EnvironmentProbe`] that do not come from the render's own passes: the
/// exact integrals at the point for comparison (the analytic method's own
/// `environment_integrals`, recorded) and the map on a coarse grid of the sphere.
fn fill_environment_probe(
    ctx: &RenderContext,
    env: &crate::render::environment_passes::SceneEnvironment,
    sp: &ShadingPoint,
    frame: &Frame,
    out: &mut EnvironmentProbe,
) {
    let (rows, cols) = SKY_GRID;
    out.sky_rows = rows;
    out.sky_cols = cols;
    out.sky = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| (r, c)))
        .map(|(r, c)| {
            let local = sky_grid_direction(rows, cols, r as f64 + 0.5, c as f64 + 0.5);
            env.light.radiance(frame.to_world(local))
        })
        .collect();
    let mut recording = StageRecording::new(false);
    let exact = environment_integrals(
        &ctx.prepared,
        &env.occluders,
        sp,
        EnvironmentPass::Occluded,
        &|f: &Frame, poly| env.light.integrate(f, poly),
        &mut ShadingScratch::default(),
        &mut recording,
    );
    out.exact_static = Some(
        exact
            .static_visible
            .unwrap_or_else(|| env.light.irradiance(sp.normal)),
    );
    out.exact_occluded = Some(exact.occluded);
    if env.settings.method != crate::environment::EnvMethod::Analytic {
        out.exact_terms = recording.environment.terms;
    }
}

/// The debug dump of one pixel, as `penumbra probe` writes it: the recording of the shading
/// point `ctx` (prepared as the same render prepares it) computes there for `settings`
/// (method, samples, seed, size), with a Monte Carlo check of 65,536 samples. `analytic-exact`
/// records the analytic stages plus the LTC's correction, sampled as the first pass of an
/// `--aa 1` render with the same samples and seed samples this pixel.
pub fn debug_dump(
    ctx: &RenderContext,
    scene_name: &str,
    camera: &Camera,
    settings: &crate::render::RenderSettings,
    pixel: (f64, f64),
    gh_steps: bool,
) -> crate::Result<Probe> {
    debug_dump_with(ctx, scene_name, camera, settings, pixel, gh_steps, None)
}

/// [`debug_dump`], with the derivative along `derivative` recorded as [`probe_full`] records
/// it (`penumbra probe --derivative OBJECT:AXIS`). A derivative of a method other than
/// `analytic`, or of a scene with an environment light, is refused, as the renderer refuses
/// it.
pub fn debug_dump_with(
    ctx: &RenderContext,
    scene_name: &str,
    camera: &Camera,
    settings: &crate::render::RenderSettings,
    pixel: (f64, f64),
    gh_steps: bool,
    derivative: Option<&Motion>,
) -> crate::Result<Probe> {
    let size = (settings.width, settings.height);
    let (method, correction) =
        probe_method(settings.method, settings.spp, settings.seed, pixel, size.0)?;
    // What the derivative covers is the renderer's to say.
    if derivative.is_some() {
        ctx.derivative_refusal(settings.method)?;
    }
    let mut dump = probe_full(
        ctx, scene_name, camera, size, pixel, method, correction, gh_steps, derivative,
    )?;
    if let (Some(sp), Some(m)) = (dump.point, dump.material.clone()) {
        dump.monte_carlo = Some(monte_carlo(ctx, &sp, &m, 65536, settings.seed));
    }
    Ok(dump)
}

/// The `mc` method's estimator at the probed point with `samples` samples: an independent
/// check of the analytic value, with its standard error.
pub fn monte_carlo(
    ctx: &RenderContext,
    point: &ShadingPoint,
    material: &Material,
    samples: u32,
    seed: u64,
) -> MonteCarloEstimate {
    let mut rng = Pcg32::new(seed, 0);
    let mut scratch = EstimatorScratch::default();
    let sums = direct_samples(
        &ctx.sampled(),
        point,
        material,
        samples,
        LightSampling::SolidAngle,
        &mut rng,
        &mut scratch,
    );
    MonteCarloEstimate {
        samples,
        mean: sums.s_n(),
        stderr: sums.s_variance_of_mean().map(f64::sqrt),
    }
}

/// A pixel worth inspecting first: on a receiver in the penumbra of a light, where the
/// pipeline does the most (set differences with several occluders), near the middle of the
/// light's shadow boundary. `None` when no sampled pixel is in a penumbra.
///
/// Candidates are the centres of a `grid`×`grid` lattice of cells, each shaded once by the
/// renderer's own `shade` with the recorder on (the recording is what the score reads). The
/// score prefers a visible share of the light's solid angle near one half, more occluders
/// subtracted, and pixels near the image centre; ties go to the first in scan order, so the
/// choice is deterministic.
pub fn interesting_pixel(
    ctx: &RenderContext,
    camera: &Camera,
    size: (u32, u32),
    grid: u32,
) -> Option<(f64, f64)> {
    use rayon::prelude::*;
    let basis = camera.basis().ok()?;
    let (w, h) = (size.0.max(1), size.1.max(1));
    let grid = grid.max(2);
    let cells: Vec<(u32, u32)> = (0..grid)
        .flat_map(|j| (0..grid).map(move |i| (i, j)))
        .collect();
    let scored: Vec<Option<(f64, (f64, f64))>> = cells
        .par_iter()
        .map_init(ShadingScratch::default, |scratch, &(i, j)| {
            let x = ((i as f64 + 0.5) / grid as f64 * w as f64).floor();
            let y = ((j as f64 + 0.5) / grid as f64 * h as f64).floor();
            let ray = Ray {
                origin: basis.eye,
                dir: basis.direction(x + 0.5, y + 0.5, w, h),
            };
            let hit = ctx.primary_hit(&ray)?;
            if !hit.receiver {
                return None;
            }
            let sp = hit.point;
            let material = &ctx.prepared.materials[sp.object.unwrap_or(0) as usize];
            let mut rec = StageRecording::new(false);
            shade(
                &ctx.prepared,
                &sp,
                material,
                Method::Analytic,
                scratch,
                &mut rec,
            );
            let mut best: Option<f64> = None;
            for r in &rec.lights {
                let (mut clipped, mut visible) = (0.0, 0.0);
                for (stage, poly) in &r.polygons {
                    match stage {
                        Stage::HorizonClipped => clipped += poly.signed_solid_angle(),
                        Stage::Visible => visible += poly.signed_solid_angle(),
                        _ => {}
                    }
                }
                if clipped <= 0.0 || r.set_differences.is_empty() {
                    continue;
                }
                let f = visible / clipped;
                if !(0.05..=0.95).contains(&f) {
                    continue;
                }
                let occluders = r.set_differences.len().min(3) as f64;
                let centre = ((x / w as f64 - 0.5).powi(2) + (y / h as f64 - 0.5).powi(2)).sqrt();
                let s = 1.0 - (f - 0.5).abs() + 0.15 * occluders - 0.5 * centre;
                best = Some(best.map_or(s, |b: f64| b.max(s)));
            }
            best.map(|s| (s, (x, y)))
        })
        .collect();
    scored
        .into_iter()
        .flatten()
        .fold(None, |acc: Option<(f64, (f64, f64))>, c| match acc {
            Some(a) if a.0 >= c.0 => Some(a),
            _ => Some(c),
        })
        .map(|c| c.1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::RenderMethod;

    /// The command line's probe and the workbench's pick read this one decision: every method
    /// either has analytic stages to record (analytic-exact with the render's own samples) or
    /// is refused with its name.
    #[test]
    fn every_render_method_is_probed_or_refused_by_name() {
        for m in RenderMethod::ALL {
            match probe_method(m, 7, 3, (5.0, 2.0), 10) {
                Ok((method, correction)) => {
                    assert_eq!(Some(method), m.analytic().or(Some(Method::Analytic)));
                    match m {
                        RenderMethod::AnalyticExact => {
                            let c = correction.expect("analytic-exact samples its correction");
                            assert_eq!((c.samples, c.seed, c.stream), (7, 3, 25));
                        }
                        _ => assert!(correction.is_none(), "{}", m.name()),
                    }
                }
                Err(why) => {
                    assert!(m.analytic().is_none() && m != RenderMethod::AnalyticExact);
                    assert!(
                        why.to_string().contains(m.name())
                            && why.to_string().contains("stochastic"),
                        "{why}"
                    );
                }
            }
        }
    }
}
