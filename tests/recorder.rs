//! The recording is the computation: what the stage recorder captured at a pixel adds up to the
//! value the renderer produced there, and recording does not change that value.

use penumbra::ltc::form_factor;
use penumbra::render::{RenderContext, RenderSettings, subpixel_rays};
use penumbra::scene::scene_file;
use penumbra::shading::{Lobe, Method, NoRecorder, ShadingScratch, Stage, StageRecording};

#[test]
fn recorded_stages_reproduce_the_rendered_pixels() {
    let scene = scene_file::load_embedded("default").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let basis = cam.basis().unwrap();
    let settings = RenderSettings {
        width: 24,
        height: 18,
        aa: 1,
        method: Method::Analytic.into(),
        ..Default::default()
    };
    let (img, _) = ctx.render(&cam, &settings, None).unwrap();
    let mut scratch = ShadingScratch::default();
    let mut checked = 0;
    for y in 0..settings.height {
        for x in 0..settings.width {
            let ray = subpixel_rays(&basis, x, y, 1, settings.width, settings.height)
                .next()
                .unwrap();
            let mut rec = StageRecording::new(true);
            let recorded = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut rec);
            let plain = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut NoRecorder);
            // Bit for bit: the recorder only observes.
            assert_eq!(recorded, plain);
            assert_eq!(plain, img.at(x, y));
            let Some(hit) = ctx.primary_hit(&ray) else {
                continue;
            };
            let sum = rec
                .lights
                .iter()
                .map(|l| l.diffuse + l.specular)
                .sum::<glam::DVec3>()
                + hit.emitted;
            assert!((sum - plain).abs().max_element() <= 1e-12 * plain.max_element().max(1.0));
            for l in &rec.lights {
                // The diffuse integral recorded is the form factor of the recorded visible polygon.
                if let Some((_, visible)) = l.polygons.iter().find(|(s, _)| *s == Stage::Visible) {
                    let (_, _, _, e) = l
                        .lobes
                        .iter()
                        .find(|(lobe, ..)| *lobe == Lobe::Diffuse)
                        .unwrap();
                    assert!((form_factor(visible.loops()).max(0.0) - e).abs() < 1e-15);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 50);
}
