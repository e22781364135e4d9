//! The environment light at a probed pixel: what the probe records is what
//! the renderer computed, checked against independent oracles: a brute-force ray count of the
//! region the exact method integrates, dot-product geometry for `rt`'s culling, and the
//! rendered image itself.

use glam::DVec3;
use penumbra::environment::EnvironmentLight;
use penumbra::inspect::{Probe, probe};
use penumbra::math::{Frame, Pcg32};
use penumbra::render::environment_passes::EnvironmentSettings;
use penumbra::render::{RenderContext, RenderSettings};
use penumbra::scene::environment_spec::EnvMethod;
use penumbra::scene::environment_spec::EnvironmentSpec;
use penumbra::scene::scene_file;
use penumbra::shading::{EnvironmentSide, Method, RayOutcome};
use std::sync::Arc;

/// `name` lit by the band-limited sky (`sky-sh`), rendered with `settings`.
fn context(name: &str, settings: EnvironmentSettings) -> (RenderContext, penumbra::scene::Camera) {
    let mut scene = scene_file::load_embedded(name).unwrap();
    let spec = EnvironmentSpec::new("sky-sh", Some(30.0), Some(1.0), None, None).unwrap();
    scene.environment = Some(spec.clone());
    let cam = scene.camera.unwrap();
    let mut ctx = RenderContext::new(&scene);
    ctx.set_environment(Arc::new(EnvironmentLight::load(&spec).unwrap()), settings);
    (ctx, cam)
}

const SIZE: (u32, u32) = (40, 30);

/// Probes every `step`-th pixel of a SIZE image.
fn probes(ctx: &RenderContext, cam: &penumbra::scene::Camera, step: usize) -> Vec<Probe> {
    let mut out = Vec::new();
    for y in (0..SIZE.1).step_by(step) {
        for x in (0..SIZE.0).step_by(step) {
            out.push(
                probe(
                    ctx,
                    "t",
                    cam,
                    SIZE,
                    (x as f64, y as f64),
                    Method::Analytic,
                    false,
                )
                .unwrap(),
            );
        }
    }
    out
}

/// The probe's radiance is the `--aa 1` render's pixel, bit for bit, for the environment
/// methods whose pixel is not filtered across neighbours (and `rt` with the filter off).
#[test]
fn probed_radiance_is_the_rendered_pixel_with_an_environment() {
    let mut rt = EnvironmentSettings::new(EnvMethod::Rt, 16, 3);
    rt.filter = false;
    for settings in [
        EnvironmentSettings::new(EnvMethod::Analytic, 1, 0),
        rt,
        EnvironmentSettings::new(EnvMethod::Rtao, 8, 5),
        EnvironmentSettings::new(EnvMethod::Reference, 8, 5),
    ] {
        for scene in ["env_figures", "default"] {
            let (ctx, cam) = context(scene, settings);
            let rs = RenderSettings {
                width: SIZE.0,
                height: SIZE.1,
                aa: 1,
                ..RenderSettings::default()
            };
            let img = ctx.render(&cam, &rs, None).unwrap().0;
            let mut surfaces = 0;
            for p in probes(&ctx, &cam, 3) {
                let (x, y) = (p.pixel.0 as u32, p.pixel.1 as u32);
                assert_eq!(
                    p.radiance,
                    img.at(x, y),
                    "{scene} {:?} pixel ({x}, {y})",
                    settings.method
                );
                let e = p.environment.as_ref().expect("the environment is probed");
                assert!(!e.filtered_in_render);
                surfaces += e.sample.is_some() as u32;
            }
            assert!(surfaces > 20, "{scene}: {surfaces} surface pixels");
        }
    }
}

/// Σ of the recorded dynamic terms is the E_occluded the renderer used, and the hemisphere
/// minus Σ of the static terms its E_static (consistency: the same numbers, summed in
/// another grouping).
#[test]
fn recorded_terms_add_up_to_the_probed_irradiances() {
    let (ctx, cam) = context(
        "env_atrium",
        EnvironmentSettings::new(EnvMethod::Analytic, 1, 0),
    );
    let (mut dynamic, mut statics) = (0, 0);
    for p in probes(&ctx, &cam, 2) {
        let Some(s) = p.environment.as_ref().and_then(|e| e.sample) else {
            continue;
        };
        let rec = &p.recording.environment;
        let occ = s.occluded.unwrap();
        let sum_d = rec.sum(EnvironmentSide::Dynamic);
        assert!((sum_d - occ).abs().max_element() <= 1e-12 * occ.abs().max_element().max(1.0));
        let sum_s = rec.sum(EnvironmentSide::Static);
        if rec.terms.iter().any(|t| t.side == EnvironmentSide::Static) {
            let st = s.e_static.unwrap();
            // I_s = I_hemisphere − Σ static, and I_hemisphere = E_unshadowed (Eq. 7).
            assert!(
                (s.unshadowed - sum_s - st).abs().max_element()
                    <= 1e-9 * s.unshadowed.max_element(),
                "{:?} {:?} {:?}",
                s.unshadowed,
                sum_s,
                st
            );
            statics += 1;
        }
        dynamic += (occ.max_element() > 0.0) as u32;
        // The probe's exact integrals are the method's own numbers here.
        let e = p.environment.as_ref().unwrap();
        assert_eq!(e.exact_occluded, Some(occ));
    }
    assert!(dynamic > 3 && statics > 3, "{dynamic} {statics}");
}

