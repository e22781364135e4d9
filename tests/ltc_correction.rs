//! `analytic-exact`: the LTC image plus `∫_V (f_GGX − f_LTC) cos` sampled inside the
//! exact visible polygon `V` (`shading::ltc_correction`), against brute-force ray casting of
//! GGX (`penumbra::reference::direct_lighting`: area-sampled shadow rays through the BVH, no
//! LTC and no spherical polygon anywhere).

use glam::DVec3;
use penumbra::math::Pcg32;
use penumbra::reference::direct_lighting;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::sampling::area_light::LightSampler;
use penumbra::scene::{Material, scene_file};
use penumbra::shading::{
    CorrectionSampling, Method, NoRecorder, ShadingPoint, ShadingScratch, Stage, StageRecording,
    shade, shade_corrected,
};

/// A point of the `glossy` scene's floor seen from `view_deg` off the normal, toward +z (the
/// camera's side, so the light's reflection is in front of the view).
fn floor_point(x: f64, z: f64, view_deg: f64) -> ShadingPoint {
    let (s, c) = view_deg.to_radians().sin_cos();
    ShadingPoint {
        position: DVec3::new(x, 0.0, z),
        normal: DVec3::Y,
        view: DVec3::new(0.0, c, s),
        object: Some(0),
        face: Some(0),
    }
}

/// The corrected estimator's mean equals GGX integrated by ray casting, within the joint
/// confidence interval of the two estimates, at normal, oblique and grazing views, for two
/// roughnesses, per channel with three Fresnel F0, and at points whose visible polygon has a
/// hole (the box seen inside the light). The LTC alone is outside that interval at some of these
/// points (else the test could not tell the two apart).
#[test]
fn corrected_mean_matches_ray_cast_ggx_including_holes_and_grazing_views() {
    // The glossy scene with its box shrunk to 35 % about its centre: seen from under it, the
    // box lies inside the light and cuts a hole in the visible polygon.
    let mut scene = scene_file::load_embedded("glossy").unwrap();
    let bx = scene.objects.iter_mut().find(|o| o.name == "box").unwrap();
    let centre = bx.mesh.positions.iter().sum::<DVec3>() / bx.mesh.positions.len() as f64;
    for p in &mut bx.mesh.positions {
        *p = centre + (*p - centre) * 0.35;
    }
    let ctx = RenderContext::new(&scene);
    let lights = LightSampler::new(&scene);
    let mut scratch = ShadingScratch::default();
    let mut rng = Pcg32::new(5, 9);
    let (mut holes, mut ltc_rejected, mut cases) = (0, 0, 0);
    for alpha in [0.1, 0.3] {
        for view_deg in [10.0, 60.0, 85.0] {
            // Lit, in the box's penumbra, and on the line from the light's centre through the
            // box's (the box inside the light: a hole).
            for &(x, z) in &[(0.0, 0.9), (0.2, 0.55), (0.143, 0.586), (0.12, 0.62)] {
                let sp = floor_point(x, z, view_deg);
                let mat = Material {
                    kd: DVec3::ZERO,
                    ks: DVec3::new(1.0, 0.5, 0.04),
                    alpha,
                    ..Material::default()
                };
                let sampling = CorrectionSampling {
                    samples: 40_000,
                    seed: 3,
                    stream: cases,
                };
                let mut rec = StageRecording::default();
                let c = shade_corrected(
                    &ctx.prepared,
                    &sp,
                    &mat,
                    Method::Analytic,
                    &sampling,
                    &mut scratch,
                    &mut rec,
                );
                if rec.lights.iter().any(|l| {
                    l.polygons
                        .iter()
                        .any(|(s, p)| *s == Stage::Visible && p.loop_count() >= 2)
                }) {
                    holes += 1;
                }
                let (m, e) = direct_lighting(&ctx, &lights, &sp, &mat, 400_000, &mut rng);
                let est = c.total();
                for k in 0..3 {
                    let sigma = (c.variance[k] + e[k] * e[k]).sqrt();
                    assert!(
                        (est[k] - m[k]).abs() <= 4.5 * sigma + 1e-12,
                        "α {alpha}, θv {view_deg}°, ({x}, {z}), channel {k}: corrected {} \
                         (LTC {} + {}) vs ray cast {} (σ {sigma})",
                        est[k],
                        c.ltc[k],
                        c.correction[k],
                        m[k]
                    );
                    if (c.ltc[k] - m[k]).abs() > 6.0 * sigma {
                        ltc_rejected += 1;
                    }
                }
                cases += 1;
            }
        }
    }
    assert!(holes >= 2, "only {holes} visible polygons with a hole");
    assert!(
        ltc_rejected >= 6,
        "the LTC alone was told apart from GGX in only {ltc_rejected} channels"
    );
}

