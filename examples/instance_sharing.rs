//! Precomputation time and tree bytes of the `instances` scene with instances sharing one
//! silhouette tree and with sharing disabled (docs/silhouettes.md), the disk cache off so that
//! every tree is built.
//!
//!     cargo run --release --example instance_sharing
use penumbra::scene::scene_file;
use penumbra::shading::PreparedScene;
use std::collections::HashSet;
use std::time::Instant;

fn main() {
    // SAFETY: set before any thread starts; nothing else reads the environment yet.
    unsafe { std::env::set_var("PENUMBRA_CACHE_DIR", "off") };
    let scene = scene_file::load_embedded("instances").expect("embedded");
    for share in [true, false] {
        let t = Instant::now();
        let p = PreparedScene::prepare(
            &scene,
            penumbra::shading::PrepareOptions {
                share_instances: share,
                ..penumbra::shading::PrepareOptions::default()
            },
        );
        let seconds = t.elapsed().as_secs_f64();
        // Distinct trees, by address: shared ones counted once.
        let mut seen = HashSet::new();
        let (mut trees, mut bytes) = (0, 0);
        for o in &p.objects {
            if let Some(t) = o.convex_tree()
                && seen.insert(std::sync::Arc::as_ptr(t) as usize)
            {
                trees += 1;
                bytes += t.stored_bytes();
            }
            if let Some(t) = o.exact_tree()
                && seen.insert(std::sync::Arc::as_ptr(t) as usize)
            {
                trees += 1;
                bytes += t.stored_bytes();
            }
        }
        println!(
            "sharing {}: {seconds:.3} s to prepare, {trees} trees for {} meshes, {bytes} bytes",
            if share { "on " } else { "off" },
            p.objects.len()
        );
    }
}
