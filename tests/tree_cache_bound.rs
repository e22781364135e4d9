//! The disk cache of silhouette trees stays within its bound however many scenes are
//! prepared, evicting the least recently used trees first; a stress run writes nothing to it.

use glam::{DAffine3, DQuat, DVec3};
use penumbra::math::Pcg32;
use penumbra::scene::shapes::quad;
use penumbra::scene::thesis_polyhedra::thesis_polyhedron;
use penumbra::scene::{Material, ObjectFlags, Scene, SceneObject};
use penumbra::shading::tree_cache::TreeCache;
use penumbra::shading::{PrepareOptions, PreparedScene};

/// A quad light over a "hole" polyhedron turned at random: a scene whose two trees (the
/// hole's exact-silhouette tree and the light's) are new files.
fn scene(k: u64) -> Scene {
    let mut rng = Pcg32::new(7, k);
    let axis = rng.unit_vector();
    let turn = DAffine3::from_rotation_translation(
        DQuat::from_axis_angle(axis, rng.range(0.1, 3.0)),
        DVec3::new(0.0, 0.0, 1.0),
    );
    let object = |name: &str, mesh, light: bool| SceneObject {
        name: name.into(),
        mesh,
        material: Material {
            ke: if light { DVec3::ONE } else { DVec3::ZERO },
            ..Material::default()
        },
        flags: ObjectFlags {
            light,
            occluder: true,
            receiver: true,
            is_static: false,
        },
    };
    Scene {
        objects: vec![
            object(
                "light",
                quad(DVec3::new(0.0, 0.0, 3.0), DVec3::X, -DVec3::Y),
                true,
            ),
            object(
                "hole",
                thesis_polyhedron("hole").unwrap().transformed(&turn),
                false,
            ),
        ],
        ..Scene::default()
    }
}

#[test]
fn the_cache_stays_within_its_bound_and_evicts_the_least_recently_used() {
    let dir = std::env::temp_dir().join(format!("penumbra-cache-bound-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let bound: u64 = 400 << 10;
    let cache = TreeCache {
        dir: dir.clone(),
        max_bytes: bound,
    };
    let prepare = |scene: &Scene| {
        let options = PrepareOptions {
            cache: Some(&cache),
            ..PrepareOptions::default()
        };
        PreparedScene::prepare(scene, options)
    };

    // One scene's files, to learn their size.
    let first = prepare(&scene(0));
    assert!(first.trees_built > 0);
    let per_scene = cache.usage().bytes;
    assert!(per_scene > 0 && per_scene < bound / 3, "{per_scene} bytes");

    // Scene 0 is read again after every new scene: it stays recently used.
    let mut peak = 0;
    for k in 1..40 {
        let p = prepare(&scene(k));
        assert!(p.trees_built > 0, "scene {k} is new");
        peak = peak.max(cache.usage().bytes);
        assert!(cache.usage().bytes <= bound, "after scene {k}");
        let again = prepare(&scene(0));
        assert_eq!(
            again.trees_built, 0,
            "scene 0 is still cached after scene {k}"
        );
    }
    assert!(
        peak > bound - per_scene,
        "the bound was reached ({peak} bytes)"
    );
    // Scene 1 was the least recently used long ago: evicted, so it is built again.
    assert!(prepare(&scene(1)).trees_built > 0);
    // The most recent scene is still there.
    assert_eq!(prepare(&scene(39)).trees_built, 0);

    // A stress run writes nothing to the cache.
    cache.clear();
    let report = penumbra::stress::run(300, 1, 64, None, |_| {});
    assert_eq!(report.cases, 300);
    assert_eq!(cache.usage().files, 0, "stress cases are not cached");
    let _ = std::fs::remove_dir_all(&dir);
}
