//! Whole shading points and whole images against independent oracles: brute-force ray casting
//! (area-sampled shadow rays through the BVH, `penumbra::reference`) and a second algorithm
//! (the per-triangle path of 000 Sect. 4.4).

use glam::DVec3;
use penumbra::accel::Ray;
use penumbra::math::Pcg32;
use penumbra::reference::{direct_lighting, render_reference};
use penumbra::render::{RenderContext, RenderSettings, compare::compare};
use penumbra::sampling::area_light::LightSampler;
use penumbra::scene::{Scene, scene_file};
use penumbra::shading::{Method, NoRecorder, ShadingPoint, ShadingScratch, shade};

/// Shading points seen from the scene camera through random pixels (receivers only).
fn points(ctx: &RenderContext, n: usize, seed: u64) -> Vec<ShadingPoint> {
    let cam = ctx.scene.camera.expect("embedded scenes have a camera");
    let basis = cam.basis().unwrap();
    let mut rng = Pcg32::new(seed, 0);
    let mut out = Vec::new();
    while out.len() < n {
        let dir = basis.direction(rng.range(0.0, 64.0), rng.range(0.0, 64.0), 64, 64);
        let hit = ctx.primary_hit(&Ray {
            origin: basis.eye,
            dir,
        });
        if let Some(hit) = hit.filter(|h| h.receiver) {
            out.push(hit.point);
        }
    }
    out
}

/// An embedded scene, or `chair-one-mesh`: the chair scene with its six boxes merged into one
/// non-convex mesh (000 Fig. 8's case for the per-triangle method, with shared-free but nearly
/// touching parts).
fn load(name: &str) -> Scene {
    if name != "chair-one-mesh" {
        return scene_file::load_embedded(name).unwrap();
    }
    let mut scene = scene_file::load_embedded("chair").unwrap();
    let parts: Vec<_> = scene
        .objects
        .iter()
        .filter(|o| o.flags.occluder && !o.flags.light)
        .cloned()
        .collect();
    scene.objects.retain(|o| !o.flags.occluder || o.flags.light);
    let mut merged = parts[0].clone();
    merged.name = "chair".into();
    for p in &parts[1..] {
        merged.mesh.append(&p.mesh);
    }
    scene.objects.push(merged);
    scene
}

/// The pipeline's value at a shading point, with the material of the object it lies on.
fn shade_at(
    ctx: &RenderContext,
    sp: &ShadingPoint,
    method: Method,
    scratch: &mut ShadingScratch,
) -> glam::DVec3 {
    let mat = &ctx.prepared.materials[sp.object.unwrap() as usize];
    shade(&ctx.prepared, sp, mat, method, scratch, &mut NoRecorder)
}

fn lambertian(name: &str) -> Scene {
    let scene = load(name);
    assert!(
        scene.objects.iter().all(|o| o.material.ks == DVec3::ZERO),
        "{name} is meant to be Lambertian"
    );
    scene
}

#[test]
fn shading_points_match_brute_force_ray_casting() {
    for name in ["fig4", "chair", "nonconvex", "chair-one-mesh"] {
        let scene = lambertian(name);
        let ctx = RenderContext::new(&scene);
        let lights = LightSampler::new(&scene);
        let mut scratch = ShadingScratch::default();
        let mut rng = Pcg32::new(99, 1);
        let mut worst: f64 = 0.0;
        for sp in points(&ctx, 60, 7) {
            let mat = &ctx.prepared.materials[sp.object.unwrap() as usize];
            let analytic = shade_at(&ctx, &sp, Method::Analytic, &mut scratch);
            let (mc, err) = direct_lighting(&ctx, &lights, &sp, mat, 20_000, &mut rng);
            for k in 0..3 {
                // 4.5σ of the estimate's own standard error: a false alarm over the 180×2
                // channels has probability ~2e-3; a tiny floor absorbs σ = 0 in full shadow.
                let z = (analytic[k] - mc[k]).abs() / (err[k] + 1e-12);
                worst = worst.max(z);
                assert!(
                    (analytic[k] - mc[k]).abs() <= 4.5 * err[k] + 1e-9,
                    "{name}: point {:?}: analytic {} vs ray cast {} ± {}",
                    sp.position,
                    analytic[k],
                    mc[k],
                    err[k]
                );
            }
        }
        eprintln!("{name}: worst |analytic − ray cast| = {worst:.2} σ");
    }
}

