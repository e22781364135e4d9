//! The stochastic estimators (003 Sect. 3) against independent oracles: the analytic result on
//! Lambertian scenes (exact there), ray casting for what the light sampler covers, and the
//! estimators' own measured variance for the rate of convergence.

use glam::DVec3;
use penumbra::accel::Ray;
use penumbra::math::{Frame, Pcg32};
use penumbra::render::stochastic::StochasticBuffers;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::scene::{Scene, scene_file};
use penumbra::stochastic::{Estimator, LightSampling, LightSet, combine};

fn settings(method: RenderMethod, w: u32, h: u32, spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: w,
        height: h,
        aa: 1,
        method,
        spp,
        seed,
        light_sampling: LightSampling::SolidAngle,
        collect_stats: false,
        exact_u: false,
    }
}

fn buffers(ctx: &RenderContext, s: &RenderSettings) -> StochasticBuffers {
    let cam = ctx.scene.camera.unwrap();
    std::sync::Arc::unwrap_or_clone(ctx.render_full(&cam, s, None).unwrap().buffers.unwrap())
}

/// 003: "noise-free in lit regions". Wherever every sample of a pixel is unshadowed
/// (S_N = U_N bit for bit), the ratio estimators return exactly emitted + U; and with every
/// occluder switched off the ratio image equals the analytic unshadowed image bit for bit.
#[test]
fn ratio_is_exactly_u_where_nothing_is_shadowed() {
    let scene = scene_file::load_embedded("default").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    for method in [RenderMethod::Ratio, RenderMethod::RatioGray] {
        let out = ctx
            .render_full(&cam, &settings(method, 64, 48, 4, 3), None)
            .unwrap();
        let b = out.buffers.unwrap();
        let mut lit = 0;
        let mut shadowed = 0;
        for i in 0..b.s_n.pixels.len() {
            if b.s_n.pixels[i] == b.u_n.pixels[i] {
                lit += 1;
                assert_eq!(out.image.pixels[i], b.emitted.pixels[i] + b.u.pixels[i]);
            } else {
                shadowed += 1;
            }
        }
        assert!(
            lit > 500 && shadowed > 100,
            "lit {lit}, shadowed {shadowed}"
        );
    }

    let mut open = scene.clone();
    for o in &mut open.objects {
        o.flags.occluder = false;
    }
    let ctx = RenderContext::new(&open);
    let unshadowed = ctx
        .render(
            &cam,
            &settings(RenderMethod::Unshadowed, 64, 48, 1, 0),
            None,
        )
        .unwrap()
        .0;
    let ratio = ctx
        .render(&cam, &settings(RenderMethod::Ratio, 64, 48, 4, 3), None)
        .unwrap()
        .0;
    assert_eq!(ratio.pixels, unshadowed.pixels);
}

/// A render is reproducible bit for bit, and the seed matters.
#[test]
fn renders_are_deterministic() {
    let scene = scene_file::load_embedded("fig4").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let s = settings(RenderMethod::Mc, 48, 36, 4, 11);
    let a = ctx.render(&cam, &s, None).unwrap().0;
    let b = ctx.render(&cam, &s, None).unwrap().0;
    assert_eq!(a.pixels, b.pixels);
    let c = ctx
        .render(&cam, &RenderSettings { seed: 12, ..s }, None)
        .unwrap()
        .0;
    assert_ne!(a.pixels, c.pixels);
}

/// Mean squared error over the valid pixels of `est` against `exact` (per channel).
fn mse(b: &StochasticBuffers, est: &[DVec3], exact: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    let mut n = 0;
    for i in 0..est.len() {
        if b.gbuffer.valid[i] {
            let d = est[i] - exact[i];
            sum += d.length_squared();
            n += 3;
        }
    }
    sum / n as f64
}

fn estimate(b: &StochasticBuffers, e: Estimator) -> Vec<DVec3> {
    (0..b.s_n.pixels.len())
        .map(|i| combine(e, b.u.pixels[i], b.s_n.pixels[i], b.u_n.pixels[i]))
        .collect()
}