/// Where the BRDF is Lambertian the LTC (a clamped cosine) is exact: no correction sample is
/// taken, the correction and its variance are exactly zero, and `analytic-exact` renders the
/// analytic image bit for bit with a zero standard error.
#[test]
fn correction_has_zero_variance_where_the_brdf_is_lambertian() {
    let scene = scene_file::load_embedded("glossy").unwrap();
    let ctx = RenderContext::new(&scene);
    let mut scratch = ShadingScratch::default();
    let mat = Material {
        kd: DVec3::splat(0.7),
        ks: DVec3::ZERO,
        alpha: 0.3,
        ..Material::default()
    };
    for (i, &(x, z, view)) in [(0.0, 0.9, 30.0), (0.1, 0.6, 80.0)].iter().enumerate() {
        let sp = floor_point(x, z, view);
        let sampling = CorrectionSampling {
            samples: 64,
            seed: 1,
            stream: i as u64,
        };
        let c = shade_corrected(
            &ctx.prepared,
            &sp,
            &mat,
            Method::Analytic,
            &sampling,
            &mut scratch,
            &mut NoRecorder,
        );
        assert!(c.ltc.max_element() > 0.0);
        assert_eq!((c.correction, c.variance), (DVec3::ZERO, DVec3::ZERO));
        let plain = shade(
            &ctx.prepared,
            &sp,
            &mat,
            Method::Analytic,
            &mut scratch,
            &mut NoRecorder,
        );
        assert_eq!(c.ltc, plain);
    }

    let chair = scene_file::load_embedded("chair").unwrap();
    let ctx = RenderContext::new(&chair);
    let cam = chair.camera.unwrap();
    let base = RenderSettings {
        width: 48,
        height: 36,
        ..RenderSettings::default()
    };
    let analytic = ctx.render(&cam, &base, None).unwrap().0;
    let exact = ctx
        .render_full(
            &cam,
            &RenderSettings {
                method: RenderMethod::AnalyticExact,
                spp: 8,
                ..base
            },
            None,
        )
        .unwrap();
    assert_eq!(exact.image.pixels, analytic.pixels);
    let stderr = exact.stderr.unwrap();
    assert!(stderr.pixels.iter().all(|p| *p == DVec3::ZERO));
}

/// On the glossy scene the LTC image is biased and `analytic-exact` is not: the mean of the
/// difference between an `analytic-exact` image and an independent ray-cast reference, in
/// units of their joint per-pixel noise, is near 0, while the LTC image's is far below it.
#[test]
fn analytic_exact_image_is_unbiased_against_a_ray_cast_reference() {
    let scene = scene_file::load_embedded("glossy").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let base = RenderSettings {
        width: 40,
        height: 30,
        ..RenderSettings::default()
    };
    let reference = ctx
        .render_full(
            &cam,
            &RenderSettings {
                method: RenderMethod::Reference,
                spp: 512,
                ..base
            },
            None,
        )
        .unwrap();
    let exact = ctx
        .render_full(
            &cam,
            &RenderSettings {
                method: RenderMethod::AnalyticExact,
                spp: 256,
                seed: 7,
                ..base
            },
            None,
        )
        .unwrap();
    let ltc = ctx.render(&cam, &base, None).unwrap().0;
    let (rs, es) = (reference.stderr.unwrap(), exact.stderr.unwrap());
    // The mean over all channels of (image − reference), against its standard error from the
    // per-pixel variances of both (pixels are independent).
    let (mut d_exact, mut mean, mut var, mut n) = (0.0, 0.0, 0.0, 0usize);
    let mut d_ltc = 0.0;
    for i in 0..ltc.pixels.len() {
        for k in 0..3 {
            d_exact += exact.image.pixels[i][k] - reference.image.pixels[i][k];
            d_ltc += ltc.pixels[i][k] - reference.image.pixels[i][k];
            mean += reference.image.pixels[i][k];
            var += rs.pixels[i][k].powi(2) + es.pixels[i][k].powi(2);
            n += 1;
        }
    }
    let se = var.sqrt() / n as f64;
    let (d_exact, d_ltc, mean) = (d_exact / n as f64, d_ltc / n as f64, mean / n as f64);
    eprintln!(
        "mean difference: analytic-exact {d_exact:.2e}, LTC {d_ltc:.2e}, standard error {se:.2e}, mean {mean:.3}"
    );
    assert!(
        d_exact.abs() < 4.0 * se,
        "mean difference of analytic-exact {d_exact} (standard error {se})"
    );
    // The test has the power to see a bias of 1 % of the image's mean.
    assert!(0.01 * mean > 8.0 * se, "1 % of {mean} against {se}");
}