/// A set difference whose walk crosses its bound (forced here: every walk is capped at one
/// step where the polygon subtracted has more than five vertices, as the chair's and the
/// sphere's outlines do and their faces do not) leaves the visible polygon as it was, is
/// counted, and its occluder is subtracted face by face: the pixel keeps its exact value.
/// Oracle: the per-triangle path (a second algorithm), which the cap does not reach.
#[test]
fn a_bound_crossed_in_the_set_difference_falls_back_face_by_face() {
    let scene = scene_file::load_embedded("default").unwrap();
    let ctx = RenderContext::new(&scene);
    let mut scratch = ShadingScratch::default();
    let (mut fell_back, mut face_capped) = (0, 0);
    // Most differences are holes now, which take no walk: enough points that the ones left to
    // Greiner–Hormann (a third overlapping occluder, a non-convex outline) cross the cap.
    for sp in points(&ctx, 1200, 5) {
        scratch.limit_set_difference_walks(Some((1, 5)));
        let exact = shade_at(&ctx, &sp, Method::PerTriangle, &mut scratch);
        if scratch.stats.fallbacks.bounds_crossed > 0 {
            face_capped += 1; // a face clipped to more than five vertices: no oracle here
            continue;
        }
        let a = shade_at(&ctx, &sp, Method::Analytic, &mut scratch);
        if scratch.stats.fallbacks.bounds_crossed == 0 {
            continue;
        }
        fell_back += 1;
        let d = (a - exact).abs().max_element() / exact.max_element().max(1e-3);
        assert!(
            d < 1e-7,
            "{:?}: {a} after the fallback, per-triangle {exact}",
            sp.position
        );
    }
    scratch.limit_set_difference_walks(None);
    eprintln!("the fallback ran at {fell_back} of 1200 points ({face_capped} without an oracle)");
    assert!(
        fell_back >= 30 && face_capped < 120,
        "the fallback ran at {fell_back} of 1200 points ({face_capped} without an oracle)"
    );
}

#[test]
fn silhouette_path_equals_per_triangle_path_on_convex_scenes() {
    for name in ["fig4", "chair", "default"] {
        let scene = scene_file::load_embedded(name).unwrap();
        let ctx = RenderContext::new(&scene);
        let mut scratch = ShadingScratch::default();
        let mut worst: f64 = 0.0;
        for sp in points(&ctx, 300, 3) {
            let a = shade_at(&ctx, &sp, Method::Analytic, &mut scratch);
            let b = shade_at(&ctx, &sp, Method::PerTriangle, &mut scratch);
            // Both are exact up to rounding: the visible region is the same set.
            let d = (a - b).abs().max_element() / a.max_element().max(1e-3);
            worst = worst.max(d);
            assert!(
                d < 1e-7,
                "{name}: {:?}: silhouettes {a} vs per-triangle {b}",
                sp.position
            );
        }
        eprintln!("{name}: worst relative difference {worst:.2e}");
    }
}

/// Where two occluders overlap inside the light, the region is held as the light less both
/// holes plus their overlap (inclusion–exclusion): the chair's seat and back, and its legs,
/// overlap so from points of the floor. Those points agree with the per-triangle path (a
/// second algorithm, no holes) as every other point does, and the case is met.
#[test]
fn two_overlapping_holes_equal_the_per_triangle_path() {
    // The chair as it is (Lambertian) and glossy, and `instances` (glossy, lights of many
    // faces): the specular lobe clips each loop of the holes to the horizon after M⁻¹, which
    // the diffuse one does not, and there the holes' overlap does cross it.
    for (name, glossy) in [("chair", false), ("chair", true), ("instances", true)] {
        let mut scene = scene_file::load_embedded(name).unwrap();
        if glossy && name == "chair" {
            for o in &mut scene.objects {
                o.material.ks = DVec3::splat(0.5);
                o.material.alpha = 0.25;
            }
        }
        two_holes_against_per_triangle(&scene, name, glossy);
    }
}

