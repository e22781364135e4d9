//! The disk cache of silhouette trees: a second preparation reads what the first stored and
//! renders the same image bit for bit (trees and triangulations); a damaged file (bad JSON, or an index out of range) is
//! ignored and the tree rebuilt, never trusted; without one (the default) nothing is written.

use penumbra::render::{RenderContext, RenderSettings};
use penumbra::scene::scene_file;
use penumbra::shading::PrepareConfig;
use penumbra::shading::tree_cache::TreeCache;
use std::sync::Arc;

fn render(ctx: &RenderContext) -> Vec<glam::DVec3> {
    let cam = ctx.scene.camera.unwrap();
    let settings = RenderSettings {
        width: 48,
        height: 36,
        ..RenderSettings::default()
    };
    ctx.render(&cam, &settings, None).unwrap().0.pixels
}

fn trees(ctx: &RenderContext) -> usize {
    ctx.prepared
        .objects
        .iter()
        .filter(|o| o.path.tree().is_some())
        .count()
}

fn triangulations(ctx: &RenderContext) -> usize {
    ctx.prepared
        .objects
        .iter()
        .filter(|o| o.triangulation.is_some())
        .count()
}

#[test]
fn trees_round_trip_through_the_cache_and_damaged_files_are_rebuilt() {
    let dir = std::env::temp_dir().join(format!("penumbra-tree-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let config = PrepareConfig {
        tree_cache: Some(TreeCache {
            dir: dir.clone(),
            max_bytes: penumbra::shading::tree_cache::DEFAULT_MAX_BYTES,
        }),
        ..PrepareConfig::default()
    };
    let scene = Arc::new(scene_file::load_embedded("nonconvex").unwrap());
    let prepare = || RenderContext::configured(scene.clone(), &config);
    let built = prepare();
    let files: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
    // Two trees, and the triangulations of the light that is not star-shaped.
    assert_eq!(
        files.len(),
        3,
        "one file per tree and per set of triangulations"
    );
    let read = prepare();
    assert_eq!(trees(&read), 2);
    assert_eq!(triangulations(&read), 1);
    assert_eq!(render(&built), render(&read));

    // Damage: one file truncated, the other with an index far out of range.
    let paths: Vec<_> = files.iter().map(|f| f.path()).collect();
    let text = std::fs::read_to_string(&paths[0]).unwrap();
    std::fs::write(&paths[0], &text[..text.len() / 2]).unwrap();
    let text = std::fs::read_to_string(&paths[1]).unwrap();
    let damaged = text.replacen("\"back\":", "\"back\":99999999,\"x\":", 1);
    assert_ne!(damaged, text);
    std::fs::write(&paths[1], damaged).unwrap();
    let rebuilt = prepare();
    assert_eq!(trees(&rebuilt), 2);
    assert_eq!(triangulations(&rebuilt), 1);
    assert_eq!(render(&built), render(&rebuilt));

    // Without a cache (the library's default) nothing is read or written.
    std::fs::remove_dir_all(&dir).unwrap();
    let uncached = RenderContext::configured(scene.clone(), &PrepareConfig::default());
    assert!(uncached.prepared.trees_built > 0);
    assert!(!dir.exists());
}
