//! Rigid edits (`scene::edit`), the cheap re-prepare after one (`RenderContext::
//! with_moved_object`) and saving (`scene::save`): a context re-prepared after a move renders
//! and probes what a context prepared from scratch on the moved scene does, in f64, to 1e-12
//! relative; a saved scene loads back with the same vertices, materials, flags and camera and
//! renders the same values; `penumbra edit` does one edit and saves.

use glam::DVec3;
use penumbra::inspect::probe;
use penumbra::render::{RenderContext, RenderSettings};
use penumbra::scene::edit::{EditHistory, Rigid, resolve_object};
use penumbra::scene::{Camera, Scene, scene_file};
use penumbra::shading::{Method, MoveReuse, PathKind};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `a` and `b` agree to 1e-12 relative (an absolute floor of 1e-15 for values near zero).
fn close(a: DVec3, b: DVec3) -> bool {
    (0..3).all(|k| {
        let (x, y) = (a[k], b[k]);
        (x - y).abs() <= 1e-12 * x.abs().max(y.abs()) + 1e-15
    })
}

const SIZE: (u32, u32) = (40, 30);

/// Pixels of a `SIZE` image to probe: a grid over the image.
fn probe_pixels() -> Vec<(f64, f64)> {
    let mut v = Vec::new();
    for y in [3.0, 11.0, 17.0, 26.0] {
        for x in [4.0, 13.0, 20.0, 27.0, 36.0] {
            v.push((x, y));
        }
    }
    v
}

/// Compares the image and the probes of two contexts of the same scene.
fn assert_same(moved: &RenderContext, fresh: &RenderContext, camera: &Camera, what: &str) {
    let settings = RenderSettings {
        width: SIZE.0,
        height: SIZE.1,
        ..RenderSettings::default()
    };
    let (a, _) = moved.render(camera, &settings, None).unwrap();
    let (b, _) = fresh.render(camera, &settings, None).unwrap();
    let mut worst = (0.0f64, 0usize);
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        assert!(
            close(*p, *q),
            "{what}: pixel {} of the moved context {p} != {q} from scratch",
            i
        );
        let d = (*p - *q).abs().max_element();
        if d > worst.0 {
            worst = (d, i);
        }
    }
    assert!(
        a.pixels.iter().any(|p| p.max_element() > 0.0),
        "{what}: the image is not black"
    );
    for px in probe_pixels() {
        let pa = probe(moved, what, camera, SIZE, px, Method::Analytic, false).unwrap();
        let pb = probe(fresh, what, camera, SIZE, px, Method::Analytic, false).unwrap();
        assert!(
            close(pa.radiance, pb.radiance),
            "{what}: probe {px:?}: {} != {}",
            pa.radiance,
            pb.radiance
        );
        assert_eq!(pa.point.map(|p| p.object), pb.point.map(|p| p.object));
        assert_eq!(pa.lights.len(), pb.lights.len());
        for (la, lb) in pa.lights.iter().zip(&pb.lights) {
            assert!(close(la.shadowed, lb.shadowed), "{what}: probe {px:?}");
            assert!(close(la.unshadowed, lb.unshadowed), "{what}: probe {px:?}");
            let (sa, sb) = (la.visible_solid_angle, lb.visible_solid_angle);
            assert!(
                (sa - sb).abs() <= 1e-12 * sa.abs().max(sb.abs()) + 1e-15,
                "{what}: probe {px:?}: visible solid angle {sa} != {sb}"
            );
        }
    }
}

