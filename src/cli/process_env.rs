//! What the command line reads from its process's environment for the library, which reads
//! none: where trees are cached and the switches for measuring (docs/silhouettes.md).

use penumbra::shading::PrepareConfig;
use penumbra::shading::tree_cache::CacheVars;
use std::env::var_os;

/// `PENUMBRA_CACHE_DIR`, `PENUMBRA_CACHE_MAX`, `XDG_CACHE_HOME` and `HOME` as set.
pub(crate) fn cache_vars() -> CacheVars {
    CacheVars {
        cache_dir: var_os("PENUMBRA_CACHE_DIR"),
        cache_max: std::env::var("PENUMBRA_CACHE_MAX").ok(),
        xdg_cache_home: var_os("XDG_CACHE_HOME"),
        home: var_os("HOME"),
    }
}

/// The preparation the environment asks for (`PrepareConfig::from_vars`); a cache bound that
/// is not a size leaves the cache off, with a note.
pub fn prepare_config() -> PrepareConfig {
    let (config, warning) = PrepareConfig::from_vars(
        &cache_vars(),
        var_os("PENUMBRA_HOISTED_TREES").as_deref(),
        var_os("PENUMBRA_QI").as_deref(),
    );
    if let Some(w) = warning {
        eprintln!("note: {w}");
    }
    config
}