fn two_holes_against_per_triangle(scene: &Scene, name: &str, glossy: bool) {
    use penumbra::shading::{DifferenceMethod, StageRecording};
    let ctx = RenderContext::new(scene);
    let mut scratch = ShadingScratch::default();
    let (mut two, mut worst) = (0, 0.0f64);
    for sp in points(&ctx, 2000, 17) {
        let mat = &ctx.prepared.materials[sp.object.unwrap() as usize];
        let mut rec = StageRecording::new(false);
        let a = shade(
            &ctx.prepared,
            &sp,
            mat,
            Method::Analytic,
            &mut scratch,
            &mut rec,
        );
        let holes = |l: &penumbra::shading::LightRecord| {
            l.set_differences
                .iter()
                .filter(|d| d.method == DifferenceMethod::Hole)
                .count()
        };
        if !rec.lights.iter().any(|l| holes(l) >= 2) {
            continue;
        }
        two += 1;
        let b = shade_at(&ctx, &sp, Method::PerTriangle, &mut scratch);
        let d = (a - b).abs().max_element() / a.max_element().max(1e-3);
        worst = worst.max(d);
        assert!(
            d < 1e-9,
            "{name} (glossy {glossy}), {:?}: two holes {a} vs per-triangle {b}",
            sp.position
        );
    }
    eprintln!(
        "glossy {glossy}: {two} points with two holes, worst relative difference {worst:.2e}"
    );
    assert!(two >= 20, "only {two} of 2000 points took two holes");
}

#[test]
fn embedded_scenes_render_without_invalid_pixels() {
    for name in scene_file::embedded_scene_names() {
        let scene = scene_file::load_embedded(name).unwrap();
        let mut ctx = RenderContext::new(&scene);
        // The environment scenes are lit by their sky alone.
        if let Some(spec) = &scene.environment {
            let light = penumbra::environment::EnvironmentLight::load(spec).unwrap();
            let env = penumbra::render::environment_passes::EnvironmentSettings::new(
                penumbra::scene::environment_spec::EnvMethod::Analytic,
                1,
                1,
            );
            ctx.set_environment(std::sync::Arc::new(light), env);
        }
        for method in [Method::Analytic, Method::PerTriangle, Method::Unshadowed] {
            let settings = RenderSettings {
                width: 48,
                height: 36,
                aa: 2,
                method: method.into(),
                ..Default::default()
            };
            let (img, _) = ctx.render(&scene.camera.unwrap(), &settings, None).unwrap();
            assert_eq!(img.invalid_counts(), (0, 0, 0), "{name} with {method:?}");
            assert!(
                img.pixels.iter().any(|p| p.max_element() > 0.0),
                "{name} is black"
            );
        }
    }
}

#[test]
fn lambertian_render_agrees_with_a_converged_reference() {
    for name in ["fig4", "chair", "nonconvex", "chair-one-mesh"] {
        let scene = lambertian(name);
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let settings = RenderSettings {
            width: 40,
            height: 30,
            aa: 1,
            method: Method::Analytic.into(),
            ..Default::default()
        };
        let (img, _) = ctx.render(&cam, &settings, None).unwrap();
        let (reference, stderr) = render_reference(&ctx, &cam, &settings, 2048, 5).unwrap();
        let c = compare(
            &img.to_rgb32(),
            &reference.to_rgb32(),
            Some(&stderr.to_rgb32()),
        );
        eprintln!("{name}: {c:?}");
        // If the difference is the reference's noise alone, z is ~N(0, 1): over ~3600 channels the
        // RMS of z lies within 1 ± 0.05 and its mean within ±0.07 (4σ each). The variance estimate
        // of pixels with few unoccluded samples is itself noisy, which only widens |z| tails, so
        // the bounds allow 1.2 and 0.1; a bias of a tenth of the noise would already show.
        assert!(c.rms_z.unwrap() < 1.2, "{name}: rms z {:?}", c.rms_z);
        assert!(
            c.mean_z.unwrap().abs() < 0.1,
            "{name}: mean z {:?}",
            c.mean_z
        );
        assert!(
            c.within_3_sigma.unwrap() > 0.98,
            "{name}: {:?}",
            c.within_3_sigma
        );
    }
}

