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