/// The oracle: the recorded dynamic terms cover the directions that see a dynamic object and
/// no static one ((∪D) ∖ (∪S), module doc of `shading::environment_occlusion`). Cast stratified cosine
/// rays from the point against the BVH (no polygon clipping at all) and compare
/// π/N Σ L_SH(ω)·[ω in the region] with the Σ of the recorded integrals, within 4.5 standard
/// errors.
#[test]
fn recorded_dynamic_terms_agree_with_a_brute_force_ray_count() {
    let (ctx, cam) = context(
        "env_atrium",
        EnvironmentSettings::new(EnvMethod::Analytic, 1, 0),
    );
    let env = ctx.environment.as_ref().unwrap();
    let (mut checked, mut shadowed) = (0, 0);
    for p in probes(&ctx, &cam, 2) {
        let (Some(sp), Some(s)) = (p.point, p.environment.as_ref().and_then(|e| e.sample)) else {
            continue;
        };
        let recorded = p.recording.environment.sum(EnvironmentSide::Dynamic);
        // Every point in a dynamic object's shadow, and a few outside (the count must be 0).
        if recorded == DVec3::ZERO && checked >= 2 * shadowed + 4 {
            continue;
        }
        let frame = Frame::from_z(sp.normal);
        let extent = 20.0;
        let t_min = 1e-9 * extent;
        let is_static = |o: u32| ctx.scene.objects[o as usize].flags.is_static;
        let own = |o: u32, f: u32| Some(o) == sp.object && Some(f) == sp.face;
        let blocks = |o: u32, f: u32| ctx.scene.objects[o as usize].flags.occluder && !own(o, f);
        let k = 96u32; // k×k strata
        let mut rng = Pcg32::new(11, checked as u64);
        let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
        for i in 0..k {
            for j in 0..k {
                let u = (i as f64 + rng.next_f64()) / k as f64;
                let v = (j as f64 + rng.next_f64()) / k as f64;
                let (r, phi) = (u.sqrt(), std::f64::consts::TAU * v);
                let local = DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u).max(0.0).sqrt());
                let ray = penumbra::accel::Ray {
                    origin: sp.position,
                    dir: frame.to_world(local),
                };
                let sees_dynamic = ctx.bvh.occluded(&ray, t_min, f64::INFINITY, |o, f| {
                    blocks(o, f) && !is_static(o)
                });
                let sees_static = ctx.bvh.occluded(&ray, t_min, f64::INFINITY, |o, f| {
                    blocks(o, f) && is_static(o)
                });
                if sees_dynamic && !sees_static {
                    let x = env.light.sh_radiance(ray.dir) * std::f64::consts::PI;
                    sum += x;
                    sum2 += x * x;
                }
            }
        }
        let n = (k * k) as f64;
        let mean = sum / n;
        let stderr = ((sum2 / n - mean * mean).max(DVec3::ZERO) / (n - 1.0)).map(f64::sqrt);
        let tol = stderr * 4.5 + DVec3::splat(2e-3 * s.unshadowed.max_element());
        assert!(
            (mean - recorded).abs().cmple(tol).all(),
            "pixel {:?}: rays {mean:?} ± {stderr:?}, recorded terms {recorded:?}",
            p.pixel
        );
        checked += 1;
        shadowed += (recorded.max_element() > 1e-3 * s.unshadowed.max_element()) as u32;
        if shadowed >= 12 {
            break;
        }
    }
    assert!(checked >= 6 && shadowed >= 3, "{checked} {shadowed}");
}