/// Moves object `name` of `scene` by `motion` (about its pivot when `about_pivot`), through
/// the edit history, and checks the re-prepared context against one from scratch. Returns
/// how the moved object's data were reused.
fn check_move(scene: Scene, name: &str, rotate_deg: f64, translate: DVec3) -> MoveReuse {
    let camera = scene.camera.unwrap();
    let base = Arc::new(scene);
    let ctx = RenderContext::from_arc(base.clone());
    let index = resolve_object(&base, name).unwrap();
    let mut history = EditHistory::new(&base);
    let pivot = history.begin_drag(index).unwrap();
    // A few frames of a drag, each re-prepared from the previous context, as the workbench does.
    let mut current = ctx;
    let mut scene = base.clone();
    for k in 1..=3 {
        let f = k as f64 / 3.0;
        let r = Rigid::rotation_about(pivot, DVec3::Y, (f * rotate_deg).to_radians()).unwrap();
        history
            .update_drag(r.then(Rigid::translation(f * translate)))
            .unwrap();
        scene = Arc::new(history.moved_scene(&base, index).unwrap());
        current = current.with_moved_object(index, scene.clone()).unwrap();
    }
    assert!(history.end_drag().is_some());
    let (_, reuse) = RenderContext::from_arc(base.clone())
        .prepared
        .with_moved_object(&scene, index)
        .unwrap();
    let fresh = RenderContext::from_arc(scene.clone());
    // The moved object takes the path it takes from scratch.
    let path = |c: &RenderContext| {
        c.prepared
            .objects
            .iter()
            .find(|o| o.object == index as u32)
            .map(|o| o.kind())
    };
    assert_eq!(path(&current), path(&fresh), "{name}: path");
    let what = format!("{name} rotated {rotate_deg}°, moved by {translate}");
    assert_same(&current, &fresh, &camera, &what);
    // Undo gives the original scene back, bit for bit.
    let mut s = (*scene).clone();
    assert_eq!(history.undo(&mut s).unwrap(), Some(index));
    assert_eq!(
        s.objects[index].mesh.positions,
        base.objects[index].mesh.positions
    );
    reuse
}

fn embedded(name: &str) -> Scene {
    scene_file::load_embedded(name).unwrap()
}

#[test]
fn default_occluder_translated_and_rotated() {
    // The chair's back: a convex box that reads its silhouettes from a BSP tree.
    let scene = embedded("default");
    let ctx = RenderContext::new(&scene);
    let back = ctx
        .prepared
        .objects
        .iter()
        .find(|o| o.name == "back")
        .unwrap();
    assert_eq!(back.kind(), PathKind::ConvexTree);
    let r = check_move(
        embedded("default"),
        "back",
        0.0,
        DVec3::new(0.15, 0.05, -0.1),
    );
    assert_eq!(r, MoveReuse::Trees);
    let r = check_move(embedded("default"), "back", 35.0, DVec3::ZERO);
    assert_eq!(r, MoveReuse::Trees);
    let r = check_move(
        embedded("default"),
        "sphere",
        -20.0,
        DVec3::new(-0.2, 0.0, 0.1),
    );
    assert!(matches!(r, MoveReuse::Trees | MoveReuse::NoTree));
}

#[test]
fn default_lights_translated_and_rotated() {
    // The panel is flat (no tree); the tube is convex and reads a BSP tree.
    check_move(
        embedded("default"),
        "panel_light",
        0.0,
        DVec3::new(0.2, -0.1, 0.1),
    );
    check_move(embedded("default"), "panel_light", 25.0, DVec3::ZERO);
    let r = check_move(
        embedded("default"),
        "tube_light",
        30.0,
        DVec3::new(0.0, 0.1, 0.2),
    );
    assert_eq!(r, MoveReuse::Trees);
}

#[test]
fn exact_silhouette_trees_move_with_their_mesh() {
    // The L-shaped occluder and the U-shaped light read exact silhouettes from BSP trees.
    let scene = embedded("nonconvex");
    let ctx = RenderContext::new(&scene);
    for o in &ctx.prepared.objects {
        assert_eq!(o.kind(), PathKind::ExactTree, "{}", o.name);
    }
    let occluder = ctx.prepared.objects[ctx.prepared.occluders[0] as usize]
        .name
        .clone();
    let light = ctx.prepared.objects[ctx.prepared.lights[0].0 as usize]
        .name
        .clone();
    assert_eq!(
        check_move(
            embedded("nonconvex"),
            &occluder,
            40.0,
            DVec3::new(0.1, 0.0, -0.1)
        ),
        MoveReuse::Trees
    );
    assert_eq!(
        check_move(
            embedded("nonconvex"),
            &light,
            -30.0,
            DVec3::new(0.0, 0.05, 0.1)
        ),
        MoveReuse::Trees
    );
}

