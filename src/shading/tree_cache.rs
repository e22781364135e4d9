//! The trees of precomputed silhouettes, cached on disk: one file per mesh, box, size limit and
//! format, so that a scene is precomputed once (001 Sect. 7.2.2: "only once per light
//! source"). A mesh whose tree was over the limits is cached too, as such, so that it is not
//! attempted again.
//!
//! The directory is `$PENUMBRA_CACHE_DIR` (`off` disables the cache), else
//! `$XDG_CACHE_HOME/penumbra/trees`, else `~/.cache/penumbra/trees` (`default_dir`, from the
//! values the caller read: [`CacheVars`]). A file is used only if it
//! names the same key and format and its tree is well formed (every index in range); anything
//! else is ignored and rebuilt. Writes go to a temporary file renamed into place. Failing to
//! read or write the cache is never an error: the tree is then built in memory.
//!
//! The cache is bounded: `$PENUMBRA_CACHE_MAX` (bytes, or with a `K`, `M` or `G` suffix;
//! default [`DEFAULT_MAX_BYTES`]). After every write, the least recently used files (by
//! modification time, which a read refreshes) are deleted until the directory is within the
//! bound; a tree larger than the bound is not written at all. Scenes that are generated and
//! thrown away (stress cases) do not use the cache (`PrepareOptions::cache`).

use crate::geometry::{ExactSilhouetteBsp, Polyhedron, SilhouetteBsp, SilhouetteTriangulation};
use glam::DVec3;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// Bump whenever a tree build changes what it produces.
pub(crate) const FORMAT: u32 = 6;

/// The default bound on the cache's size on disk.
pub const DEFAULT_MAX_BYTES: u64 = 256 << 20;

/// Temporary files older than this are debris of a process that died while writing.
const STALE_TMP: Duration = Duration::from_secs(600);

/// What is stored for one mesh.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum CachedTree {
    Convex(SilhouetteBsp),
    Exact(ExactSilhouetteBsp),
    /// Triangulations of the silhouettes of an `Exact` tree (stored under a key of its own).
    Triangulation(SilhouetteTriangulation),
    /// Data a layer above keeps here under a key of its own, as it serializes itself: the
    /// environment's precomputed transfer over a scene's static surfaces (002 Eq. 6,
    /// `environment::prt`). The cache only stores and bounds it
    /// (`TreeCache::load_data`, `TreeCache::store_data`).
    Transfer(serde_json::Value),
    /// The tree would exceed its size budget: it needs more than `tried` cells or leaves
    /// (a later, larger budget tries again).
    OverLimit {
        tried: usize,
    },
}

#[derive(serde::Serialize, serde::Deserialize)]
struct CacheFile {
    format: u32,
    key: u64,
    tree: CachedTree,
}

/// The on-disk cache: where it is and how large it may grow.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TreeCache {
    pub dir: PathBuf,
    pub max_bytes: u64,
}

/// What the cache directory holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheUsage {
    pub files: u64,
    pub bytes: u64,
}

/// What configures the cache, as the caller read it from its environment (`None`: unset). The
/// library reads no environment: the command line, Python and the workbench's launch fill
/// this in.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CacheVars {
    /// `$PENUMBRA_CACHE_DIR`: the directory, or `off`.
    pub cache_dir: Option<OsString>,
    /// `$PENUMBRA_CACHE_MAX`: the bound, as `parse_size` reads it.
    pub cache_max: Option<String>,
    /// `$XDG_CACHE_HOME`.
    pub xdg_cache_home: Option<OsString>,
    /// `$HOME`.
    pub home: Option<OsString>,
}

/// The cache directory `vars` name: `cache_dir` (none when it is `off`), else
/// `xdg_cache_home/penumbra/trees`, else `home/.cache/penumbra/trees`.
pub(crate) fn default_dir(vars: &CacheVars) -> Option<PathBuf> {
    match &vars.cache_dir {
        Some(d) if d == "off" => None,
        Some(d) => Some(PathBuf::from(d)),
        None => vars
            .xdg_cache_home
            .as_ref()
            .map(PathBuf::from)
            .or_else(|| vars.home.as_ref().map(|h| PathBuf::from(h).join(".cache")))
            .map(|d| d.join("penumbra").join("trees")),
    }
}

/// A size such as `1048576`, `512K`, `256M`, `2G` or `1.5G` (powers of 1024), in bytes.
pub(crate) fn parse_size(text: &str) -> crate::Result<u64> {
    let t = text.trim();
    let (num, unit) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&t[..i], t[i..].to_ascii_uppercase()),
        None => (t, String::new()),
    };
    let scale: u64 = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => {
            return Err(crate::Error::from(format!(
                "'{text}' is not a size (e.g. 256M, 2G, 1048576)"
            )));
        }
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a size (e.g. 256M, 2G, 1048576)"))?;
    if !v.is_finite() || v < 0.0 || v * scale as f64 > u64::MAX as f64 {
        return Err(crate::Error::from(format!(
            "'{text}' is not a size (e.g. 256M, 2G, 1048576)"
        )));
    }
    Ok((v * scale as f64) as u64)
}