/// `rt`'s recorded rays: traced + culled = spp; every culled ray lies outside every merged
/// cone and every traced one inside at least one (checked with the cones' own axis and angle
/// by a dot product); the rays that hit a dynamic object give the recorded E_occluded
/// (002 Eq. 8: π/N Σ L_SH).
#[test]
fn recorded_rays_follow_the_recorded_cones() {
    let spp = 64;
    let mut settings = EnvironmentSettings::new(EnvMethod::Rt, spp, 9);
    settings.filter = false;
    let (ctx, cam) = context("env_figures", settings);
    let env = ctx.environment.as_ref().unwrap();
    let (mut culled_total, mut traced_total) = (0, 0);
    for p in probes(&ctx, &cam, 2) {
        let Some(s) = p.environment.as_ref().and_then(|e| e.sample) else {
            continue;
        };
        let rec = &p.recording.environment;
        assert_eq!(rec.rays.len(), spp as usize);
        let mut e_occ = DVec3::ZERO;
        for r in &rec.rays {
            let inside = rec
                .merged_cones
                .iter()
                .any(|c| r.dir.dot(c.axis) >= c.half_angle.cos() - 1e-12);
            let strictly_inside = rec
                .merged_cones
                .iter()
                .any(|c| r.dir.dot(c.axis) > c.half_angle.cos() + 1e-12);
            match r.outcome {
                RayOutcome::Culled => {
                    assert!(!strictly_inside, "a culled ray inside a cone");
                    culled_total += 1;
                }
                _ => {
                    assert!(inside, "a traced ray outside every cone");
                    traced_total += 1;
                }
            }
            if r.outcome == RayOutcome::Dynamic {
                let world = p.frame_x * r.dir.x + p.frame_y * r.dir.y + p.frame_z * r.dir.z;
                e_occ += env.light.sh_radiance(world);
            }
        }
        e_occ *= std::f64::consts::PI / spp as f64;
        let occ = s.occluded.unwrap();
        assert!((e_occ - occ).abs().max_element() <= 1e-9 * occ.max_element().max(1e-3));
        // Merging (Alg. 1) loses no ray: a ray strictly inside a cone of Eq. 4 is traced.
        for r in &rec.rays {
            if rec
                .cones
                .iter()
                .any(|c| r.dir.dot(c.axis) > c.half_angle.cos() + 1e-12)
            {
                assert_ne!(r.outcome, RayOutcome::Culled, "merging lost a ray");
            }
        }
    }
    assert!(
        culled_total > 100 && traced_total > 100,
        "{culled_total} {traced_total}"
    );
}

/// A dump written before the environment light existed (no `environment` fields) still loads,
/// and a dump with them reads back equal.
#[test]
fn dumps_with_and_without_the_environment_load() {
    let (ctx, cam) = context(
        "env_figures",
        EnvironmentSettings::new(EnvMethod::Analytic, 1, 0),
    );
    let p = probe(&ctx, "t", &cam, SIZE, (20.0, 25.0), Method::Analytic, false).unwrap();
    assert!(p.environment.is_some() && !p.recording.environment.is_empty());
    let text = serde_json::to_string(&p).unwrap();
    let back = Probe::from_json(&text, "new.json").unwrap();
    assert_eq!(back.recording.environment, p.recording.environment);
    assert_eq!(
        back.environment.unwrap().sample,
        p.environment.as_ref().unwrap().sample
    );

    let mut old: serde_json::Value = serde_json::from_str(&text).unwrap();
    old.as_object_mut().unwrap().remove("environment");
    old["recording"]
        .as_object_mut()
        .unwrap()
        .remove("environment");
    let old = Probe::from_json(&old.to_string(), "old.json").unwrap();
    assert!(old.environment.is_none() && old.recording.environment.is_empty());
}

/// Every frame of the progressive render carries the environment's term, at every scale and
/// in every later pass of a stochastic area-light method, composed at once or deferred: on a
/// scene with no area lights the frame's image is exactly the environment's image.
#[test]
fn progressive_frames_keep_the_environment_term() {
    use penumbra::render::RenderMethod;
    use penumbra::render::progressive::render_progressive_with;
    use std::sync::atomic::AtomicBool;
    let (ctx, cam) = context(
        "env_figures",
        EnvironmentSettings::new(EnvMethod::Analytic, 1, 0),
    );
    for (method, defer) in [
        (RenderMethod::Analytic, false),
        (RenderMethod::Ratio, false),
        (RenderMethod::RatioDenoised, true),
    ] {
        let settings = RenderSettings {
            width: 128,
            height: 96,
            method,
            spp: 2,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let mut frames = 0;
        let last = render_progressive_with(&ctx, &cam, &settings, 3, &cancel, defer, |f| {
            let mut f = f.clone();
            f.compose(method);
            let env = f
                .output
                .environment
                .as_ref()
                .expect("the environment's term");
            assert_eq!(
                f.output.image.pixels, env.image.pixels,
                "{method:?} scale {}",
                f.scale
            );
            assert!(env.image.pixels.iter().any(|p| p.max_element() > 0.0));
            frames += 1;
        })
        .unwrap()
        .unwrap();
        assert!(last.finished && frames >= 2, "{method:?}: {frames} frames");
    }
}
