//! `--env*`: the environment the command line asks for, merged with the scene's by the
//! library (`scene::environment_spec::EnvironmentOverrides`).

use super::args::*;
use anyhow::Result;
use penumbra::environment::EnvironmentLight;
use penumbra::render::RenderContext;
use penumbra::render::environment::EnvironmentSettings;
use penumbra::scene::Scene;
use penumbra::scene::environment_spec::EnvironmentOverrides;

/// Puts the environment `args` ask for into `scene.environment` (the command line overrides
/// the scene file's `[environment]`; `--env none` removes it), so that the scene is prepared
/// knowing it has one.
pub(crate) fn resolve_environment(scene: &mut Scene, args: &RenderArgs) -> Result<()> {
    let e = &args.env;
    let overrides = EnvironmentOverrides {
        map: e.env.clone(),
        rotate_deg: e.env_rotate,
        scale: e.env_scale,
        method: e.env_method,
        spp: args.spp,
    };
    scene.environment = overrides
        .apply(scene.environment.as_ref())
        .map_err(anyhow::Error::msg)?;
    Ok(())
}

/// Loads the scene's environment (after [`resolve_environment`]) and attaches it to `ctx`.
/// GGX lobes get no environment light (002 is diffuse): said once here.
pub(crate) fn attach_environment(
    ctx: &mut RenderContext,
    scene: &Scene,
    args: &RenderArgs,
) -> Result<Option<EnvironmentSettings>> {
    let Some(spec) = &scene.environment else {
        return Ok(None);
    };
    let light = EnvironmentLight::load(spec)?;
    let mut settings = EnvironmentSettings::for_spec(spec, args.seed);
    if args.env.env_no_filter {
        settings.filter = false;
    }
    settings.max_cones = args.env.env_max_cones;
    if let Some(t) = args.env.env_static {
        settings.static_term = t;
    }
    if scene.objects.iter().any(|o| o.material.has_specular()) {
        eprintln!(
            "note: the environment lights the diffuse lobe only (002 is diffuse); GGX lobes see the area lights alone"
        );
    }
    ctx.set_environment(std::sync::Arc::new(light), settings);
    Ok(Some(settings))
}
