//! The trees of precomputed silhouettes, cached on disk: one file per mesh, box, size limit and
//! format, so that a scene is precomputed once (001 Sect. 7.2.2: "only once per light
//! source"). A mesh whose tree was over the limits is cached too, as such, so that it is not
//! attempted again.
//!
//! The directory is `$PENUMBRA_CACHE_DIR` (`off` disables the cache), else
//! `$XDG_CACHE_HOME/penumbra/trees`, else `~/.cache/penumbra/trees`. A file is used only if it
//! names the same key and format and its tree is well formed (every index in range); anything
//! else is ignored and rebuilt. Writes go to a temporary file renamed into place. Failing to
//! read or write the cache is never an error: the tree is then built in memory.

use crate::geometry::{ExactSilhouetteBsp, Polyhedron, SilhouetteBsp, SilhouetteTriangulation};
use glam::DVec3;
use std::path::PathBuf;

/// Bump whenever a tree build changes what it produces.
pub const FORMAT: u32 = 3;

/// What is stored for one mesh.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum CachedTree {
    Convex(SilhouetteBsp),
    Exact(ExactSilhouetteBsp),
    /// Triangulations of the silhouettes of an `Exact` tree (stored under a key of its own).
    Triangulation(SilhouetteTriangulation),
    /// The tree would exceed its size limit.
    OverLimit,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct CacheFile {
    format: u32,
    key: u64,
    tree: CachedTree,
}

/// The cache directory, if any.
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("PENUMBRA_CACHE_DIR") {
        Some(d) if d == "off" => None,
        Some(d) => Some(PathBuf::from(d)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
            .map(|d| d.join("penumbra").join("trees")),
    }
}

/// FNV-1a over everything a tree depends on.
pub fn tree_key(poly: &Polyhedron, lo: DVec3, hi: DVec3, limit: usize, convex: bool) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    eat(FORMAT as u64);
    eat(convex as u64);
    eat(limit as u64);
    for v in poly.vertices.iter().chain([&lo, &hi]) {
        eat(v.x.to_bits());
        eat(v.y.to_bits());
        eat(v.z.to_bits());
    }
    for &i in poly.face_indices.iter().chain(&poly.face_starts) {
        eat(i as u64);
    }
    h
}

/// The cached tree for `key`, if a valid one is on disk.
pub fn load(key: u64, poly: &Polyhedron) -> Option<CachedTree> {
    let path = cache_dir()?.join(format!("{key:016x}.json"));
    let text = std::fs::read_to_string(path).ok()?;
    let file: CacheFile = serde_json::from_str(&text).ok()?;
    if file.format != FORMAT || file.key != key {
        return None;
    }
    let nv = poly.vertices.len();
    let ok = match &file.tree {
        CachedTree::Convex(t) => t.is_well_formed(nv),
        CachedTree::Exact(t) => t.is_well_formed(nv),
        CachedTree::Triangulation(t) => t.is_well_formed(nv),
        CachedTree::OverLimit => true,
    };
    ok.then_some(file.tree)
}

/// Stores `tree` for `key` (errors are ignored: the cache is an optimisation).
pub fn store(key: u64, tree: &CachedTree) {
    let Some(dir) = cache_dir() else {
        return;
    };
    if std::fs::create_dir_all(&dir).is_err() {
        return;
    }
    let file = CacheFile {
        format: FORMAT,
        key,
        tree: tree.clone(),
    };
    let Ok(text) = serde_json::to_string(&file) else {
        return;
    };
    let tmp = dir.join(format!("{key:016x}.{}.tmp", std::process::id()));
    if std::fs::write(&tmp, text).is_ok() {
        let _ = std::fs::rename(&tmp, dir.join(format!("{key:016x}.json")));
    }
    let _ = std::fs::remove_file(&tmp);
}