/// On Lambertian scenes (where the analytic value is exact) every estimator converges to the
/// analytic image like 1/√N: its per-pixel variance is measured from K independent renders
/// at N₀ samples, which predicts the mean squared error at 16·N₀ and 64·N₀ samples
/// (MSE = σ²(N₀)·N₀/N); the measured MSE, from other seeds, must match within the sampling
/// tolerance of a mean of squares over the image (a factor 0.6–1.6, several standard
/// deviations for these pixel counts).
#[test]
fn estimators_converge_to_the_analytic_result_like_one_over_sqrt_n() {
    for name in ["fig4", "chair"] {
        let scene = scene_file::load_embedded(name).unwrap();
        let ctx = RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let (w, h) = (40, 30);
        // S (exact on Lambertian scenes) and U, analytic.
        let b = buffers(&ctx, &settings(RenderMethod::Ratio, w, h, 1, 0));
        let shadowed: Vec<DVec3> = {
            let img = ctx
                .render(&cam, &settings(RenderMethod::Analytic, w, h, 1, 0), None)
                .unwrap()
                .0;
            (0..img.pixels.len())
                .map(|i| img.pixels[i] - b.emitted.pixels[i])
                .collect()
        };
        // The grayscale ratio converges to U · lum(S) / lum(U) instead (Sect. 3.4: it differs
        // from S where lights of different colours are shadowed differently).
        let gray_limit: Vec<DVec3> = (0..shadowed.len())
            .map(|i| {
                combine(
                    Estimator::RatioGray,
                    b.u.pixels[i],
                    shadowed[i],
                    b.u.pixels[i],
                )
            })
            .collect();
        let n0 = 8;
        let k = 12;
        let runs: Vec<StochasticBuffers> = (0..k)
            .map(|s| buffers(&ctx, &settings(RenderMethod::Ratio, w, h, n0, 100 + s)))
            .collect();
        let big: Vec<(u32, StochasticBuffers)> = [16 * n0, 64 * n0]
            .iter()
            .map(|&n| {
                (
                    n,
                    buffers(&ctx, &settings(RenderMethod::Ratio, w, h, n, 999)),
                )
            })
            .collect();
        for e in [
            Estimator::FullStochastic,
            Estimator::ControlVariate,
            Estimator::Ratio,
            Estimator::RatioGray,
        ] {
            // Per-pixel variance at N₀ from the K runs (about their own mean, so that the bias
            // of the ratio estimator at N₀ is not counted as variance).
            let ests: Vec<Vec<DVec3>> = runs.iter().map(|b| estimate(b, e)).collect();
            let mut var = 0.0;
            let mut count = 0;
            for i in 0..ests[0].len() {
                if !runs[0].gbuffer.valid[i] {
                    continue;
                }
                let mean: DVec3 = ests.iter().map(|x| x[i]).sum::<DVec3>() / k as f64;
                let v: f64 = ests
                    .iter()
                    .map(|x| (x[i] - mean).length_squared())
                    .sum::<f64>()
                    / (k - 1) as f64;
                var += v;
                count += 3;
            }
            let var_n0 = var / count as f64;
            assert!(var_n0 > 0.0, "{name} {e:?}: no noise at all?");
            let exact = if e == Estimator::RatioGray {
                &gray_limit
            } else {
                &shadowed
            };
            for (n, b) in &big {
                let predicted = var_n0 * n0 as f64 / *n as f64;
                let measured = mse(b, &estimate(b, e), exact);
                let ratio = measured / predicted;
                eprintln!("{name} {e:?} N={n}: MSE/predicted = {ratio:.2}");
                assert!(
                    (0.6..1.6).contains(&ratio),
                    "{name} {e:?} N={n}: MSE {measured:.3e} vs predicted {predicted:.3e} (×{ratio:.2})"
                );
            }
        }
    }
}

