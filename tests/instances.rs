//! Instances sharing one silhouette tree under an affine map (`shading::prepared`, 001 Sect.
//! 5.4), against two oracles: the same scene prepared with sharing disabled (every instance its
//! own tree, built in its world frame) renders the same image, and the silhouette read from the
//! shared tree at random points is the one computed on the fly from the instance's own mesh.

use glam::{DAffine3, DVec3};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ExactSilhouetteScratch, Sidedness, SilhouetteScratch, SphericalPolygon, exact_silhouette,
    silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::render::{RenderContext, RenderSettings};
use penumbra::scene::scene_file;
use penumbra::shading::PreparedScene;
use penumbra::shading::instance_map;
use std::sync::Arc;

use crate::silhouette_common;
use silhouette_common::{is_inside, same_loops, triangles};

fn groups_by_name(p: &PreparedScene) -> Vec<(String, usize)> {
    p.tree_groups
        .iter()
        .map(|g| (p.objects[g[0] as usize].name.clone(), g.len()))
        .collect()
}

#[test]
fn the_instances_scene_shares_one_tree_per_mesh() {
    let scene = scene_file::load_embedded("instances").unwrap();
    let p = PreparedScene::new(&scene);
    let groups = groups_by_name(&p);
    // The pillars are boxes: affine images of the cube, so the five share one tree.
    for (name, n) in [("bowl", 3), ("hole", 2), ("cube", 5), ("corner", 2)] {
        assert!(groups.contains(&(name.to_owned(), n)), "{name}: {groups:?}");
    }
    for g in &p.tree_groups {
        let first = &p.objects[g[0] as usize];
        assert!(
            first.to_tree.is_none(),
            "the first member is the tree's frame"
        );
        assert!(first.path.tree().is_some(), "{}", first.name);
        for &m in &g[1..] {
            let o = &p.objects[m as usize];
            assert!(o.to_tree.is_some());
            match (
                first.convex_tree(),
                o.convex_tree(),
                first.exact_tree(),
                o.exact_tree(),
            ) {
                (Some(a), Some(b), None, None) => assert!(Arc::ptr_eq(a, b)),
                (None, None, Some(a), Some(b)) => assert!(Arc::ptr_eq(a, b)),
                _ => panic!("{}: not the same tree as {}", o.name, first.name),
            }
        }
        if g.len() > 1 {
            assert!(
                p.report
                    .lines()
                    .iter()
                    .any(|n| n.contains("share one silhouette tree")
                        && n.contains(&format!("'{}'", first.name))),
                "{:?}",
                p.report.lines()
            );
        }
    }
    let unshared = PreparedScene::prepare(
        &scene,
        penumbra::shading::PrepareOptions {
            share_instances: false,
            ..penumbra::shading::PrepareOptions::default()
        },
    );
    assert!(unshared.tree_groups.iter().all(|g| g.len() == 1));
    assert!(unshared.objects.iter().all(|o| o.to_tree.is_none()));
}

/// The map between instances is found for rotations, uniform and per-axis scales and
/// translations, and refused for a mirror image, for other faces, and for vertices moved by
/// more than the tolerance.
#[test]
fn instance_maps_are_affine_with_positive_determinant() {
    let m = penumbra::scene::thesis_polyhedra::thesis_polyhedron("bowl").unwrap();
    let base = IndexedPolyhedron::new(&m.positions, &m.faces);
    let t = DAffine3::from_translation(DVec3::new(1.0, -2.0, 0.5))
        * DAffine3::from_rotation_y(0.7)
        * DAffine3::from_rotation_x(-0.3)
        * DAffine3::from_scale(DVec3::new(1.3, 0.6, 2.0));
    let moved = m.transformed(&t);
    let other = IndexedPolyhedron::new(&moved.positions, &moved.faces);
    let found = instance_map(&base, &other).expect("an affine instance");
    for (p, q) in base.vertices.iter().zip(&other.vertices) {
        assert!((found.transform_point3(*p) - *q).length() < 1e-12);
        assert!((t.transform_point3(*p) - *q).length() < 1e-12);
    }
    // A mirror image: `transformed` reverses its faces, so they differ.
    let mirrored = m.transformed(&DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)));
    let mirrored = IndexedPolyhedron::new(&mirrored.positions, &mirrored.faces);
    assert!(instance_map(&base, &mirrored).is_none());
    // The mirror image's positions with the original faces: an inside-out mesh, refused.
    let inside_out = IndexedPolyhedron::new(
        &m.transformed(&DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)))
            .positions,
        &m.faces,
    );
    assert!(instance_map(&base, &inside_out).is_none());
    // One vertex off by 1e-6 of the radius.
    let mut nudged = moved.clone();
    nudged.positions[5].y += 1e-6 * other.radius;
    let nudged = IndexedPolyhedron::new(&nudged.positions, &nudged.faces);
    assert!(instance_map(&base, &nudged).is_none());
}

