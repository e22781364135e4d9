//! One code path: the benchmark times what `penumbra render` runs. A scene is
//! prepared the same way by both (`BenchConfig::prepare` is `RenderContext::for_render` for
//! the config's image), so on every embedded scene both prepare every mesh alike and the bench's analytic image equals
//! the render's bit for bit.

use penumbra::bench::runner::{self, BenchConfig};
use penumbra::render::request::RenderRequest;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::scene::scene_file::{self, load_embedded};
use penumbra::stochastic::LightSampling;

#[test]
fn the_bench_renders_the_analytic_image_that_render_renders() {
    // Every embedded scene, as `penumbra scenes` lists them.
    for &name in scene_file::embedded_scene_names() {
        let scene = load_embedded(name).unwrap();
        let camera = scene.camera.expect("embedded scenes have a camera");
        let (w, h, aa) = (40, 30, 2);
        let mut config = BenchConfig::new(name, camera, w, h);
        config.aa = aa;
        config.methods = vec![RenderMethod::Analytic];
        config.ladder = vec![1];
        config.reference_spp = 1;
        config.repeats = 1;
        config.area_baseline = false;
        config.exact_u_variants = false;
        let ctx = config.prepare(&scene);
        let reference = runner::render_reference(&ctx, &config, None).unwrap();
        let (_, images) = runner::run_bench(&ctx, &config, &reference, None, |_, _, _| {}).unwrap();
        let bench = images
            .iter()
            .find(|i| i.method == RenderMethod::Analytic)
            .expect("the analytic image");

        // What `penumbra render NAME --size 40x30 --aa 2` does.
        let settings = RenderSettings {
            width: w,
            height: h,
            aa,
            method: RenderMethod::Analytic,
            spp: 1,
            seed: config.seed,
            light_sampling: LightSampling::SolidAngle,
            collect_stats: false,
            exact_u: false,
        };
        let render_ctx = RenderContext::for_render(&scene, &RenderRequest::with_settings(settings));
        // The same preparation: every mesh takes the same path and the same trees (the notes
        // say which). `RenderContext::new`, which the bench used before, sizes the trees for
        // 256×256×16 rays and differs here on default, fig4 and polyhedra.
        assert_eq!(render_ctx.prepared.report, ctx.prepared.report, "{name}");
        let render = render_ctx.render_full(&camera, &settings, None).unwrap();
        let bits = |img: &penumbra::raster::Image| -> Vec<[u64; 3]> {
            img.pixels
                .iter()
                .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect()
        };
        assert_eq!(bits(&bench.image), bits(&render.image), "{name}");
    }
}
