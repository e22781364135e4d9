//! The image's derivative along a rigid motion (`render::derivative`) against its oracle:
//! central finite differences of the analytic renderer itself, which is exact, so that a small
//! step gives a sharp reference (docs/derivatives.md, "Verified").

use penumbra::Choice;
use penumbra::render::request::RenderRequest;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::shading::derivative::{Axis, FD_STEP};

/// How the derivative of one object along one axis compares with central differences.
#[derive(Debug)]
pub struct FdReport {
    pub unmasked: usize,
    pub masked: u64,
    /// Unmasked pixels where |d − d_FD| > 1e-6 · max(|d_FD|, max |d|) at the step h and at
    /// h/10 both.
    pub disagree: usize,
    /// Unmasked pixels that disagree at h and agree at h/10: the visible region changes its
    /// topology within ±h of θ = 0 (a vertex crossing an edge), so the difference straddles a
    /// kink, and a smaller step leaves it outside.
    pub topology: usize,
    /// The largest relative error at h over unmasked pixels, the differences' rounding
    /// included.
    pub worst: f64,
    pub max_rate: f64,
}

/// The pixels (indices) where `d` and the central difference of `ctx` at `step` disagree.
fn disagreeing(
    ctx: &RenderContext,
    motion: &penumbra::shading::derivative::Motion,
    camera: &penumbra::scene::Camera,
    settings: &RenderSettings,
    out: &penumbra::render::derivative::DerivativeOutput,
    step: f64,
    pixels: &[usize],
) -> (Vec<usize>, f64, f64) {
    let image = |theta: f64| {
        ctx.moved_by(motion, theta)
            .unwrap()
            .render(camera, settings, None)
            .unwrap()
            .0
    };
    let (plus, minus) = (image(step), image(-step));
    let max_rate = (0..out.mask.pixels.len())
        .filter(|&i| out.mask.pixels[i].x == 0.0)
        .map(|i| out.derivative.pixels[i].abs().max_element())
        .fold(0.0, f64::max);
    // The differences' own rounding: each image carries a few ulps of its largest value,
    // divided by 2h (with h = 1e-6 that is about 1e-8 of the image's largest value).
    let max_value = out
        .image
        .pixels
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    let noise = 32.0 * f64::EPSILON * max_value / step;
    let mut worst = 0.0f64;
    let mut bad = Vec::new();
    for &i in pixels {
        let f = (plus.pixels[i] - minus.pixels[i]) / (2.0 * step);
        let d = out.derivative.pixels[i];
        let raw = (d - f).abs().max_element();
        let err = (raw - noise).max(0.0);
        let scale = f.abs().max_element().max(max_rate).max(1e-300);
        worst = worst.max(raw / scale);
        if err > 1e-6 * scale {
            bad.push(i);
            if std::env::var_os("FD_DEBUG").is_some() {
                let w = settings.width as usize;
                eprintln!("pixel {} {}: d {d} fd {f} (h {step})", i % w, i / w);
            }
        }
    }
    (bad, worst, max_rate)
}

