//! A point on a large closed light, lit by the rest of it: the analytic method cuts the
//! point's sky into windows (`shading::analytic::sky_windows`); the per-triangle method takes
//! the light's faces one by one, each less the faces in front of it. Two exact constructions
//! of the same region: at every camera sample on Blender's torus light they agree to 1e-9
//! relative, the shadowed and the unshadowed method alike.

use penumbra::render::request::RenderRequest;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings, subpixel_rays};
use penumbra::scene::scene_file::load_scene;
use penumbra::shading::{Method, NoRecorder, ShadingScratch};
use std::path::Path;

#[test]
fn the_sky_windows_light_a_point_on_the_torus_as_its_faces_do() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender/torus_light.toml");
    let scene = load_scene(&path).unwrap();
    let camera = scene.camera.expect("a camera");
    let (w, h, aa) = (48, 36, 2);
    let settings = RenderSettings {
        width: w,
        height: h,
        aa,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let ctx = RenderContext::for_render(&scene, &RenderRequest::with_settings(settings));
    let torus = scene
        .objects
        .iter()
        .position(|o| o.name == "TorusLight")
        .unwrap() as u32;
    let basis = camera.basis().unwrap();
    let mut scratch = ShadingScratch::default();
    let (mut on_torus, mut worst) = (0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            for ray in subpixel_rays(&basis, x, y, aa, w, h) {
                let Some(hit) = ctx.primary_hit(&ray) else {
                    continue;
                };
                if hit.point.object != Some(torus) {
                    continue;
                }
                on_torus += 1;
                for (windows, faces) in [
                    (Method::Analytic, Method::PerTriangle),
                    (Method::Unshadowed, Method::PerTriangle),
                ] {
                    let a = ctx.radiance_at(&hit, windows, &mut scratch, &mut NoRecorder);
                    let b = ctx.radiance_at(&hit, faces, &mut scratch, &mut NoRecorder);
                    // What the light sends the point (its own emission is the same in both).
                    let (a, b) = (a - hit.emitted, b - hit.emitted);
                    let rel = (a - b).abs().max_element() / b.abs().max_element().max(1e-300);
                    assert!(
                        rel <= 1e-9,
                        "pixel ({x}, {y}), {windows:?}: {a} against {b} face by face"
                    );
                    worst = worst.max(rel);
                }
            }
        }
    }
    assert!(on_torus >= 20, "only {on_torus} samples on the torus");
    eprintln!("{on_torus} samples on the torus, worst relative difference {worst:.1e}");
}