#[test]
fn moved_trees_are_shared_not_rebuilt() {
    let scene = Arc::new(embedded("default"));
    let ctx = RenderContext::from_arc(scene.clone());
    let index = resolve_object(&scene, "seat").unwrap();
    let mut history = EditHistory::new(&scene);
    let mut moved = (*scene).clone();
    history
        .edit(
            &mut moved,
            index,
            Rigid::translation(DVec3::new(0.1, 0.0, 0.0)),
        )
        .unwrap();
    let next = ctx.with_moved_object(index, Arc::new(moved)).unwrap();
    for (a, b) in ctx.prepared.objects.iter().zip(&next.prepared.objects) {
        match (a.convex_tree(), b.convex_tree()) {
            (Some(x), Some(y)) => assert!(Arc::ptr_eq(x, y), "{}", a.name),
            (None, None) => {}
            _ => panic!("{}: a tree appeared or vanished", a.name),
        }
    }
    assert_eq!(next.prepared.trees_built, 0);
    assert!(next.bvh.refits() > 0, "the BVH is refit, not rebuilt");
    // Bad input is an error, not a panic.
    assert!(ctx.with_moved_object(99, scene.clone()).is_err());
    let mut fewer = (*scene).clone();
    fewer.objects.pop();
    assert!(ctx.with_moved_object(0, Arc::new(fewer)).is_err());
}

fn bunny_scene() -> Option<Scene> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/bunny.toml");
    p.is_file()
        .then(|| scene_file::load_scene(&p).expect("the bunny scene loads"))
}