/// `render_derivative` of `object` (index or name) along `axis` in the embedded scene
/// `scene_name`, against central differences of the analytic renderer (the oracle).
pub fn fd_check(scene_name: &str, object: &str, axis: Axis, w: u32, h: u32, aa: u32) -> FdReport {
    let mut scene = penumbra::scene::scene_file::load_scene_by_name(scene_name).unwrap();
    let camera = scene.camera.unwrap();
    let settings = RenderSettings {
        width: w,
        height: h,
        aa,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let request = RenderRequest::with_settings(settings);
    // Prepared as `penumbra render` prepares it: with its environment, if it has one.
    let ctx = request.prepare(&mut scene).unwrap().ctx;
    let index = penumbra::scene::edit::resolve_object(&scene, object).unwrap();
    let motion = ctx.motion(index, axis).unwrap();
    let out = ctx
        .render_derivative(&camera, &settings, &motion, None)
        .unwrap();
    let step = std::env::var("FD_H")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(FD_STEP);
    let unmasked: Vec<usize> = (0..out.mask.pixels.len())
        .filter(|&i| out.mask.pixels[i].x == 0.0)
        .collect();
    let (bad, worst, max_rate) =
        disagreeing(&ctx, &motion, &camera, &settings, &out, step, &unmasked);
    let still = if bad.is_empty() {
        bad.clone()
    } else {
        disagreeing(&ctx, &motion, &camera, &settings, &out, step / 10.0, &bad).0
    };
    FdReport {
        unmasked: unmasked.len(),
        masked: out.masked.pixels,
        disagree: still.len(),
        topology: bad.len() - still.len(),
        worst,
        max_rate,
    }
}

#[test]
#[ignore = "a survey: prints every embedded scene, object and axis"]
fn survey() {
    for name in penumbra::scene::scene_file::embedded_scene_names() {
        let scene = penumbra::scene::scene_file::load_scene_by_name(name).unwrap();
        if scene.camera.is_none() {
            continue;
        }
        for (i, o) in scene.objects.iter().enumerate() {
            for axis in Axis::ALL {
                let r = fd_check(name, &i.to_string(), axis, 48, 36, 2);
                println!("{name} {} {}: {r:?}", o.name, axis.name());
            }
        }
    }
}

#[test]
#[ignore = "debugging: FD_SCENE, FD_OBJECT, FD_AXIS"]
fn one() {
    let var = |k: &str| std::env::var(k).unwrap();
    let axis = Axis::named(&var("FD_AXIS")).unwrap();
    let r = fd_check(&var("FD_SCENE"), &var("FD_OBJECT"), axis, 48, 36, 2);
    println!("{r:?}");
}

/// Oracle: central differences of the analytic renderer. The two derivatives the issue names,
/// at a size where the penumbrae span many pixels.
#[test]
fn default_sphere_tx_and_panel_light_ty_match_central_differences() {
    for (object, axis) in [("sphere", Axis::Tx), ("panel_light", Axis::Ty)] {
        let r = fd_check("default", object, axis, 96, 72, 2);
        println!("default {object}:{}: {r:?}", axis.name());
        assert!(r.max_rate > 0.1, "{r:?}");
        assert_eq!(r.disagree, 0, "{r:?}");
        assert!(r.topology * 1000 <= r.unmasked, "{r:?}");
    }
}

/// Oracle: central differences of the analytic renderer, for every object of every embedded
/// scene (the environment's term included, `--env-method analytic`), along every axis: the
/// pixels that disagree at the step must agree at a tenth of it (a topology change within the
/// step), and be rare (under 0.1 % of the unmasked pixels in all).
#[test]
fn every_embedded_object_and_axis_matches_central_differences() {
    let (mut cases, mut moving, mut topology, mut pixels, mut masked) = (0, 0, 0, 0, 0);
    let mut worst = Vec::new();
    for name in penumbra::scene::scene_file::embedded_scene_names() {
        let scene = penumbra::scene::scene_file::load_scene_by_name(name).unwrap();
        if scene.camera.is_none() {
            continue;
        }
        for i in 0..scene.objects.len() {
            for axis in Axis::ALL {
                let r = fd_check(name, &i.to_string(), axis, 32, 24, 2);
                assert_eq!(r.disagree, 0, "{name} object {i} {}: {r:?}", axis.name());
                cases += 1;
                moving += (r.max_rate > 0.0) as usize;
                topology += r.topology;
                pixels += r.unmasked;
                masked += r.masked;
                worst.push(r.worst);
            }
        }
    }
    worst.sort_by(f64::total_cmp);
    println!(
        "{cases} cases ({moving} with a derivative), {pixels} unmasked and {masked} masked \
         pixels, {topology} at a topology change within the step; worst relative error at the \
         step per case: median {:.1e}, largest {:.1e}",
        worst[worst.len() / 2],
        worst[worst.len() - 1]
    );
    assert!(cases > 200 && moving > 150, "{cases} {moving}");
    assert!(topology * 1000 <= pixels, "{topology} of {pixels}");
}

/// Oracle: central differences of the ray-cast reference (an independent renderer: light
/// sampling and rays, no polygons) at a coarse step, with common random numbers (one seed for
/// both sides). Noise allows no per-pixel bound; the check is of sign and size over the image:
/// the least-squares slope of the reference's differences against the exact derivative, and
/// their correlation, over the pixels whose camera ray stays on its face within the step (the
/// secant of a sharp penumbra is a little flatter than its tangent: slope 0.93 for the sphere).
#[test]
fn the_reference_renderer_agrees_in_sign_and_size() {
    let scene = penumbra::scene::scene_file::load_scene_by_name("default").unwrap();
    let camera = scene.camera.unwrap();
    let settings = RenderSettings {
        width: 48,
        height: 36,
        aa: 1,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let ctx = RenderContext::for_render(&scene, &RenderRequest::with_settings(settings));
    for (object, axis) in [("sphere", Axis::Tx), ("panel_light", Axis::Ty)] {
        let index = penumbra::scene::edit::resolve_object(&scene, object).unwrap();
        let motion = ctx.motion(index, axis).unwrap();
        let out = ctx
            .render_derivative(&camera, &settings, &motion, None)
            .unwrap();
        let step = 0.01;
        let reference = |theta: f64| {
            let moved = ctx.moved_by(&motion, theta).unwrap();
            penumbra::reference::render_reference(&moved, &camera, &settings, 2048, 7)
                .unwrap()
                .0
        };
        let (plus, minus) = (reference(step), reference(-step));
        // Pixels whose camera ray meets another face within the coarse step are steps, not
        // slopes, at that step: left out (the exact derivative's own mask is for its step).
        let basis = camera.basis().unwrap();
        let (c_plus, c_minus) = (
            ctx.moved_by(&motion, step).unwrap(),
            ctx.moved_by(&motion, -step).unwrap(),
        );
        let (mut dd, mut dr, mut rr) = (0.0, 0.0, 0.0);
        for i in 0..out.derivative.pixels.len() {
            let (x, y) = (i as u32 % settings.width, i as u32 / settings.width);
            let ray =
                penumbra::render::subpixel_rays(&basis, x, y, 1, settings.width, settings.height)
                    .next()
                    .unwrap();
            let face =
                |c: &RenderContext| c.primary_hit(&ray).map(|h| (h.point.object, h.point.face));
            let here = face(&ctx);
            if out.mask.pixels[i].x != 0.0 || face(&c_plus) != here || face(&c_minus) != here {
                continue;
            }
            let d = out.derivative.pixels[i].x;
            let r = (plus.pixels[i].x - minus.pixels[i].x) / (2.0 * step);
            dd += d * d;
            dr += d * r;
            rr += r * r;
        }
        let slope = dr / dd;
        let correlation = dr / (dd * rr).sqrt();
        println!(
            "{object}:{}: slope {slope:.3}, correlation {correlation:.3}",
            axis.name()
        );
        assert!((slope - 1.0).abs() < 0.1, "{object}: slope {slope}");
        assert!(correlation > 0.9, "{object}: correlation {correlation}");
    }
}
