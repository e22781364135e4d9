//! Scene files and the embedded scenes.

use glam::DVec3;
use penumbra::scene::obj::load_obj_str;
use penumbra::scene::scene_file::{
    embedded_scene_names, load_embedded, load_scene, load_scene_str,
};
use penumbra::scene::{Scene, SceneObject};
use std::path::{Path, PathBuf};

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes")
}

fn obj<'a>(s: &'a Scene, name: &str) -> &'a SceneObject {
    s.object(name)
        .unwrap_or_else(|| panic!("no object '{name}'"))
}

fn counts<'a>(objs: impl Iterator<Item = &'a SceneObject>) -> Vec<(String, usize)> {
    objs.map(|o| (o.name.clone(), o.mesh.positions.len()))
        .collect()
}

fn lowest(o: &SceneObject) -> f64 {
    o.mesh.bounds().unwrap().0.y
}

fn highest(o: &SceneObject) -> f64 {
    o.mesh.bounds().unwrap().1.y
}

#[test]
fn every_embedded_scene_loads_cleanly_and_matches_the_files() {
    assert_eq!(
        embedded_scene_names(),
        [
            "default",
            "fig4",
            "chair",
            "cube",
            "nonconvex",
            "polyhedra",
            "instances",
            "letters",
            "env_figures",
            "env_atrium",
            "env_crowd",
            "glossy"
        ]
    );
    for &name in embedded_scene_names() {
        let s = load_embedded(name).unwrap();
        assert!(s.warnings.is_empty(), "{name}: {:?}", s.warnings);
        let cam = s.camera.expect("camera");
        cam.basis().unwrap();
        // The environment scenes are lit by their sky; their floor is a static occluder.
        let env = s.environment.is_some();
        assert_eq!(env, name.starts_with("env_"), "{name}");
        assert!(env || s.lights().count() >= 1, "{name}");
        // Floor: receiver only, faces up, at y = 0.
        let floor = obj(&s, "floor");
        assert_eq!(
            (
                floor.flags.light,
                floor.flags.occluder,
                floor.flags.receiver,
                floor.flags.is_static
            ),
            (false, env, true, env)
        );
        assert!((floor.mesh.face_normal(0).unwrap() - DVec3::Y).length() < 1e-15);
        for o in &s.objects {
            // Default flags unless overridden: light iff Ke > 0, everything else occludes. The
            // instances scene turns its (emissive) corners into plain occluders.
            let overridden = name == "instances" && o.name == "corner";
            assert_eq!(
                o.flags.light,
                o.material.is_emissive() && !overridden,
                "{}",
                o.name
            );
            assert_eq!(o.flags.occluder, env || o.name != "floor", "{}", o.name);
            assert!(o.flags.receiver);
            assert!(o.mesh.positions.iter().all(|p| p.is_finite()));
            // Everything but the open quads is a closed outward manifold.
            if o.mesh.faces.len() > 1 {
                assert!(o.mesh.is_closed_manifold(), "{name}/{}", o.name);
                assert!(o.mesh.signed_volume() > 0.0, "{name}/{}", o.name);
            }
            assert!(o.mesh.max_face_nonplanarity() < 1e-9, "{name}/{}", o.name);
            // Lights above the floor, above every occluder's top... (checked per scene).
            assert!(lowest(o) >= 0.0, "{name}/{}", o.name);
        }
        // The floor is reasonably exposed: unshadowed irradiance ~ 1 under the scene.
        let e = s.unshadowed_irradiance(DVec3::new(0.0, 0.0, 0.3), DVec3::Y);
        assert!(
            env || (e.min_element() > 0.5 && e.max_element() < 2.0),
            "{name}: {e}"
        );
        // The files on disk are the embedded ones.
        let disk = load_scene(&assets().join(format!("{name}.toml"))).unwrap();
        assert_eq!(disk.camera, s.camera);
        assert_eq!(disk.objects.len(), s.objects.len());
        for (a, b) in disk.objects.iter().zip(&s.objects) {
            assert_eq!(
                (&a.name, &a.mesh, &a.material),
                (&b.name, &b.mesh, &b.material)
            );
            assert_eq!(a.flags, b.flags);
        }
    }
    assert!(load_embedded("fig4.toml").is_ok());
    let e = load_embedded("nope").unwrap_err().to_string();
    assert!(e.contains("nope") && e.contains("fig4"), "{e}");
}

