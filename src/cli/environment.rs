//! `--env*`: the environment the command line asks for, as the library's request options
//! (`render::request::EnvironmentOptions`, merged with the scene's by the library).

use super::args::*;
use penumbra::render::request::EnvironmentOptions;
use penumbra::scene::environment_spec::EnvironmentOverrides;

/// The environment options of `args`.
pub(crate) fn environment_options(args: &RenderArgs) -> EnvironmentOptions {
    let e = &args.env;
    EnvironmentOptions {
        overrides: EnvironmentOverrides {
            map: e.env.clone(),
            rotate_deg: e.env_rotate,
            scale: e.env_scale,
            method: e.env_method,
            spp: args.spp,
        },
        no_filter: e.env_no_filter,
        max_cones: e.env_max_cones,
        static_term: e.env_static,
    }
}

/// Loads `args.scene` with the environment `args` ask for resolved into it, and prepares it
/// for `args`' settings (`render::request::prepare`), printing the library's notes.
pub(crate) fn prepared_scene(
    args: &RenderArgs,
) -> anyhow::Result<(
    penumbra::scene::Scene,
    penumbra::render::request::PreparedRender,
)> {
    use penumbra::render::request;
    let mut scene = super::render::load_scene(&args.scene)?;
    let ltc = super::ltc::ltc_table(&args.ltc_table)?;
    let settings = super::render::settings(args);
    let config = super::process_env::prepare_config();
    let prepared = request::resolve_and_prepare(
        &mut scene,
        &settings,
        &environment_options(args),
        ltc,
        &config,
    )
    .map_err(anyhow::Error::msg)?;
    for n in &prepared.notes {
        eprintln!("note: {n}");
    }
    Ok((scene, prepared))
}
