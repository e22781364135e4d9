//! The environment light end to end (paper 002): every method against independent oracles.
//!
//! * `analytic` (the exact SH × cos integral over the visible region) against `reference`
//!   (Monte Carlo of the map itself with shadow rays, a different algorithm), on a map that
//!   is band-limited so that both integrate the same radiance: per-pixel z-scores.
//! * `rt` (002 Alg. 1–2, unfiltered) against `analytic`: unbiased, so the mean difference
//!   over the pixels is within a few standard errors of it.
//! * Culling (direction, direction + length, none) leaves E_occluded bit for bit the same.

use glam::DVec3;
use penumbra::environment::{EnvironmentLight, EnvironmentMap, Sh9};
use penumbra::raster::Image;
use penumbra::render::environment_passes::{Culling, EnvironmentOutput, EnvironmentSettings};
use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
use penumbra::scene::environment_spec::EnvMethod;
use penumbra::scene::shapes::{cuboid, l_shape, quad};
use penumbra::scene::{Camera, Material, Mesh, ObjectFlags, Scene, SceneObject};
use std::sync::Arc;

fn object(name: &str, mesh: Mesh, kd: f64, is_static: bool) -> SceneObject {
    SceneObject {
        name: name.into(),
        mesh,
        material: Material {
            kd: DVec3::splat(kd),
            ..Material::default()
        },
        flags: ObjectFlags {
            light: false,
            occluder: true,
            receiver: true,
            is_static,
        },
    }
}

/// A floor, a box standing on it, an L floating beside it and (optionally) a wall behind
/// them: contact shadows, a non-convex occluder, and static geometry behind dynamic objects
/// (what length culling skips).
fn scene(static_floor: bool, wall: bool) -> Scene {
    let mut objects = vec![
        object(
            "floor",
            quad(DVec3::ZERO, DVec3::Z * 3.0, DVec3::X * 3.0),
            0.7,
            static_floor,
        ),
        object(
            "box",
            cuboid(DVec3::new(-0.4, 0.301, 0.0), DVec3::new(0.25, 0.3, 0.25)),
            0.6,
            false,
        ),
        object(
            "l",
            l_shape(DVec3::new(0.5, 0.55, -0.2), 0.6, 0.8, 0.2, 0.3),
            0.5,
            false,
        ),
    ];
    if wall {
        objects.push(object(
            "wall",
            cuboid(DVec3::new(0.0, 0.8, -1.2), DVec3::new(2.0, 0.8, 0.1)),
            0.65,
            true,
        ));
    }
    Scene {
        objects,
        camera: Some(Camera {
            eye: DVec3::new(0.3, 1.6, 2.6),
            target: DVec3::new(0.0, 0.35, 0.0),
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        }),
        warnings: Vec::new(),
        environment: None,
    }
}

/// A band-limited sky: positive everywhere (L00 dominates), brighter above, tinted, with
/// every band-1 and band-2 coefficient nonzero so that the quadratic form is fully exercised.
fn band_limited_light() -> Arc<EnvironmentLight> {
    let mut sh = Sh9::default();
    let c = [
        [2.0, 2.1, 2.4],
        [0.45, 0.5, 0.6],
        [0.15, 0.1, -0.1],
        [-0.2, -0.1, 0.05],
        [0.05, -0.04, 0.03],
        [-0.06, 0.05, 0.02],
        [0.1, 0.08, 0.12],
        [0.04, -0.05, 0.06],
        [-0.07, 0.03, -0.02],
    ];
    for (k, v) in c.iter().enumerate() {
        sh.coeffs[k] = DVec3::from_array(*v);
    }
    let map = EnvironmentMap::from_sh(&sh, 256, 128);
    assert!(
        map.pixels().iter().all(|p| p.min_element() > 0.0),
        "the test sky must be positive"
    );
    Arc::new(EnvironmentLight::from_map(map, "test-sh".into()))
}

const SIZE: u32 = 40;