/// Oracle (a): the same scene with sharing disabled. The silhouettes are read off each
/// instance's own vertices either way, so the images differ by rounding only (a loop may start
/// at another vertex): far below any visible or statistical difference.
#[test]
fn an_instanced_scene_renders_as_with_sharing_disabled() {
    let scene = scene_file::load_embedded("instances").unwrap();
    let shared = RenderContext::new(&scene);
    let mut unshared = RenderContext::new(&scene);
    unshared.prepared = PreparedScene::prepare(
        &scene,
        penumbra::shading::PrepareOptions {
            share_instances: false,
            ..penumbra::shading::PrepareOptions::default()
        },
    );
    let cam = scene.camera.unwrap();
    let settings = RenderSettings {
        width: 64,
        height: 48,
        aa: 2,
        ..RenderSettings::default()
    };
    let a = shared.render(&cam, &settings, None).unwrap().0.pixels;
    let b = unshared.render(&cam, &settings, None).unwrap().0.pixels;
    let peak = a.iter().map(|p| p.max_element()).fold(0.0, f64::max);
    assert!(peak > 0.0);
    let mut worst: f64 = 0.0;
    for (p, q) in a.iter().zip(&b) {
        let d = (*p - *q).abs().max_element();
        let scale = p
            .abs()
            .max_element()
            .max(q.abs().max_element())
            .max(1e-3 * peak);
        worst = worst.max(d / scale);
    }
    eprintln!("max relative difference shared vs unshared: {worst:.2e}");
    assert!(worst < 1e-11, "max relative difference {worst:.2e}");
}

/// Oracle (b): at random points of the scene (outside the instance), the silhouette read from
/// the shared tree, looked up at the point mapped into the tree's frame, is the silhouette
/// computed on the fly from the instance's own world-space mesh.
#[test]
fn the_shared_tree_gives_each_instance_its_own_silhouette() {
    let scene = scene_file::load_embedded("instances").unwrap();
    let p = PreparedScene::new(&scene);
    let (lo, hi) = p.bounds;
    let mut rng = Pcg32::new(17, 3);
    let frame = Frame::from_z(DVec3::new(0.3, 0.8, -0.52).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut exact = ExactSilhouetteScratch::default();
    let mut convex = SilhouetteScratch::default();
    let mut instances = 0;
    for g in p.tree_groups.iter().filter(|g| g.len() > 1) {
        for &m in &g[1..] {
            instances += 1;
            let o = &p.objects[m as usize];
            let (mut checked, mut from_tree) = (0, 0);
            let mesh = triangles(&o.poly);
            while checked < 1500 {
                let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
                if is_inside(&mesh, x) {
                    continue;
                }
                let tx = o.tree_point(x);
                if let Some(t) = o.convex_tree() {
                    checked += 1;
                    assert!(
                        t.silhouette_at(&o.poly, x, tx, &frame, &mut a),
                        "{}",
                        o.name
                    );
                    from_tree += 1;
                    silhouette(
                        &o.poly,
                        x,
                        &frame,
                        Sidedness::FrontOnly,
                        &mut b,
                        &mut convex,
                    );
                } else if let Some(t) = o.exact_tree() {
                    if exact_silhouette(&o.poly, x, &frame, &mut b, &mut exact).is_err() {
                        continue;
                    }
                    checked += 1;
                    if !t.silhouette_at(&o.poly, x, tx, &frame, &mut a) {
                        continue; // a leaf left to the on-the-fly path
                    }
                    from_tree += 1;
                }
                assert!(
                    same_loops(&a, &b, 1e-9),
                    "{} at {x}: {:?} vs {:?}",
                    o.name,
                    a.loops().collect::<Vec<_>>(),
                    b.loops().collect::<Vec<_>>()
                );
            }
            eprintln!("{}: {from_tree} of {checked} from the shared tree", o.name);
            assert!(
                from_tree * 10 >= checked * 9,
                "{}: too few from the tree",
                o.name
            );
        }
    }
    assert_eq!(instances, 8);
}