#[test]
fn fig4_matches_the_paper() {
    let s = load_embedded("fig4").unwrap();
    let lights = counts(s.lights());
    assert_eq!(
        lights,
        [
            ("light_plane".to_owned(), 4),
            ("light_cylinder".to_owned(), 20),
            ("light_cone".to_owned(), 20)
        ]
    );
    let occluders = counts(s.occluders().filter(|o| !o.flags.light));
    assert_eq!(
        occluders,
        [
            ("cube".to_owned(), 8),
            ("icosphere".to_owned(), 16),
            ("ellipsoid".to_owned(), 154)
        ]
    );
    // Lambertian only.
    for o in &s.objects {
        assert_eq!(o.material.ks, DVec3::ZERO, "{}", o.name);
    }
    // Convex lights and occluders; the plane light faces down.
    for name in [
        "light_cylinder",
        "light_cone",
        "cube",
        "icosphere",
        "ellipsoid",
    ] {
        assert!(obj(&s, name).mesh.is_convex(1e-9), "{name}");
    }
    let plane = obj(&s, "light_plane");
    assert!((plane.mesh.face_normal(0).unwrap() + DVec3::Y).length() < 1e-15);
    // Lights above the occluders, occluders above the floor.
    let top = s
        .occluders()
        .filter(|o| !o.flags.light)
        .map(highest)
        .fold(0.0, f64::max);
    for l in s.lights() {
        assert!(lowest(l) > top + 1.0, "{}", l.name);
    }
    for o in s.occluders().filter(|o| !o.flags.light) {
        assert!(lowest(o) > 0.3, "{}", o.name);
    }
}

#[test]
fn default_scene_contents() {
    let s = load_embedded("default").unwrap();
    let parts = [
        "leg_front_left",
        "leg_front_right",
        "leg_back_left",
        "leg_back_right",
        "seat",
        "back",
    ];
    for p in parts {
        let o = obj(&s, p);
        assert_eq!(o.mesh.positions.len(), 8, "{p}");
        assert!(o.mesh.is_convex(1e-12) && o.flags.occluder && !o.flags.light);
    }
    let panel = obj(&s, "panel_light");
    assert_eq!(panel.mesh.positions.len(), 4);
    assert!(panel.flags.light);
    // It faces down (and tilts towards the chair).
    assert!(panel.mesh.face_normal(0).unwrap().y < -0.8);
    let tube = obj(&s, "tube_light");
    assert_eq!(tube.mesh.positions.len(), 32);
    assert!(tube.flags.light && tube.mesh.is_convex(1e-12));
    assert_eq!(s.lights().count(), 2);
    // Specular somewhere: the sphere and the floor are glossy.
    let sphere = obj(&s, "sphere");
    assert!(sphere.material.has_specular() && sphere.material.alpha < 0.2);
    assert!(obj(&s, "floor").material.has_specular());
    assert!(!obj(&s, "seat").material.has_specular());
    // Lights are above the chair.
    for l in s.lights() {
        assert!(lowest(l) > highest(obj(&s, "back")), "{}", l.name);
    }
}

#[test]
fn chair_and_nonconvex_scenes() {
    let s = load_embedded("chair").unwrap();
    assert_eq!(counts(s.lights()), [("light".to_owned(), 4)]);
    let boxes: Vec<_> = s.occluders().filter(|o| !o.flags.light).collect();
    assert_eq!(boxes.len(), 6);
    assert!(
        boxes
            .iter()
            .all(|o| o.mesh.positions.len() == 8 && o.mesh.is_convex(1e-12))
    );
    assert!(s.objects.iter().all(|o| !o.material.has_specular()));

    let s = load_embedded("nonconvex").unwrap();
    let l = obj(&s, "l_occluder");
    let u = obj(&s, "u_light");
    assert!(l.flags.occluder && !l.flags.light && !l.mesh.is_convex(1e-9));
    assert!(u.flags.light && !u.mesh.is_convex(1e-9));
    assert_eq!((l.mesh.positions.len(), u.mesh.positions.len()), (12, 16));
    assert!(lowest(u) > highest(l));
    assert!(s.objects.iter().all(|o| !o.material.has_specular()));
}

// ---------------------------------------------------------------------------------------------
// The scene-file format
// ---------------------------------------------------------------------------------------------

const BOX_OBJ: &str = "\
mtllib b.mtl
o b
v 0 0 1
v 0 1 1
v 1 0 1
f 1 2 3
o a
v 0 0 0
v 1 0 0
v 0 1 0
usemtl lamp
f 4 5 6
";

fn memory_loader(rel: &str) -> Result<Scene, penumbra::Error> {
    match rel {
        "box.obj" => load_obj_str(BOX_OBJ, Some("newmtl lamp\nKe 2 2 2\n"), "box.obj"),
        other => Err(penumbra::Error::File {
            file: other.to_owned(),
            message: "no such file".into(),
        }),
    }
}

