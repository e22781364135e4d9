//! A render as a user asks for it (the command line, the Python module): a scene, the
//! environment options merged into it, the LTC table, prepared once for the settings. One
//! preparation whatever asks, so that equal requests give equal images bit for bit.

use super::environment::{EnvironmentSettings, StaticTerm};
use super::{RenderContext, RenderSettings};
use crate::environment::EnvironmentLight;
use crate::ltc::LtcTable;
use crate::scene::Scene;
use crate::scene::environment_spec::EnvironmentOverrides;
use crate::shading::PrepareConfig;

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

/// The LTC table named `spec`: `embedded`, `published` or a file, with `+renorm` for its
/// horizon-renormalised variant. Tables are kept for the process (a render refers to one).
pub fn ltc_table(spec: &str) -> Result<&'static LtcTable, String> {
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
pub fn resolve_environment(scene: &mut Scene, env: &EnvironmentOptions) -> Result<(), String> {
    scene.environment = env.overrides.apply(scene.environment.as_ref())?;
    Ok(())
}

/// Prepares `scene` (its environment already resolved, [`resolve_environment`]) for
/// `settings`: the context, the LTC table, and the environment loaded and attached with the
/// request's options and `settings.seed`; `config` is the caller's (the tree cache).
pub fn prepare(
    scene: &Scene,
    settings: &RenderSettings,
    env: &EnvironmentOptions,
    ltc: &'static LtcTable,
    config: &PrepareConfig,
) -> Result<PreparedRender, String> {
    let mut ctx = RenderContext::for_render(scene, settings, config);
    ctx.prepared.ltc = ltc;
    let mut notes = ctx.prepared.report.lines();
    let mut environment = None;
    if let Some(spec) = &scene.environment {
        let light = EnvironmentLight::load(spec).map_err(|e| format!("{e:#}"))?;
        let mut s = EnvironmentSettings::for_spec(spec, settings.seed);
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

/// [`resolve_environment`] then [`prepare`]: a loaded scene made ready for one request (the
/// command line's and the Python module's one way to it).
pub fn resolve_and_prepare(
    scene: &mut Scene,
    settings: &RenderSettings,
    env: &EnvironmentOptions,
    ltc: &'static LtcTable,
    config: &PrepareConfig,
) -> Result<PreparedRender, String> {
    resolve_environment(scene, env)?;
    prepare(scene, settings, env, ltc, config)
}
