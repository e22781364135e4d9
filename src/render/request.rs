//! A render as a user asks for it ([`RenderRequest`]: the command line, Python, the benchmark
//! and the workbench): a scene, the environment options merged into it, the LTC table,
//! prepared once for the settings. One preparation whatever asks, so that equal requests give
//! equal images bit for bit.

use super::environment_passes::{EnvironmentSettings, StaticTerm};
use super::{RenderContext, RenderSettings};
use crate::environment::EnvironmentLight;
use crate::ltc::LtcTable;
use crate::scene::Scene;
use crate::scene::environment_spec::EnvironmentOverrides;
use crate::shading::{PrepareConfig, PrepareOptions};

/// The environment options of a request (`--env*` on the command line).
#[derive(Clone, Debug, Default)]
pub struct EnvironmentOptions {
    /// The map, rotation, scale, method and rays, over the scene file's `[environment]`.
    pub overrides: EnvironmentOverrides,
    /// Leave the 5×5 filter of `rt`'s occlusion off.
    pub no_filter: bool,
    pub max_cones: Option<usize>,
    pub static_term: Option<StaticTerm>,
}

/// A scene prepared for one request: the context to render with, the environment's settings
/// if it has one, and notes worth telling the user.
pub struct PreparedRender {
    pub ctx: RenderContext,
    pub environment: Option<EnvironmentSettings>,
    pub notes: Vec<String>,
}

/// A render as a user asks for it, with the defaults every caller starts from: what to render
/// (`settings`: method, size, sub-pixel positions, samples, seed), the environment's options
/// over the scene file's, the LTC table, and how scenes are prepared (the caller's
/// [`PrepareConfig`]). The command line, Python, the benchmark and the workbench build theirs
/// from [`RenderRequest::default`], so that a default is written once.
#[derive(Clone)]
pub struct RenderRequest {
    pub settings: RenderSettings,
    pub environment: EnvironmentOptions,
    pub ltc: &'static LtcTable,
    pub prepare: PrepareConfig,
}

impl Default for RenderRequest {
    fn default() -> Self {
        RenderRequest {
            settings: RenderSettings::default(),
            environment: EnvironmentOptions::default(),
            ltc: LtcTable::embedded(),
            prepare: PrepareConfig::default(),
        }
    }
}

impl RenderRequest {
    /// `settings` with every other part of the request at its default.
    pub fn with_settings(settings: RenderSettings) -> Self {
        RenderRequest {
            settings,
            ..RenderRequest::default()
        }
    }

    /// How `scene` is prepared for this request: trees sized by the cost model for the
    /// request's camera rays, knowing whether the scene has an environment, with the request's
    /// LTC table and the caller's choices.
    pub(crate) fn prepare_options(&self, scene: &Scene) -> PrepareOptions<'_> {
        let s = &self.settings;
        PrepareOptions {
            expected_rays: u64::from(s.width) * u64::from(s.height) * u64::from(s.aa).pow(2),
            environment: scene.environment.is_some(),
            ltc: self.ltc,
            ..self.prepare.options()
        }
    }

    /// `scene` with the request's environment merged into it (`resolve_environment`), then
    /// prepared for the request ([`prepare`]): the command line's and Python's one way to a
    /// render.
    pub fn prepare(&self, scene: &mut Scene) -> crate::Result<PreparedRender> {
        resolve_environment(scene, &self.environment)?;
        prepare(scene, self)
    }
}

/// The LTC table named `spec`: `embedded`, `published` or a file, with `+renorm` for its
/// horizon-renormalised variant. Tables are kept for the process (a render refers to one).
pub fn ltc_table(spec: &str) -> crate::Result<&'static LtcTable> {
    let (name, renorm) = match spec.strip_suffix("+renorm") {
        Some(n) => (n, true),
        None => (spec, false),
    };
    let base: &'static LtcTable = match name {
        "embedded" => LtcTable::embedded(),
        "published" => crate::ltc::published::published(),
        path => Box::leak(Box::new(
            LtcTable::load(path).map_err(|e| format!("LTC table {path}: {e:#}"))?,
        )),
    };
    Ok(if renorm {
        Box::leak(Box::new(base.horizon_renormalized()))
    } else {
        base
    })
}

/// Merges `env` into `scene.environment` (the request overrides the scene file; a map of
/// `none` removes it), so that the scene is prepared knowing whether it has one.
pub(crate) fn resolve_environment(
    scene: &mut Scene,
    env: &EnvironmentOptions,
) -> crate::Result<()> {
    scene.environment = env.overrides.apply(scene.environment.as_ref())?;
    Ok(())
}

/// Prepares `scene` (its environment already resolved, `resolve_environment`) for
/// `request`: the context (its trees sized for the request's image, its LTC table), and the
/// environment loaded and attached with the request's options and `settings.seed`.
pub fn prepare(scene: &Scene, request: &RenderRequest) -> crate::Result<PreparedRender> {
    let mut ctx = RenderContext::for_render(scene, request);
    let mut notes = ctx.prepared.report.lines();
    let mut environment = None;
    let env = &request.environment;
    if let Some(spec) = &scene.environment {
        let light = EnvironmentLight::load(spec).map_err(|e| format!("{e:#}"))?;
        let mut s = EnvironmentSettings::for_spec(spec, request.settings.seed);
        if env.no_filter {
            s.filter = false;
        }
        s.max_cones = env.max_cones;
        if let Some(t) = env.static_term {
            s.static_term = t;
        }
        if scene.objects.iter().any(|o| o.material.has_specular()) {
            notes.push(
                "the environment lights the diffuse lobe only (002 is diffuse); GGX lobes see \
                 the area lights alone"
                    .into(),
            );
        }
        ctx.set_environment(std::sync::Arc::new(light), s);
        environment = Some(s);
    }
    Ok(PreparedRender {
        ctx,
        environment,
        notes,
    })
}
