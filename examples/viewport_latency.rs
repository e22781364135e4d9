//! Time from a change of view to the first image of the new view on the workbench's render
//! worker, without a window (the render side alone; `penumbra gui --measure` measures it in
//! the real window, painting included).
//!
//!     cargo run --release --example viewport_latency [analytic|ratio-denoised]

use penumbra::app::viewport::RenderWorker;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::scene::scene_file;
use std::sync::Arc;
use std::time::{Duration, Instant};

fn main() {
    let method = match std::env::args().nth(1).as_deref() {
        Some("analytic") => RenderMethod::Analytic,
        _ => RenderMethod::RatioDenoised,
    };
    let scene = scene_file::load_embedded("default").expect("embedded scene");
    let ctx = Arc::new(RenderContext::new(&scene));
    let cam0 = scene.camera.expect("the default scene has a camera");
    let mut worker = RenderWorker::start(|| {});
    // The viewport's size in the 1280×800 window, and the workbench's default spp.
    let settings = RenderSettings {
        width: 474,
        height: 734,
        method,
        spp: 4,
        ..RenderSettings::default()
    };
    let (mut latency, mut render) = (Vec::new(), Vec::new());
    for k in 0..12 {
        let mut cam = cam0;
        cam.eye.x += 0.05 * k as f64;
        let t = Instant::now();
        let g = worker.request(ctx.clone(), cam, settings, 64, None);
        loop {
            if let Some(f) = worker.latest()
                && f.generation == g
            {
                render.push(f.frame.elapsed);
                break;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
        latency.push(t.elapsed().as_secs_f64());
        // Let the render reach full resolution and the denoiser, as after a real drag.
        std::thread::sleep(Duration::from_millis(700));
    }
    let ms = |v: &[f64]| v.iter().map(|t| (t * 1e3).round()).collect::<Vec<_>>();
    println!(
        "{}: first image after a change (ms): {:?}",
        method.name(),
        ms(&latency)
    );
    println!("of which rendering it (ms): {:?}", ms(&render));
    println!("max {:.3} s", latency.iter().copied().fold(0.0, f64::max));
}