/// The light sampler's triangles cover exactly the directions in which a ray from the shading
/// point hits the light's front (ray casting against the light alone), for convex (silhouette
/// fan), flat, star-shaped (the exact silhouette fanned from a kernel point: `polyhedra`'s
/// corner and extruded cube), neither (the triangles precomputed for the point's cell:
/// `polyhedra`'s hole and bowl) and other non-convex (per-face) lights; and the total solid angle
/// of a light's triangles matches a Monte Carlo estimate of the directions its rays hit
/// (per-face lights count overlapping faces once per face).
#[test]
fn light_triangles_cover_what_ray_casting_sees() {
    let (mut star_runs, mut cell_runs) = (0, 0);
    for name in ["fig4", "nonconvex", "default", "polyhedra", "letters"] {
        let scene: Scene = scene_file::load_embedded(name).unwrap();
        let ctx = RenderContext::new(&scene);
        if name == "letters" {
            // L and T are star-shaped (fans), the C is not (per-cell triangulations).
            let shape = |n: &str| {
                let o = ctx.prepared.objects.iter().find(|o| o.name == n).unwrap();
                (o.star_centre.is_some(), o.triangulation.is_some())
            };
            assert_eq!(shape("letter_l"), (true, false));
            assert_eq!(shape("letter_t"), (true, false));
            assert_eq!(shape("letter_c"), (false, true));
        }
        let cam = scene.camera.unwrap();
        let basis = cam.basis().unwrap();
        let mut rng = Pcg32::new(5, 5);
        let mut set = LightSet::default();
        let mut checked = 0;
        for _ in 0..60 {
            let dir = basis.direction(rng.range(0.0, 64.0), rng.range(0.0, 64.0), 64, 64);
            let Some(hit) = ctx.primary_hit(&Ray {
                origin: basis.eye,
                dir,
            }) else {
                continue;
            };
            if !hit.receiver {
                continue;
            }
            let sp = hit.point;
            let frame = Frame::from_normal_and_view(sp.normal, sp.view);
            set.build(&ctx.prepared, &sp, &frame);
            for (r, run) in set.runs.iter().enumerate() {
                let light_obj = run.object;
                if sp.object == Some(light_obj) {
                    // A point on the light itself (`polyhedra`'s lights are receivers): the ray
                    // oracle would meet the face the point lies on at t = 0.
                    continue;
                }
                let n = 4000;
                let mut hits = 0;
                for _ in 0..n {
                    // Uniform directions in the upper hemisphere.
                    let mut w = rng.unit_vector();
                    w.z = w.z.abs();
                    let wd = frame.to_world(w);
                    let ray = Ray {
                        origin: sp.position,
                        dir: wd,
                    };
                    let seen = ctx
                        .bvh
                        .intersect_accept(&ray, 0.0, f64::INFINITY, |o, _| o == light_obj)
                        .is_some_and(|h| h.geometric_normal.dot(wd) < 0.0);
                    assert_eq!(
                        set.covers(r, w),
                        seen,
                        "{name}: light {} at {:?} direction {w}",
                        run.light,
                        sp.position
                    );
                    hits += seen as u32;
                }
                checked += 1;
                let obj = ctx
                    .prepared
                    .objects
                    .iter()
                    .find(|o| o.object == light_obj)
                    .unwrap();
                if obj.star_centre.is_some() && !run.self_occluding {
                    star_runs += 1;
                }
                if obj.triangulation.is_some() && !run.self_occluding {
                    cell_runs += 1;
                }
                if !run.self_occluding {
                    // Binomial σ under the hypothesis that Ω is right.
                    let tau = 2.0 * std::f64::consts::PI;
                    let p = (run.solid_angle / tau).min(1.0);
                    let mc = hits as f64 / n as f64 * tau;
                    let sigma = tau * (p * (1.0 - p) / n as f64).sqrt();
                    assert!(
                        (mc - run.solid_angle).abs() < 4.5 * sigma + 1e-9,
                        "{name}: Ω {} vs MC {mc} ± {sigma}",
                        run.solid_angle
                    );
                }
            }
        }
        assert!(checked > 20, "{name}: only {checked} lights checked");
    }
    assert!(star_runs > 20, "only {star_runs} star-shaped fans checked");
    assert!(
        cell_runs > 20,
        "only {cell_runs} precomputed triangulations checked"
    );
}
