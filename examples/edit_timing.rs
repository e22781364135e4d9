//! What one frame of dragging an object in the workbench costs on the render side: the scene
//! copy with the object moved (`EditHistory::moved_scene`), the cheap re-prepare
//! (`RenderContext::with_moved_object`), the picked pixel's recording after it (`inspect::
//! probe_corrected`, as the workbench's pick, Greiner–Hormann steps included) and the first
//! progressive image of the default viewport (474×734 in the 1280×800 window, analytic, the
//! workbench's defaults; `render_progressive_with` as its render worker calls it), against
//! preparing the moved scene from scratch. Medians over a drag of several frames.
//!
//!     cargo run --release --example edit_timing
//!
//! Scenes: `default` (its chair back, a convex occluder with a BSP tree, and its tube light)
//! and `assets/scenes/bunny.toml` (the scanned bunny, 3,674 triangles), when present.

use glam::DVec3;
use penumbra::inspect::probe_corrected;
use penumbra::render::progressive::render_progressive_with;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::scene::edit::{EditHistory, Rigid, resolve_object};
use penumbra::scene::{Scene, scene_file};
use penumbra::shading::Method;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

const FRAMES: usize = 9;
const VIEWPORT: (u32, u32) = (474, 734);

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn ms(s: f64) -> String {
    format!("{:.2} ms", s * 1e3)
}

fn run(label: &str, scene: Scene, object: &str) {
    let camera = scene.camera.expect("the scene has a camera");
    let base = Arc::new(scene);
    let index = resolve_object(&base, object).expect("the object exists");
    let t = Instant::now();
    let mut ctx = RenderContext::from_arc(base.clone());
    let first_prepare = t.elapsed().as_secs_f64();
    let mut history = EditHistory::new(&base);
    let pivot = history.begin_drag(index).expect("in range");
    let settings = RenderSettings {
        width: VIEWPORT.0,
        height: VIEWPORT.1,
        method: RenderMethod::Analytic,
        spp: 4,
        ..RenderSettings::default()
    };
    let pick = (VIEWPORT.0 as f64 / 2.0, VIEWPORT.1 as f64 * 0.6);
    let (mut copy, mut moved, mut probe, mut first_image, mut scratch) =
        (vec![], vec![], vec![], vec![], vec![]);
    for k in 1..=FRAMES {
        let f = k as f64 / FRAMES as f64;
        let motion = Rigid::rotation_about(pivot, DVec3::Y, 0.5 * f)
            .expect("finite")
            .then(Rigid::translation(DVec3::new(0.1 * f, 0.0, -0.05 * f)));
        history.update_drag(motion).expect("dragging");

        let t = Instant::now();
        let scene = Arc::new(history.moved_scene(&base, index).expect("in range"));
        copy.push(t.elapsed().as_secs_f64());

        let t = Instant::now();
        ctx = ctx
            .with_moved_object(index, scene.clone())
            .expect("re-prepared");
        moved.push(t.elapsed().as_secs_f64());

        let t = Instant::now();
        let p = probe_corrected(
            &ctx,
            label,
            &camera,
            VIEWPORT,
            pick,
            Method::Analytic,
            None,
            true,
        )
        .expect("probed");
        probe.push(t.elapsed().as_secs_f64());
        std::hint::black_box(p);

        let cancel = AtomicBool::new(false);
        let t = Instant::now();
        let mut first = None;
        render_progressive_with(&ctx, &camera, &settings, 64, &cancel, false, |_| {
            if first.is_none() {
                first = Some(t.elapsed().as_secs_f64());
                cancel.store(true, Ordering::Relaxed);
            }
        })
        .expect("rendered");
        first_image.push(first.expect("one frame"));

        let t = Instant::now();
        std::hint::black_box(RenderContext::from_arc(scene));
        scratch.push(t.elapsed().as_secs_f64());
    }
    history.end_drag();
    println!(
        "{label}: move '{object}' ({} frames of a drag; first prepare {}, BVH refits {})",
        FRAMES,
        ms(first_prepare),
        ctx.bvh.refits()
    );
    println!("  scene copy with the object moved : {}", ms(median(copy)));
    println!("  with_moved_object                : {}", ms(median(moved)));
    println!("  picked pixel's recording (probe) : {}", ms(median(probe)));
    println!(
        "  first progressive image {}x{}  : {}",
        VIEWPORT.0,
        VIEWPORT.1,
        ms(median(first_image))
    );
    println!(
        "  prepare from scratch instead     : {}",
        ms(median(scratch))
    );
}

fn main() {
    let default = scene_file::load_embedded("default").expect("embedded");
    run("default", default.clone(), "back");
    run("default", default, "tube_light");
    let bunny = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/bunny.toml");
    match scene_file::load_scene(&bunny) {
        Ok(scene) => {
            run("bunny", scene.clone(), "bunny");
            run("bunny", scene, "light");
        }
        Err(e) => println!("bunny skipped: {e}"),
    }
}