impl TreeCache {
    /// The cache `vars` configure: `Ok(None)` when it is off or no directory is named, `Err`
    /// when the bound is not a size.
    pub fn configured(vars: &CacheVars) -> crate::Result<Option<TreeCache>> {
        let max_bytes = match &vars.cache_max {
            Some(v) => parse_size(v).map_err(|e| format!("PENUMBRA_CACHE_MAX: {e}"))?,
            None => DEFAULT_MAX_BYTES,
        };
        Ok(default_dir(vars).map(|dir| TreeCache { dir, max_bytes }))
    }

    fn path(&self, key: u64) -> PathBuf {
        self.dir.join(format!("{key:016x}.json"))
    }

    /// The cached tree for `key`, if a valid one is on disk; a hit marks the file as recently
    /// used.
    pub fn load(&self, key: u64, poly: &Polyhedron) -> Option<CachedTree> {
        let (nv, ne) = (poly.vertices.len(), poly.edges.len());
        self.load_checked(key, |tree| match tree {
            CachedTree::Convex(t) => t.is_well_formed(nv),
            CachedTree::Exact(t) => t.is_well_formed(nv, ne),
            CachedTree::Triangulation(t) => t.is_well_formed(nv),
            CachedTree::Transfer(_) => false,
            CachedTree::OverLimit { .. } => true,
        })
    }

    /// The data stored for `key` by [`TreeCache::store_data`], if a file is on disk, reads
    /// as a `T` and `check` accepts it.
    pub(crate) fn load_data<T: serde::de::DeserializeOwned>(
        &self,
        key: u64,
        check: impl Fn(&T) -> bool,
    ) -> Option<T> {
        let mut data = None;
        self.load_checked(key, |t| match t {
            CachedTree::Transfer(v) => {
                data = T::deserialize(v).ok().filter(|d| check(d));
                data.is_some()
            }
            _ => false,
        })?;
        data
    }

    /// Stores `data` for `key` (see [`CachedTree::Transfer`]).
    pub(crate) fn store_data<T: serde::Serialize>(&self, key: u64, data: &T) {
        if let Ok(v) = serde_json::to_value(data) {
            self.store(key, &CachedTree::Transfer(v));
        }
    }

    /// The file for `key` if it names that key and this format and `ok` accepts its content;
    /// a hit marks the file as recently used.
    fn load_checked(
        &self,
        key: u64,
        mut ok: impl FnMut(&CachedTree) -> bool,
    ) -> Option<CachedTree> {
        let path = self.path(key);
        let text = std::fs::read_to_string(&path).ok()?;
        let file: CacheFile = serde_json::from_str(&text).ok()?;
        if file.format != FORMAT || file.key != key || !ok(&file.tree) {
            return None;
        }
        touch(&path);
        Some(file.tree)
    }

    /// Stores `tree` for `key`, then evicts the least recently used files beyond the bound
    /// (errors are ignored: the cache is an optimisation).
    pub(crate) fn store(&self, key: u64, tree: &CachedTree) {
        let file = CacheFile {
            format: FORMAT,
            key,
            tree: tree.clone(),
        };
        let Ok(text) = serde_json::to_string(&file) else {
            return;
        };
        if text.len() as u64 > self.max_bytes || std::fs::create_dir_all(&self.dir).is_err() {
            return;
        }
        let tmp = self
            .dir
            .join(format!("{key:016x}.{}.tmp", std::process::id()));
        if std::fs::write(&tmp, text).is_ok() {
            let _ = std::fs::rename(&tmp, self.path(key));
        }
        let _ = std::fs::remove_file(&tmp);
        self.trim();
    }

    /// The cache's files with their sizes and last use, oldest first; stale temporary files
    /// are deleted on the way.
    fn entries(&self) -> Vec<(SystemTime, u64, PathBuf)> {
        let Ok(dir) = std::fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        let now = SystemTime::now();
        let mut out = Vec::new();
        for e in dir.flatten() {
            let path = e.path();
            let Ok(meta) = e.metadata() else { continue };
            if !meta.is_file() {
                continue;
            }
            let used = meta.modified().unwrap_or(SystemTime::UNIX_EPOCH);
            match path.extension().and_then(|x| x.to_str()) {
                Some("json") if is_cache_name(&path) => out.push((used, meta.len(), path)),
                Some("tmp")
                    if is_cache_name(&path)
                        && now.duration_since(used).unwrap_or_default() > STALE_TMP =>
                {
                    let _ = std::fs::remove_file(&path);
                }
                _ => {}
            }
        }
        out.sort();
        out
    }