#[test]
fn scanned_mesh_moves() {
    let Some(scene) = bunny_scene() else {
        eprintln!("assets/scenes/bunny.toml not found: skipped");
        return;
    };
    check_move(scene, "bunny", 25.0, DVec3::new(0.03, 0.0, -0.02));
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-edit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every face as the sequence of its vertices' positions.
fn face_positions(s: &Scene, i: usize) -> Vec<Vec<DVec3>> {
    let m = &s.objects[i].mesh;
    m.faces
        .iter()
        .map(|f| f.iter().map(|&k| m.positions[k as usize]).collect())
        .collect()
}

#[test]
fn saved_scenes_load_back_the_same() {
    let dir = temp("save");
    for name in ["default", "instances", "env_figures"] {
        let mut scene = embedded(name);
        let mut history = EditHistory::new(&scene);
        let index = scene.objects.len() - 1;
        let pivot = history.pivot(index).unwrap();
        let motion = Rigid::rotation_about(pivot, DVec3::Y, 0.4)
            .unwrap()
            .then(Rigid::translation(DVec3::new(0.05, 0.0, -0.07)));
        history.edit(&mut scene, index, motion).unwrap();
        let path = dir.join(format!("{name}_edited.toml"));
        let saved =
            penumbra::scene::save::save_scene(&scene, scene.camera.as_ref(), &path).unwrap();
        let back = scene_file::load_scene(&saved.toml).unwrap();
        assert_eq!(back.camera, scene.camera, "{name}: camera");
        assert_eq!(back.objects.len(), scene.objects.len(), "{name}");
        assert_eq!(
            back.environment.is_some(),
            scene.environment.is_some(),
            "{name}"
        );
        for (i, (a, b)) in scene.objects.iter().zip(&back.objects).enumerate() {
            assert_eq!(a.material, b.material, "{name}: {}", a.name);
            assert_eq!(a.flags, b.flags, "{name}: {}", a.name);
            assert_eq!(a.mesh.rounding, b.mesh.rounding, "{name}: {}", a.name);
            let (fa, fb) = (face_positions(&scene, i), face_positions(&back, i));
            assert_eq!(fa.len(), fb.len(), "{name}: {}", a.name);
            for (x, y) in fa.iter().flatten().zip(fb.iter().flatten()) {
                assert!((*x - *y).length() <= 1e-9, "{name}: {}", a.name);
            }
            // Loaded meshes list their vertices in the order the faces use them: bit for bit.
            assert_eq!(a.mesh.positions, b.mesh.positions, "{name}: {}", a.name);
            assert_eq!(a.mesh.faces, b.mesh.faces, "{name}: {}", a.name);
        }
        if name == "default" {
            let camera = scene.camera.unwrap();
            let a = RenderContext::new(&scene);
            let b = RenderContext::new(&back);
            for px in probe_pixels() {
                let pa = probe(&a, name, &camera, SIZE, px, Method::Analytic, false).unwrap();
                let pb = probe(&b, name, &camera, SIZE, px, Method::Analytic, false).unwrap();
                assert!(close(pa.radiance, pb.radiance), "{name}: probe {px:?}");
            }
        }
    }
}

#[test]
fn cli_edit_moves_and_saves() {
    let dir = temp("cli");
    let out = dir.join("moved.toml");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "edit",
            "default",
            "--move",
            "seat",
            "--translate",
            "-0.1,0,0.2",
            "--rotate-y",
            "-30",
            "--out",
            out.to_str().unwrap(),
        ])
        .env("PENUMBRA_CACHE_DIR", dir.join("cache"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let original = embedded("default");
    let moved = scene_file::load_scene(&out).unwrap();
    let i = resolve_object(&original, "seat").unwrap();
    let mut expected = original.clone();
    let mut h = EditHistory::new(&original);
    let pivot = h.pivot(i).unwrap();
    let motion = Rigid::rotation_about(pivot, DVec3::Y, (-30.0f64).to_radians())
        .unwrap()
        .then(Rigid::translation(DVec3::new(-0.1, 0.0, 0.2)));
    h.edit(&mut expected, i, motion).unwrap();
    assert_eq!(
        moved.objects[i].mesh.positions,
        expected.objects[i].mesh.positions
    );
    for (k, (a, b)) in original.objects.iter().zip(&moved.objects).enumerate() {
        if k != i {
            assert_eq!(a.mesh.positions, b.mesh.positions);
        }
    }
    // An object index out of range is one readable error.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["edit", "default", "--move", "42", "--out"])
        .arg(dir.join("x.toml"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("out of range"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

// ---------------------------------------------------------------------------------------------
// The edit history on small scenes
// ---------------------------------------------------------------------------------------------

mod history {
    use glam::DVec3;
    use penumbra::scene::edit::{EditHistory, Rigid, resolve_object};
    use penumbra::scene::{Material, Mesh, ObjectFlags, Scene, SceneObject, shapes};
    use penumbra::{EditError, Error};

    fn step(k: u32) -> f64 {
        0.01 * k as f64
    }

    fn scene() -> Scene {
        let obj = |name: &str, mesh: Mesh| SceneObject {
            name: name.into(),
            mesh,
            material: Material::default(),
            flags: ObjectFlags {
                light: false,
                occluder: true,
                receiver: true,
                is_static: false,
            },
        };
        Scene {
            objects: vec![
                obj(
                    "a",
                    shapes::cuboid(DVec3::new(1.0, 0.5, 0.0), DVec3::splat(0.25)),
                ),
                obj("b", shapes::icosahedron(DVec3::ZERO, 0.3)),
            ],
            ..Scene::default()
        }
    }

    #[test]
    fn compose_and_inverse() {
        let a = Rigid::rotation_about(DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 1.0, 0.0), 0.7)
            .unwrap();
        let b = Rigid::translation(DVec3::new(-0.5, 0.25, 2.0))
            .then(Rigid::rotation(DVec3::Z, -1.1).unwrap());
        let p = DVec3::new(0.3, -0.2, 0.9);
        let ab = b.after(&a);
        assert!((ab.apply(p) - b.apply(a.apply(p))).length() < 1e-14);
        assert!((a.inverse().apply(a.apply(p)) - p).length() < 1e-14);
        // The pivot stays put.
        let c = DVec3::new(1.0, 2.0, 3.0);
        assert!((a.apply(c) - c).length() < 1e-14);
        assert!(Rigid::rotation(DVec3::ZERO, 1.0).is_err());
        assert!(Rigid::rotation(DVec3::X, f64::NAN).is_err());
    }

    #[test]
    fn a_drag_is_one_step_and_undo_redo_are_exact() {
        let mut s = scene();
        let original = s.clone();
        let mut h = EditHistory::new(&s);
        let pivot = h.begin_drag(0).unwrap();
        assert!((pivot - DVec3::new(1.0, 0.5, 0.0)).length() < 1e-15);
        for k in 1..=20 {
            let r = Rigid::rotation_about(pivot, DVec3::Y, 0.05 * k as f64).unwrap();
            h.update_drag(r.then(Rigid::translation(DVec3::X * step(k))))
                .unwrap();
            h.apply(&mut s, 0).unwrap();
        }
        assert!(h.end_drag().is_some());
        assert_eq!(h.undo_steps().len(), 1);
        let moved = s.objects[0].mesh.positions.clone();
        assert_ne!(moved, original.objects[0].mesh.positions);
        // The same final motion in one update gives the same vertices, bit for bit.
        let mut h2 = EditHistory::new(&original);
        let mut s2 = original.clone();
        let r = Rigid::rotation_about(pivot, DVec3::Y, 0.05 * 20.0f64).unwrap();
        h2.edit(&mut s2, 0, r.then(Rigid::translation(DVec3::X * step(20))))
            .unwrap();
        assert_eq!(s2.objects[0].mesh.positions, moved);

        assert_eq!(h.undo(&mut s).unwrap(), Some(0));
        assert_eq!(
            s.objects[0].mesh.positions,
            original.objects[0].mesh.positions
        );
        assert_eq!(h.undo(&mut s).unwrap(), None);
        assert_eq!(h.redo(&mut s).unwrap(), Some(0));
        assert_eq!(s.objects[0].mesh.positions, moved);
        // Many undo/redo cycles do not drift.
        for _ in 0..50 {
            h.undo(&mut s).unwrap();
            h.redo(&mut s).unwrap();
        }
        assert_eq!(s.objects[0].mesh.positions, moved);
        assert_eq!(
            s.objects[1].mesh.positions,
            original.objects[1].mesh.positions
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut s = scene();
        let mut h = EditHistory::new(&s);
        assert_eq!(
            h.begin_drag(7),
            Err(Error::Edit(EditError::ObjectOutOfRange {
                index: 7,
                count: 2
            }))
        );
        assert_eq!(
            h.update_drag(Rigid::IDENTITY),
            Err(Error::Edit(EditError::NoDrag))
        );
        h.begin_drag(1).unwrap();
        let bad = Rigid::translation(DVec3::new(f64::INFINITY, 0.0, 0.0));
        assert_eq!(h.update_drag(bad), Err(Error::Edit(EditError::NotFinite)));
        assert_eq!(h.end_drag(), None); // no motion, no step
        assert!(h.edit(&mut s, 5, Rigid::IDENTITY).is_err());
        let mut other = s.clone();
        other.objects.pop();
        assert!(h.undo(&mut other).is_err());
        assert_eq!(resolve_object(&s, "b"), Ok(1));
        assert_eq!(resolve_object(&s, "0"), Ok(0));
        assert!(resolve_object(&s, "9").is_err());
        assert!(resolve_object(&s, "zz").is_err());
    }
}
