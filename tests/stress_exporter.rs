//! The stress family of exporter-style meshes (`CaseKind::ExporterMeshes`): meshes written with
//! 6 decimals or 9 significant digits and read back, nearly convex, dented and large. Each case
//! is checked against its ray-cast estimate (the stress oracle: cosine-distributed rays that
//! first hit the front of a light face), and the family must reach every path those meshes
//! take: a hull standing in, the exact silhouette, the plain convex one.

use penumbra::shading::{PathKind, PrepareOptions, PreparedScene};
use penumbra::stress::{CaseKind, KIND_PERIOD, exporter_meshes, generate, kind_of, run_one};

#[test]
fn exporter_meshes_load_without_geometry_warnings_and_take_their_paths() {
    let mut paths = Vec::new();
    for (name, mesh) in exporter_meshes() {
        assert!(
            mesh.rounding > 0.0,
            "{name}: the rounding of its digits is known"
        );
        let scene = penumbra::scene::Scene {
            objects: vec![penumbra::scene::SceneObject {
                name: (*name).into(),
                mesh: mesh.clone(),
                material: Default::default(),
                flags: penumbra::scene::ObjectFlags {
                    light: false,
                    occluder: true,
                    receiver: true,
                    is_static: false,
                },
            }],
            camera: None,
            warnings: Vec::new(),
            environment: None,
        };
        let options = PrepareOptions {
            build_trees: false,
            ..PrepareOptions::default()
        };
        let p = PreparedScene::prepare(&scene, options);
        paths.push((*name, p.objects[0].kind()));
    }
    let path = |n: &str| paths.iter().find(|(m, _)| *m == n).map(|p| p.1);
    // Convex as meant, not as written: the hull stands in.
    assert_eq!(
        path("uv_sphere_32x16"),
        Some(PathKind::HullAtPoint),
        "{paths:?}"
    );
    assert_eq!(
        path("cylinder_32"),
        Some(PathKind::HullAtPoint),
        "{paths:?}"
    );
    // Dented and large (more faces than `WINDOWED_MIN_FACES`): the exact silhouette inside
    // each light's window.
    assert_eq!(
        path("twisted_ellipsoid"),
        Some(PathKind::ExactInWindow),
        "{paths:?}"
    );
    assert_eq!(
        path("displaced_icosphere"),
        Some(PathKind::ExactInWindow),
        "{paths:?}"
    );
}

#[test]
fn exporter_mesh_cases_match_ray_casting() {
    let (seed, rays) = (11, 4096);
    let (mut cases, mut beyond, mut worst) = (0, 0, 0.0f64);
    for index in (0..200).map(|k| KIND_PERIOD - 1 + k * KIND_PERIOD) {
        assert_eq!(kind_of(index), CaseKind::ExporterMeshes);
        assert_eq!(generate(seed, index).kind, CaseKind::ExporterMeshes);
        cases += 1;
        let (case, analytic, estimate, sigma, violations) = run_one(seed, index, rays);
        assert_eq!(violations, 0, "case {index}");
        assert!(
            analytic.is_finite() && analytic >= 0.0,
            "case {index}: {analytic}"
        );
        // The stress criterion: 6 standard deviations of the estimate plus 1/rays.
        let z = (analytic - estimate).abs() / (sigma + 1.0 / rays as f64);
        worst = worst.max(z);
        if z > 6.0 {
            beyond += 1;
            eprintln!(
                "case {index} (scale {:.2e}): analytic {analytic}, estimate {estimate}, {z:.1}σ",
                case.scale
            );
        }
    }
    assert_eq!(cases, 200);
    assert_eq!(
        beyond, 0,
        "{beyond} of {cases} cases beyond 6σ (worst {worst:.2}σ)"
    );
}