fn render(scene: &Scene, settings: EnvironmentSettings) -> (Image, EnvironmentOutput) {
    let mut ctx = RenderContext::new(scene);
    ctx.set_environment(band_limited_light(), settings);
    let rs = RenderSettings {
        width: SIZE,
        height: SIZE,
        aa: 1,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let out = ctx
        .render_full(scene.camera.as_ref().unwrap(), &rs, None)
        .unwrap();
    let env = out.environment.expect("the environment pass ran");
    (out.image, env)
}

fn assert_valid(img: &Image, what: &str) {
    let (nan, inf, neg) = img.invalid_counts();
    assert_eq!(
        (nan, inf, neg),
        (0, 0, 0),
        "{what}: NaN/Inf/negative pixels"
    );
}

/// Per-channel z-scores of `img` against a reference with standard error `err`, over the
/// channels whose standard error is positive (pixels with shadows or sky).
fn z_scores(img: &Image, reference: &Image, err: &Image) -> Vec<f64> {
    let mut z = Vec::new();
    for ((a, r), e) in img.pixels.iter().zip(&reference.pixels).zip(&err.pixels) {
        for c in 0..3 {
            if e[c] > 0.0 {
                z.push((a[c] - r[c]) / e[c]);
            }
        }
    }
    z
}

#[test]
fn analytic_matches_the_reference_within_its_noise() {
    for static_floor in [false, true] {
        let s = scene(static_floor, true);
        let (analytic, _) = render(&s, EnvironmentSettings::new(EnvMethod::Analytic, 1, 1));
        let (reference, r) = render(&s, EnvironmentSettings::new(EnvMethod::Reference, 400, 7));
        assert_valid(&analytic, "analytic");
        let err = r.stderr.expect("the reference has a standard error");
        let z = z_scores(&analytic, &reference, &err);
        assert!(z.len() > 3000, "too few shaded channels: {}", z.len());
        let n = z.len() as f64;
        let within = z.iter().filter(|v| v.abs() <= 3.0).count() as f64 / n;
        let rms = (z.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        let mean = z.iter().sum::<f64>() / n;
        // Gaussian z: 99.7 % within 3σ and rms 1. With 400 samples per pixel the standard
        // error is itself estimated (a few % relative spread) and the visibility makes the
        // per-pixel estimate skewed where few samples see the sky, hence the margins. A bias
        // of 0.2 standard errors over thousands of channels would move the mean beyond 0.1.
        assert!(
            within > 0.98,
            "static floor {static_floor}: {within} within 3σ"
        );
        assert!(rms < 1.2, "static floor {static_floor}: rms z {rms}");
        assert!(
            mean.abs() < 0.1,
            "static floor {static_floor}: mean z {mean}"
        );
    }
}

#[test]
fn rt_is_unbiased_against_analytic_when_every_object_is_dynamic() {
    let s = scene(false, false);
    let (analytic, _) = render(&s, EnvironmentSettings::new(EnvMethod::Analytic, 1, 1));
    let mut settings = EnvironmentSettings::new(EnvMethod::Rt, 512, 3);
    settings.filter = false;
    let (rt, _) = render(&s, settings);
    assert_valid(&rt, "rt");
    let d: Vec<f64> = rt
        .pixels
        .iter()
        .zip(&analytic.pixels)
        .flat_map(|(a, b)| (*a - *b).to_array())
        .filter(|v| *v != 0.0)
        .collect();
    assert!(d.len() > 1000, "too few pixels differ: {}", d.len());
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    let se = (var / n).sqrt();
    // The per-pixel rotations make the pixels' errors independent: the mean difference of an
    // unbiased estimator is within 4 standard errors (and the clamp at 0 never acts here, the
    // sky is bright and the shadows partial).
    assert!(
        mean.abs() < 4.0 * se,
        "mean difference {mean} vs standard error {se}"
    );
    // And the estimator is not noise alone: 512 rays put each pixel near the exact value.
    let rms = (d.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    let level = analytic.pixels.iter().map(|p| p.x).sum::<f64>() / analytic.pixels.len() as f64;
    assert!(
        rms < 0.05 * level,
        "rms difference {rms} against a mean level {level}"
    );
}

#[test]
fn culling_never_changes_the_occluded_irradiance() {
    for (static_floor, wall) in [(true, true), (false, true), (true, false)] {
        let s = scene(static_floor, wall);
        let run = |culling: Culling| {
            let mut settings = EnvironmentSettings::new(EnvMethod::Rt, 64, 11);
            settings.culling = culling;
            settings.filter = false;
            render(&s, settings)
        };
        let (img_none, none) = run(Culling::None);
        let (img_dir, dir) = run(Culling::Direction);
        let (img_len, len) = run(Culling::DirectionAndLength);
        assert_eq!(
            none.occluded, dir.occluded,
            "direction culling changed E_occluded"
        );
        assert_eq!(
            none.occluded, len.occluded,
            "length culling changed E_occluded"
        );
        assert_eq!(img_none, img_dir);
        assert_eq!(img_none, img_len);
        // Culling did cull: fewer rays traced (with a dynamic floor every point lies inside
        // its bounding sphere and traces every ray, 002 Alg. 1 lines 6–8), and some pixels
        // have shadows.
        if static_floor {
            assert!(len.stats.rays_traced < none.stats.rays_traced);
        } else {
            assert_eq!(len.stats.rays_traced, none.stats.rays_traced);
        }
        assert!(none.occluded.pixels.iter().any(|p| p.max_element() > 0.0));
    }
}

#[test]
fn cone_clustering_never_changes_the_occluded_irradiance() {
    let s = scene(true, true);
    let mut a = EnvironmentSettings::new(EnvMethod::Rt, 64, 5);
    a.filter = false;
    let mut b = a;
    b.max_cones = Some(1);
    assert_eq!(render(&s, a).1.occluded, render(&s, b).1.occluded);
}

#[test]
fn unshadowed_and_rtao_bound_the_shadowed_image() {
    let s = scene(false, false);
    let (unshadowed, _) = render(&s, EnvironmentSettings::new(EnvMethod::Unshadowed, 1, 1));
    let (analytic, _) = render(&s, EnvironmentSettings::new(EnvMethod::Analytic, 1, 1));
    let (rtao, _) = render(&s, EnvironmentSettings::new(EnvMethod::Rtao, 64, 1));
    assert_valid(&rtao, "rtao");
    // Shadows only remove light (the test sky is positive everywhere).
    for (u, a) in unshadowed.pixels.iter().zip(&analytic.pixels) {
        for c in 0..3 {
            assert!(a[c] <= u[c] * (1.0 + 1e-9) + 1e-12, "{a} > {u}");
        }
    }
    for (u, r) in unshadowed.pixels.iter().zip(&rtao.pixels) {
        for c in 0..3 {
            assert!(r[c] <= u[c] * (1.0 + 1e-9) + 1e-12);
        }
    }
}

#[test]
fn scene_files_carry_the_environment_and_static_objects() {
    use penumbra::scene::environment_spec::EnvironmentSource;
    use penumbra::scene::scene_file::load_scene_str;
    let obj = |_: &str| -> Result<Scene, penumbra::Error> {
        let mut s = Scene::default();
        s.objects.push(object(
            "floor",
            quad(DVec3::ZERO, DVec3::Z, DVec3::X),
            0.5,
            false,
        ));
        Ok(s)
    };
    let text = "[environment]\nmap = \"sky-sh\"\nrotate = 30\nscale = 2\nmethod = \"rt\"\nspp = 64\n\n[[object]]\nobj = \"a.obj\"\nstatic = true\n";
    let s = load_scene_str(text, "t.toml", &obj).unwrap();
    let e = s.environment.expect("environment");
    assert_eq!(e.source, EnvironmentSource::SkySh);
    assert_eq!((e.rotate_deg, e.scale, e.spp), (30.0, 2.0, Some(64)));
    assert_eq!(e.method, Some(EnvMethod::Rt));
    assert!(s.objects[0].flags.is_static);
    for (bad, line) in [
        ("[environment]\nmap = \"sky\"\nscale = -1\n", 1),
        ("[environment]\nmap = \"sky\"\nmethod = \"magic\"\n", 3),
        ("[environment]\nmap = \"sky\"\nspp = 0\n", 1),
    ] {
        let err = load_scene_str(bad, "t.toml", &obj).unwrap_err().to_string();
        assert!(err.starts_with(&format!("t.toml:{line}:")), "{err}");
    }
}

/// The precomputed transfer (002 Eq. 6, `environment::prt`) against the exact polygon integral
/// over what the static objects leave (a different algorithm: clipping, no rays), at the
/// nodes of the floor's grid, where no interpolation enters. Every object is static.
///
/// Each node's estimate is a mean of N cosine-weighted rays of π L(ω) V(ω). For independent
/// rays its variance would be at most (π L_max E − E²)/N per channel, since
/// E[(π L V)²] ≤ π L_max E[π L V]; the stratified (Hammersley) rays do better. So the
/// errors in units of that bound have an rms at most 1 and no outlier beyond 5. The nodes
/// under the wall (inside a solid) must be marked as such, and no other.
#[test]
fn prt_transfer_matches_the_exact_static_integral_at_its_nodes() {
    use penumbra::environment::prt::{PrtSettings, TransferField, transferred_irradiance};
    use penumbra::shading::{
        EnvironmentOccluders, EnvironmentPass, NoRecorder, ShadingPoint, ShadingScratch,
        environment_integrals,
    };
    let mut s = scene(true, true);
    for o in &mut s.objects {
        o.flags.is_static = true;
    }
    let ctx = RenderContext::new(&s);
    let light = band_limited_light();
    let settings = PrtSettings {
        rays: 256,
        max_nodes: 2048,
    };
    let field = TransferField::compute(&s, &ctx.bvh, settings);
    assert!(field.is_well_formed(s.objects.len(), |o| s.objects[o].mesh.faces.len()));
    let occluders = EnvironmentOccluders::new(&ctx.prepared, |_| true);
    let l_max = light
        .map
        .pixels()
        .iter()
        .fold(DVec3::ZERO, |a, &p| a.max(p))
        * 1.01;
    let grid = field.grids[field.object_grids[0] as usize].expect("the floor has a grid");
    let normal = grid.normal;
    assert!(normal.y > 0.99, "the floor faces up");
    let mut scratch = ShadingScratch::default();
    let (mut z2, mut n, mut worst, mut inside) = (0.0, 0usize, 0.0f64, 0usize);
    for b in 0..grid.nv {
        for a in 0..grid.nu {
            let p = grid.node(a, b);
            let Some(t) = field.transfer(0, 0, p, normal) else {
                // A node inside a static solid: only under the wall.
                assert!(
                    (-1.3..=-1.1).contains(&p.z),
                    "node {p} marked inside a solid"
                );
                inside += 1;
                continue;
            };
            let prt = transferred_irradiance(&light.sh, &t);
            let sp = ShadingPoint {
                position: p,
                normal,
                view: normal,
                object: Some(0),
                face: Some(0),
            };
            let exact = environment_integrals(
                &ctx.prepared,
                &occluders,
                &sp,
                EnvironmentPass::StaticOnly,
                &|frame, poly| light.integrate(frame, poly),
                &mut scratch,
                &mut NoRecorder,
            )
            .static_visible
            .unwrap_or_else(|| light.irradiance(normal));
            for c in 0..3 {
                let var = (std::f64::consts::PI * l_max[c] * exact[c] - exact[c] * exact[c])
                    .max(1e-12)
                    / settings.rays as f64;
                // f32 storage adds at most ~1e-7 relative.
                let z = (prt[c] - exact[c]) / (var.sqrt() + 1e-6 * exact[c].abs());
                z2 += z * z;
                n += 1;
                worst = worst.max(z.abs());
            }
        }
    }
    let rms = (z2 / n as f64).sqrt();
    assert!(n >= 3 * 400, "{n} node channels");
    assert!(inside > 0, "the nodes under the wall are inside it");
    assert!(
        rms <= 1.0,
        "rms error {rms} of the i.i.d. bound (worst {worst})"
    );
    assert!(worst <= 5.0, "worst error {worst} of the i.i.d. bound");
    eprintln!(
        "PRT at {} floor nodes: rms {rms:.3}, worst {worst:.3} of the i.i.d. bound",
        n / 3
    );
}

/// The transfer is cached like the trees: a second request reads the same field back; a
/// change of the static geometry (not of a dynamic object) asks for a new one.
#[test]
fn prt_transfer_is_cached_by_its_static_geometry() {
    use penumbra::environment::prt::{PrtSettings, TransferField, transfer_key};
    use penumbra::shading::tree_cache::TreeCache;
    let dir = std::env::temp_dir().join(format!("penumbra-prt-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let cache = TreeCache {
        dir: dir.clone(),
        max_bytes: 64 << 20,
    };
    let s = scene(true, true);
    let ctx = RenderContext::new(&s);
    let settings = PrtSettings {
        rays: 16,
        max_nodes: 512,
    };
    let (a, ra) = TransferField::cached_or_computed(&s, &ctx.bvh, settings, Some(&cache));
    let (b, rb) = TransferField::cached_or_computed(&s, &ctx.bvh, settings, Some(&cache));
    assert!(!ra.from_cache && rb.from_cache);
    assert_eq!(a, b);
    assert!(a.node_count() > 0 && a.node_count() <= 512);
    let key = transfer_key(&s, settings);
    let mut moved_dynamic = s.clone();
    moved_dynamic.objects[1].mesh.positions[0].x += 0.01; // the box is dynamic
    assert_eq!(transfer_key(&moved_dynamic, settings), key);
    let mut moved_static = s.clone();
    moved_static.objects[3].mesh.positions[0].x += 0.01; // the wall is static
    assert_ne!(transfer_key(&moved_static, settings), key);
    let _ = std::fs::remove_dir_all(&dir);
}