/// The progressive renderer shows the LTC image first and converges from there: the previews
/// of `analytic-exact` are the analytic images of their size bit for bit, every full-resolution
/// pass keeps that LTC image (less what the lights emit toward the eye) as its U, and the
/// correction of the last frame is the mean of the passes' corrections (its standard error
/// falls as passes accumulate).
#[test]
fn progressive_analytic_exact_starts_from_the_ltc_image() {
    use penumbra::render::progressive::{PREVIEW_SCALE, render_progressive};
    use std::sync::atomic::AtomicBool;
    let scene = scene_file::load_embedded("glossy").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let settings = RenderSettings {
        width: 320,
        height: 256,
        method: RenderMethod::AnalyticExact,
        spp: 4,
        ..RenderSettings::default()
    };
    let cancel = AtomicBool::new(false);
    let mut previews = 0;
    let mut stderr_first = None;
    let last = render_progressive(&ctx, &cam, &settings, 4, &cancel, |f| {
        let (w, h) = (f.output.image.width, f.output.image.height);
        if f.scale >= PREVIEW_SCALE {
            let analytic = ctx
                .render(
                    &cam,
                    &RenderSettings {
                        width: w,
                        height: h,
                        method: RenderMethod::Analytic,
                        ..settings
                    },
                    None,
                )
                .unwrap()
                .0;
            let same = f.output.image.pixels == analytic.pixels;
            let first = (0..analytic.pixels.len())
                .find(|&i| f.output.image.pixels[i] != analytic.pixels[i]);
            assert!(same, "preview 1/{}: pixel {first:?} differs", f.scale);
            previews += 1;
        } else if f.scale == 1 && f.passes == 1 {
            stderr_first = f.output.stderr.clone();
        }
    })
    .unwrap()
    .unwrap();
    assert!(previews >= 2);
    assert_eq!(last.passes, 4);
    let analytic = ctx
        .render(
            &cam,
            &RenderSettings {
                method: RenderMethod::Analytic,
                ..settings
            },
            None,
        )
        .unwrap()
        .0;
    let b = last.output.buffers.unwrap();
    let ltc: Vec<DVec3> =
        b.u.pixels
            .iter()
            .zip(&b.emitted.pixels)
            .map(|(u, e)| *e + *u)
            .collect();
    assert!(ltc == analytic.pixels, "emitted + U is not the LTC image");
    // Four passes: the standard error of the mean halves (summed over the image).
    let total = |img: &penumbra::raster::Image| img.pixels.iter().map(|p| p.x).sum::<f64>();
    let ratio = total(last.output.stderr.as_ref().unwrap()) / total(&stderr_first.unwrap());
    assert!(
        (0.4..0.6).contains(&ratio),
        "stderr ratio after 4 passes {ratio}"
    );
}

/// `penumbra probe --method analytic-exact` records the render's own value: with the render's
/// seed and sample count, the probe's radiance is the pixel of an `--aa 1` render bit for bit,
/// and its per-light corrections add up to the probe's correction.
#[test]
fn probe_records_the_rendered_correction() {
    use penumbra::inspect::{correction_stream, probe_corrected};
    let scene = scene_file::load_embedded("glossy").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let settings = RenderSettings {
        width: 32,
        height: 24,
        method: RenderMethod::AnalyticExact,
        spp: 8,
        seed: 11,
        ..RenderSettings::default()
    };
    let image = ctx.render(&cam, &settings, None).unwrap().0;
    let mut checked = 0;
    for &(x, y) in &[(16.0, 18.0), (10.0, 20.0), (20.0, 14.0)] {
        let p = probe_corrected(
            &ctx,
            "glossy",
            &cam,
            (32, 24),
            (x, y),
            Method::Analytic,
            Some(CorrectionSampling {
                samples: settings.spp,
                seed: settings.seed,
                stream: correction_stream((x, y), 32),
            }),
            false,
        )
        .unwrap();
        let i = (y as usize) * 32 + x as usize;
        assert_eq!(p.radiance, image.pixels[i], "pixel ({x}, {y})");
        let c = p.correction.unwrap();
        let sum: DVec3 = p.lights.iter().map(|l| l.correction).sum();
        assert!((sum - c.value).length() <= 1e-12 * c.value.length().max(1e-300));
        if c.value != DVec3::ZERO {
            checked += 1;
        }
    }
    assert!(
        checked >= 2,
        "only {checked} probed points had a correction"
    );
}
