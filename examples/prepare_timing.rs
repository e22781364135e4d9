//! Time to prepare each embedded scene (BVH, shading data and the trees of precomputed
//! silhouettes), and the chair merged into one non-convex mesh.
//!
//!     cargo run --release --example prepare_timing
use penumbra::render::RenderContext;
use penumbra::scene::scene_file;
use std::time::Instant;

fn main() {
    let mut scenes: Vec<(String, penumbra::scene::Scene)> = scene_file::embedded_scene_names()
        .iter()
        .map(|n| {
            (
                n.to_string(),
                scene_file::load_embedded(n).expect("embedded"),
            )
        })
        .collect();
    let mut chair = scene_file::load_embedded("chair").expect("embedded");
    let parts: Vec<_> = chair
        .objects
        .iter()
        .filter(|o| o.flags.occluder && !o.flags.light)
        .cloned()
        .collect();
    chair.objects.retain(|o| !o.flags.occluder || o.flags.light);
    let mut merged = parts[0].clone();
    for p in &parts[1..] {
        merged.mesh.append(&p.mesh);
    }
    chair.objects.push(merged);
    scenes.push(("chair-one-mesh".into(), chair));
    for (name, scene) in &scenes {
        let t = Instant::now();
        let ctx = RenderContext::new(scene);
        let trees = ctx
            .prepared
            .objects
            .iter()
            .filter(|o| o.path.tree().is_some())
            .count();
        println!(
            "{name}: {:.3} s, {trees} of {} meshes with a tree",
            t.elapsed().as_secs_f64(),
            ctx.prepared.objects.len()
        );
    }
}