fn scene(text: &str) -> Result<Scene, penumbra::Error> {
    load_scene_str(text, "mem.toml", &memory_loader)
}

fn err_line(text: &str) -> (usize, String) {
    match scene(text) {
        Err(e @ penumbra::Error::Line { .. }) => {
            let msg = e.to_string();
            let penumbra::Error::Line { file, line, .. } = e else {
                unreachable!()
            };
            assert_eq!(file, "mem.toml", "{msg}");
            assert!(msg.starts_with(&format!("mem.toml:{line}: ")), "{msg}");
            (line, msg)
        }
        Err(e) => panic!("error without a line: {e}"),
        Ok(_) => panic!("no error for {text}"),
    }
}

#[test]
fn scene_file_selection_flags_and_transforms() {
    let s = scene(
        r#"
[camera]
eye = [0, 1, 5]
target = [0, 0, 0]
fov = 30

[[object]]
obj = "box.obj"

[[object]]
obj = "box.obj"
name = "b"
light = true
occluder = false
receiver = false
scale = [-2, 1, 1]
translate = [10, 0, 0]

[[object]]
obj = "box.obj"
name = "a"
light = false
scale = 3
"#,
    )
    .unwrap();
    let cam = s.camera.unwrap();
    assert_eq!(cam.up, DVec3::Y);
    assert_eq!(cam.fov_deg, 30.0);
    let names: Vec<_> = s.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["b", "a", "b", "a"]);
    assert!(!s.objects[0].flags.light && s.objects[1].flags.light);
    let b = &s.objects[2];
    assert_eq!(
        (b.flags.light, b.flags.occluder, b.flags.receiver),
        (true, false, false)
    );
    // Mirrored by the negative scale, then moved: the winding is flipped to keep the front.
    let orig = &s.objects[0];
    assert_eq!(b.mesh.positions[2], DVec3::new(8.0, 0.0, 1.0));
    let n0 = orig.mesh.face_normal(0).unwrap();
    let n1 = b.mesh.face_normal(0).unwrap();
    assert!((n1 - DVec3::new(-n0.x, n0.y, n0.z)).length() < 1e-15);
    // "light = true" on a non-emitter warns with the line.
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("mem.toml:13: ") && w.contains("Ke")),
        "{:?}",
        s.warnings
    );
    let a = &s.objects[3];
    assert!(!a.flags.light && a.material.is_emissive());
    assert_eq!(a.mesh.positions[1], DVec3::new(3.0, 0.0, 0.0));
}

/// `rotate` comes after `scale` and before `translate`; a quarter turn about y maps
/// (x, y, z) to (z, y, −x) (checked coordinate by coordinate), and the Euler form about one
/// axis is the axis-angle form about that axis.
#[test]
fn scene_file_rotate_between_scale_and_translate() {
    let s = scene(
        r#"
[[object]]
obj = "box.obj"
name = "a"

[[object]]
obj = "box.obj"
name = "a"
scale = 2
rotate = [0, 90, 0]
translate = [10, 0, 0]

[[object]]
obj = "box.obj"
name = "a"
scale = 2
rotate = { axis = [0, 3, 0], angle = 90 }
translate = [10, 0, 0]
"#,
    )
    .unwrap();
    let (orig, euler, axis) = (&s.objects[0], &s.objects[1], &s.objects[2]);
    for ((p, q), r) in orig
        .mesh
        .positions
        .iter()
        .zip(&euler.mesh.positions)
        .zip(&axis.mesh.positions)
    {
        let want = DVec3::new(2.0 * p.z + 10.0, 2.0 * p.y, -2.0 * p.x);
        assert!((*q - want).length() < 1e-14, "{q} vs {want}");
        assert!((*r - want).length() < 1e-14, "{r} vs {want}");
    }
    // A rotation keeps the winding: the faces are the same indices.
    assert_eq!(orig.mesh.faces, euler.mesh.faces);
}