/// Glossy shading (GGX through the LTC) at whole shading points, shadows included, against
/// ray casting. The LTC is an approximation: `tests/ltc_*.rs` measures its fit error against
/// Monte Carlo integration of GGX at ≤ 3 % of the lobe's albedo (`norm`) per unit radiance for
/// view angles up to 60°, so the tolerance here is 3 % · norm · Σ radiance, plus 4.5σ of the
/// estimate. A wrong frame, Fresnel split, orientation or clipping would exceed it by far.
#[test]
fn glossy_shading_points_match_ray_casting_within_the_ltc_fit_error() {
    use penumbra::scene::Material;
    let scene = scene_file::load_embedded("fig4").unwrap();
    let ctx = RenderContext::new(&scene);
    let lights = LightSampler::new(&scene);
    let radiance: f64 = ctx
        .prepared
        .lights
        .iter()
        .map(|(_, l)| l.max_element())
        .sum();
    let mut scratch = ShadingScratch::default();
    let mut rng = Pcg32::new(17, 2);
    for alpha in [0.3, 0.6, 1.0] {
        for view_deg in [0.0f64, 30.0, 50.0] {
            for &(px, pz) in &[(0.0, 0.0), (1.0, 0.5), (-1.0, -0.7), (0.4, -1.2)] {
                let p = DVec3::new(px, 0.0, pz);
                let (s, c) = view_deg.to_radians().sin_cos();
                let sp = ShadingPoint {
                    position: p,
                    normal: DVec3::Y,
                    view: DVec3::new(s, c, 0.0),
                    object: Some(0),
                    face: Some(0),
                };
                let mat = Material {
                    kd: DVec3::ZERO,
                    ks: DVec3::ONE,
                    alpha,
                    ..Material::default()
                };
                let a = shade(
                    &ctx.prepared,
                    &sp,
                    &mat,
                    Method::Analytic,
                    &mut scratch,
                    &mut NoRecorder,
                )
                .x;
                let (m, e) = direct_lighting(&ctx, &lights, &sp, &mat, 100_000, &mut rng);
                let norm = ctx.prepared.ltc.lookup(c, alpha).norm;
                let bound = 0.03 * norm * radiance + 4.5 * e.x;
                assert!(
                    (a - m.x).abs() <= bound,
                    "α {alpha}, θv {view_deg}°, {p}: LTC {a} vs ray cast {} ± {} (bound {bound})",
                    m.x,
                    e.x
                );
            }
        }
    }
}

/// The unshadowed U of a non-convex light (its exact silhouette, from its tree) against the
/// per-triangle method of 000 Sect. 4.4 in the same scene with every other occluder removed: a
/// second algorithm for the same integral (the light still hides itself in both).
#[test]
fn unshadowed_non_convex_lights_equal_per_triangle_without_occluders() {
    let scenes = ["nonconvex", "corner", "extruded_cube", "hole", "bowl"].map(|name| {
        let scene = match name {
            "nonconvex" => scene_file::load_embedded(name).unwrap(),
            _ => penumbra::bench::polyhedra::light_scene(name).unwrap(),
        };
        (name, scene)
    });
    for (name, scene) in scenes {
        let mut alone = scene.clone();
        for o in &mut alone.objects {
            if !(o.flags.light && o.material.is_emissive()) {
                o.flags.occluder = false;
            }
        }
        let ctx = RenderContext::new(&scene);
        let ctx_alone = RenderContext::new(&alone);
        let mut scratch = ShadingScratch::default();
        let mut worst: f64 = 0.0;
        let mut checked = 0;
        for sp in points(&ctx, 200, 11) {
            let a = shade_at(&ctx, &sp, Method::Unshadowed, &mut scratch);
            let b = shade_at(&ctx_alone, &sp, Method::PerTriangle, &mut scratch);
            let d = (a - b).abs().max_element() / a.max_element().max(1e-3);
            worst = worst.max(d);
            checked += 1;
            assert!(
                d < 1e-7,
                "{name}: {:?}: unshadowed {a} vs per-triangle {b}",
                sp.position
            );
        }
        assert!(checked > 100);
        eprintln!("{name}: worst relative difference {worst:.2e}");
    }
}