    /// Files and bytes in the cache.
    pub fn usage(&self) -> CacheUsage {
        let e = self.entries();
        CacheUsage {
            files: e.len() as u64,
            bytes: e.iter().map(|(_, b, _)| b).sum(),
        }
    }

    /// Deletes the least recently used files until the cache is within its bound; returns
    /// what was deleted.
    pub fn trim(&self) -> CacheUsage {
        let entries = self.entries();
        let mut total: u64 = entries.iter().map(|(_, b, _)| b).sum();
        let mut evicted = CacheUsage::default();
        for (_, bytes, path) in entries {
            if total <= self.max_bytes {
                break;
            }
            if std::fs::remove_file(&path).is_ok() {
                total -= bytes;
                evicted.files += 1;
                evicted.bytes += bytes;
            }
        }
        evicted
    }

    /// Deletes every file of the cache (and only those); returns what was deleted.
    pub fn clear(&self) -> CacheUsage {
        let mut cleared = CacheUsage::default();
        for (_, bytes, path) in self.entries() {
            if std::fs::remove_file(&path).is_ok() {
                cleared.files += 1;
                cleared.bytes += bytes;
            }
        }
        if let Ok(dir) = std::fs::read_dir(&self.dir) {
            for e in dir.flatten() {
                let p = e.path();
                if p.extension().is_some_and(|x| x == "tmp") && is_cache_name(&p) {
                    let _ = std::fs::remove_file(&p);
                }
            }
        }
        cleared
    }
}

/// Whether a file name is one the cache writes (`<16 hex digits>.json` or `<16 hex>.<pid>.tmp`),
/// so that clearing a directory the user pointed the cache at deletes nothing else.
fn is_cache_name(path: &Path) -> bool {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let stem = name.split('.').next().unwrap_or("");
    stem.len() == 16 && stem.bytes().all(|b| b.is_ascii_hexdigit())
}

/// Marks a file as used now (its modification time is the eviction order).
fn touch(path: &Path) {
    if let Ok(f) = std::fs::File::options().write(true).open(path) {
        let _ = f.set_modified(SystemTime::now());
    }
}

/// FNV-1a over everything a tree depends on.
pub(crate) fn tree_key(poly: &Polyhedron, lo: DVec3, hi: DVec3, limit: usize, convex: bool) -> u64 {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units() {
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert_eq!(parse_size("512K"), Ok(512 << 10));
        assert_eq!(parse_size("256M"), Ok(256 << 20));
        assert_eq!(parse_size("256MiB"), Ok(256 << 20));
        assert_eq!(parse_size("2g"), Ok(2 << 30));
        assert_eq!(parse_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_size("0"), Ok(0));
        for bad in ["", "-1M", "12Q", "M", "nan", "1e400"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    /// `PENUMBRA_CACHE_DIR` wins (`off` turns the cache off), then `XDG_CACHE_HOME`, then
    /// `HOME`; a bound that is not a size is an error naming its variable.
    #[test]
    fn the_directory_and_bound_follow_the_values_passed() {
        let vars = |dir: Option<&str>, xdg: Option<&str>, home: Option<&str>| CacheVars {
            cache_dir: dir.map(OsString::from),
            cache_max: None,
            xdg_cache_home: xdg.map(OsString::from),
            home: home.map(OsString::from),
        };
        let dir = |v: &CacheVars| default_dir(v).map(|d| d.to_string_lossy().into_owned());
        assert_eq!(
            dir(&vars(Some("/c"), Some("/x"), Some("/h"))),
            Some("/c".into())
        );
        assert_eq!(dir(&vars(Some("off"), Some("/x"), Some("/h"))), None);
        assert_eq!(
            dir(&vars(None, Some("/x"), Some("/h"))),
            Some("/x/penumbra/trees".into())
        );
        assert_eq!(
            dir(&vars(None, None, Some("/h"))),
            Some("/h/.cache/penumbra/trees".into())
        );
        assert_eq!(dir(&vars(None, None, None)), None);
        let bounded = CacheVars {
            cache_max: Some("4K".into()),
            ..vars(Some("/c"), None, None)
        };
        assert_eq!(
            TreeCache::configured(&bounded)
                .unwrap()
                .map(|c| c.max_bytes),
            Some(4096)
        );
        let bad = CacheVars {
            cache_max: Some("lots".into()),
            ..bounded
        };
        assert!(
            TreeCache::configured(&bad)
                .unwrap_err()
                .to_string()
                .contains("PENUMBRA_CACHE_MAX")
        );
        assert_eq!(
            TreeCache::configured(&vars(Some("off"), None, None)),
            Ok(None)
        );
    }

    #[test]
    fn only_cache_files_are_recognised() {
        assert!(is_cache_name(Path::new("/x/0123456789abcdef.json")));
        assert!(is_cache_name(Path::new("0123456789abcdef.123.tmp")));
        assert!(!is_cache_name(Path::new("notes.json")));
        assert!(!is_cache_name(Path::new("0123456789abcdeg.json")));
    }
}