#[test]
fn scene_file_errors_name_file_and_line() {
    let (l, m) = err_line("[camera]\neye = [0, 1, 5]\ntarget = [0, 0,, 1]\nfov = 3\n");
    assert_eq!(l, 3, "{m}");
    let (l, m) = err_line("\n[[object]]\nobj = \"box.obj\"\nocluder = false\n");
    assert_eq!(l, 4, "{m}");
    assert!(m.contains("ocluder"), "{m}");
    let (l, _) = err_line("[[object]]\nobj = \"box.obj\"\n\nlight = \"yes\"\n");
    assert_eq!(l, 4);
    let (l, _) = err_line("[[object]]\nobj = 5\n");
    assert_eq!(l, 2);
    let (l, m) = err_line("[[object]]\n\nname = \"a\"\n");
    assert!(m.contains("obj"), "{m}");
    assert!(l <= 3, "{m}");
    let (l, m) = err_line("[[object]]\nobj = \"box.obj\"\nname = \"zz\"\n");
    assert_eq!(l, 3);
    assert!(m.contains("zz") && m.contains("b, a"), "{m}");
    let (l, _) = err_line("[[object]]\nobj = \"box.obj\"\nscale = [1, 0, 1]\n");
    assert_eq!(l, 3);
    let (l, m) = err_line("[[object]]\nobj = \"box.obj\"\nscale = \"big\"\n");
    assert_eq!(l, 3);
    assert!(m.contains("scale must be"), "{m}");
    // rotate: a wrong form, non-finite angles, a zero axis, unknown keys.
    for bad in [
        "rotate = [1, 2]",
        "rotate = \"x\"",
        "rotate = [0, nan, 0]",
        "rotate = { axis = [0, 0, 0], angle = 10 }",
        "rotate = { axis = [0, 1, 0], angle = inf }",
        "rotate = { axis = [0, 1, 0], angel = 10 }",
    ] {
        let (l, m) = err_line(&format!("[[object]]\nobj = \"box.obj\"\n\n{bad}\n"));
        assert_eq!(l, 4, "{bad}: {m}");
        assert!(m.contains("rotat"), "{bad}: {m}");
    }
    let (l, _) = err_line("[[object]]\nobj = \"box.obj\"\ntranslate = [1, 2]\n");
    assert_eq!(l, 3);
    let (l, _) = err_line("[[object]]\nobj = \"box.obj\"\ntranslate = [1, 2, inf]\n");
    assert_eq!(l, 3);
    let (l, m) = err_line("\n[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 0]\nfov = 40\n");
    assert!((2..=5).contains(&l), "{m}");
    assert!(m.contains("camera"), "{m}");
    let (l, _) = err_line("[camera]\neye = [0, 0, 1]\ntarget = [0, 0, 0]\nfov = 200\n");
    assert!((1..=4).contains(&l));
    let (l, _) = err_line("[[objects]]\nobj = \"box.obj\"\n");
    assert_eq!(l, 1);
    // Garbage never panics.
    for text in [
        "",
        "[[object]]",
        "=",
        "[camera]\n",
        "\u{0}",
        "[[object]]\nobj = \"\"\n",
    ] {
        let _ = scene(text);
    }
}

#[test]
fn scene_files_on_disk() {
    let dir = std::env::temp_dir().join(format!("penumbra_scene_test_{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/box.obj"), BOX_OBJ).unwrap();
    std::fs::write(dir.join("sub/b.mtl"), "newmtl lamp\nKe 1 1 1\n").unwrap();
    let toml = dir.join("s.toml");
    std::fs::write(&toml, "[[object]]\nobj = \"sub/box.obj\"\n").unwrap();
    let s = load_scene(&toml).unwrap();
    assert_eq!(s.objects.len(), 2);
    assert!(s.objects[1].flags.light && !s.objects[0].flags.light);
    assert!(s.camera.is_none());
    // A missing OBJ: the error names the TOML line and the OBJ path.
    std::fs::write(&toml, "\n[[object]]\nobj = \"sub/nothere.obj\"\n").unwrap();
    let e = load_scene(&toml).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, penumbra::Error::Line { line: 3, .. }), "{m}");
    assert!(m.contains("s.toml") && m.contains("nothere.obj"), "{m}");
    // A bad OBJ: the error names the OBJ and its line.
    std::fs::write(dir.join("sub/bad.obj"), "v 0 0 0\nv 1 0 zz\n").unwrap();
    std::fs::write(&toml, "[[object]]\nobj = \"sub/bad.obj\"\n").unwrap();
    let m = load_scene(&toml).unwrap_err().to_string();
    assert!(m.contains("bad.obj:2:"), "{m}");
    // Plain OBJ and unknown extensions.
    let s = load_scene(&dir.join("sub/box.obj")).unwrap();
    assert_eq!(s.objects.len(), 2);
    let m = load_scene(&dir.join("x.ply")).unwrap_err().to_string();
    assert!(m.contains("x.ply"), "{m}");
    let m = load_scene(&dir.join("missing.toml"))
        .unwrap_err()
        .to_string();
    assert!(m.contains("missing.toml"), "{m}");
    std::fs::remove_dir_all(&dir).ok();
}
