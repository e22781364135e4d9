//! `penumbra cache`: where the tree cache is, what it holds; trimming and clearing it.

use anyhow::{Context, Result};
use std::path::Path;

/// `penumbra cache`: the tree cache's place, contents and bound; `--trim`, `--clear`.
pub fn cache(clear: bool, trim: bool, json: Option<&Path>) -> Result<()> {
    use penumbra::shading::tree_cache::{CacheUsage, TreeCache};
    let Some(cache) =
        TreeCache::configured(&super::process_env::cache_vars()).map_err(anyhow::Error::msg)?
    else {
        say!("the tree cache is disabled (PENUMBRA_CACHE_DIR=off, or no home directory)");
        return Ok(());
    };
    let removed = if clear {
        Some(cache.clear())
    } else if trim {
        Some(cache.trim())
    } else {
        None
    };
    let usage = cache.usage();
    let mb = |b: u64| b as f64 / (1u64 << 20) as f64;
    say!("tree cache: {}", cache.dir.display());
    if let Some(CacheUsage { files, bytes }) = removed {
        say!("deleted {files} files, {:.1} MiB", mb(bytes));
    }
    say!(
        "{} files, {:.1} MiB of at most {:.1} MiB (PENUMBRA_CACHE_MAX)",
        usage.files,
        mb(usage.bytes),
        mb(cache.max_bytes)
    );
    if let Some(path) = json {
        let report = serde_json::json!({
            "dir": cache.dir,
            "files": usage.files,
            "bytes": usage.bytes,
            "max_bytes": cache.max_bytes,
            "deleted": removed,
        });
        std::fs::write(path, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("{}", path.display()))?;
    }
    Ok(())
}
