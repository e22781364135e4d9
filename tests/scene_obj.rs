//! OBJ/MTL loading: conventions, errors with file and line, repairs, robustness.

use glam::DVec3;
use penumbra::math::Pcg32;
use penumbra::scene::Scene;
use penumbra::scene::obj::{load_obj, load_obj_str};
use std::path::PathBuf;

const CUBE: &str = "\
# a unit cube and a quad light
mtllib test.mtl
o box
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
usemtl shiny
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
o lamp
v 0 3 0
v 1 3 0
v 1 3 1
v 0 3 1
usemtl glow
f -4 -3 -2 -1
";

const MTL: &str = "\
newmtl shiny
Kd 0.5 0.25 0.125
Ks 0.04 0.04 0.04
Ns 10
Pr 0.3
newmtl glow
Kd 0
Ke 5 4 3
newmtl phong
Kd 0.7
Ks 0.5 0.5 0.5
Ns 98
";

fn load(obj: &str, mtl: Option<&str>) -> Result<Scene, penumbra::Error> {
    load_obj_str(obj, mtl, "test.obj")
}

fn expect_line_error(obj: &str, mtl: Option<&str>, file: &str, line: usize) -> String {
    match load(obj, mtl) {
        Err(e @ penumbra::Error::Line { .. }) => {
            let msg = e.to_string();
            let penumbra::Error::Line {
                file: f, line: l, ..
            } = &e
            else {
                unreachable!()
            };
            assert_eq!((f.as_str(), *l), (file, line), "{msg}");
            assert!(msg.starts_with(&format!("{file}:{line}: ")), "{msg}");
            msg
        }
        Err(e) => panic!("expected an error with a line, got {e}"),
        Ok(_) => panic!("expected an error at {file}:{line}"),
    }
}

#[test]
fn objects_materials_and_flags() {
    let s = load(CUBE, Some(MTL)).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.objects.len(), 2);
    let b = &s.objects[0];
    assert_eq!(b.name, "box");
    assert_eq!((b.mesh.positions.len(), b.mesh.faces.len()), (8, 6));
    assert!(b.mesh.faces.iter().all(|f| f.len() == 4));
    assert!(b.mesh.is_closed_manifold());
    assert!((b.mesh.signed_volume() - 1.0).abs() < 1e-12);
    assert_eq!(b.material.name, "shiny");
    assert_eq!(b.material.kd, DVec3::new(0.5, 0.25, 0.125));
    assert_eq!(b.material.ks, DVec3::splat(0.04));
    // Pr wins over Ns: alpha = Pr^2, exact in f64.
    assert_eq!(b.material.alpha, 0.3 * 0.3);
    assert_eq!(b.material.ke, DVec3::ZERO);
    assert!(!b.flags.light && b.flags.occluder && b.flags.receiver);

    let l = &s.objects[1];
    assert_eq!(l.name, "lamp");
    assert_eq!(l.mesh.positions.len(), 4);
    assert_eq!(l.mesh.faces, vec![vec![0, 1, 2, 3]]);
    assert_eq!(l.material.ke, DVec3::new(5.0, 4.0, 3.0));
    assert_eq!(l.material.kd, DVec3::ZERO); // "Kd 0" = grey 0
    assert_eq!(l.material.alpha, 1.0); // neither Pr nor Ns
    assert!(l.flags.light && l.flags.occluder && l.flags.receiver);
    // The lamp's front faces down: (1,0,0) x (0,0,1) = -y.
    assert!((l.mesh.face_normal(0).unwrap() - DVec3::NEG_Y).length() < 1e-15);
}

#[test]
fn ns_fallback_and_grey_kd() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl phong\nf 1 2 3\n";
    let s = load(obj, Some(MTL)).unwrap();
    let m = &s.objects[0].material;
    assert_eq!(m.kd, DVec3::splat(0.7));
    assert!((m.alpha - (2.0f64 / 100.0).sqrt()).abs() < 1e-15);
    assert_eq!(s.objects[0].name, "unnamed_object");
}

#[test]
fn inline_mtl_without_mtllib_and_missing_mtl() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glow\nf 1 2 3\n";
    let s = load(obj, Some(MTL)).unwrap();
    assert!(s.objects[0].flags.light);
    // Without MTL text: warning naming the file and line, default material.
    let s = load(CUBE, None).unwrap();
    assert_eq!(s.objects.len(), 2);
    assert!(s.objects.iter().all(|o| o.material == Default::default()));
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("test.obj:2: ") && w.contains("test.mtl")),
        "{:?}",
        s.warnings
    );
    // Unknown material name: warning with the usemtl line.
    let s = load(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nope\nf 1 2 3\n",
        Some(MTL),
    )
    .unwrap();
    assert!(s.warnings.iter().any(|w| w.starts_with("test.obj:4: ")));
}

#[test]
fn missing_files() {
    let p = PathBuf::from("/nonexistent/dir/missing_scene.obj");
    let e = load_obj(&p).unwrap_err().to_string();
    assert!(e.contains("missing_scene.obj"), "{e}");

    let dir = std::env::temp_dir().join(format!("penumbra_obj_test_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("a.obj");
    std::fs::write(&obj, CUBE).unwrap();
    let s = load_obj(&obj).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("test.mtl") && w.contains("a.obj:2:"))
    );
    std::fs::write(dir.join("test.mtl"), MTL).unwrap();
    let s = load_obj(&obj).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert!(s.objects[1].flags.light);
    // A malformed MTL names the MTL file and its line.
    std::fs::write(dir.join("test.mtl"), "newmtl a\nKd 1 2\n").unwrap();
    let e = load_obj(&obj).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, penumbra::Error::Line { line: 2, .. }), "{msg}");
    assert!(msg.contains("test.mtl:2:"), "{msg}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn malformed_input_errors_name_file_and_line() {
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let m = expect_line_error(&format!("{base}v 1 x 2\n"), None, "test.obj", 4);
    assert!(m.contains("'x'"), "{m}");
    let m = expect_line_error(&format!("{base}\n\nv nan 0 0\n"), None, "test.obj", 6);
    assert!(m.contains("non-finite"), "{m}");
    expect_line_error(&format!("# c\n{base}v 0 inf 0\n"), None, "test.obj", 5);
    expect_line_error(&format!("{base}v 0 0 1e999\n"), None, "test.obj", 4);
    expect_line_error(&format!("{base}v 0 0\n"), None, "test.obj", 4);
    expect_line_error(&format!("{base}v 0 0 0 0\n"), None, "test.obj", 4);
    let m = expect_line_error(&format!("{base}f 1 2 4\n"), None, "test.obj", 4);
    assert!(m.contains("out of range"), "{m}");
    expect_line_error(&format!("{base}f 1 2 0\n"), None, "test.obj", 4);
    expect_line_error(&format!("{base}f -1 -2 -4\n"), None, "test.obj", 4);
    expect_line_error(&format!("{base}f 1 2 3.5\n"), None, "test.obj", 4);
    expect_line_error(
        &format!("{base}f 1 2 -9223372036854775808\n"),
        None,
        "test.obj",
        4,
    );
    expect_line_error(&format!("{base}vn 0 x 1\n"), None, "test.obj", 4);
    // Continuation lines report the first physical line.
    expect_line_error(&format!("{base}v 0 \\\n 0 y\n"), None, "test.obj", 4);
    // MTL errors name the MTL file (relative to the OBJ's name).
    let obj = format!("mtllib sub/m.mtl\n{base}f 1 2 3\n");
    let m = expect_line_error(&obj, Some("newmtl a\n\nNs abc\n"), "sub/m.mtl", 3);
    assert!(m.contains("abc"), "{m}");
    expect_line_error(&obj, Some("newmtl a\nKe 1 nan 1\n"), "sub/m.mtl", 2);
    expect_line_error(&obj, Some("newmtl\n"), "sub/m.mtl", 1);
    expect_line_error(&obj, Some("newmtl a\nPr\n"), "sub/m.mtl", 2);
}

#[test]
fn degenerate_faces_are_repaired_with_warnings() {
    let obj = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 1 0 0
o thing
f 1 2 2 3 4
f 1 2 5
f 1 2
f 1 2 1
f 1 2 6 3 4
f 1 2 3 4 1
";
    let s = load(obj, None).unwrap();
    assert_eq!(s.objects.len(), 1);
    let m = &s.objects[0].mesh;
    // Kept: the face of line 8. Lines 12 (6 and 2 share a position) and 13, once their
    // repeats are removed, are line 8's face again: the copies are dropped.
    assert_eq!(m.faces.len(), 1);
    assert!(m.faces.iter().all(|f| f.len() == 4));
    // Each kind of repair is one warning for the object, at its first line, listing the
    // lines: repeated vertices on 8, 12, 13; zero area on 9; fewer than 3 distinct on 11
    // (line 10, a face of two vertices, is dropped by the pre-scan).
    let w = &s.warnings;
    let has =
        |prefix: &str, what: &str| w.iter().any(|x| x.starts_with(prefix) && x.contains(what));
    assert!(
        has(
            "test.obj:8: ",
            "repeated vertices removed from 3 faces (lines 8, 12, 13)"
        ),
        "{w:?}"
    );
    assert!(
        has("test.obj:9: ", "1 face dropped: zero area (line 9)"),
        "{w:?}"
    );
    assert!(has("test.obj:10: ", "2 vertices dropped"), "{w:?}");
    assert!(
        has("test.obj:11: ", "fewer than 3 distinct vertices"),
        "{w:?}"
    );
    assert!(
        has(
            "test.obj:12: ",
            "2 faces are the same as an earlier face (same vertices, same winding): dropped \
             (lines 12, 13)"
        ),
        "{w:?}"
    );
    assert_eq!(w.len(), 5, "{w:?}");
    // Only degenerate faces: the object is skipped, the scene is empty but loads.
    let s = load("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", None).unwrap();
    assert!(s.objects.is_empty());
    assert!(!s.warnings.is_empty());
}

#[test]
fn groups_and_material_changes_split_objects() {
    let obj = "\
mtllib x.mtl
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
o chair
g leg
usemtl shiny
f 1 2 3
usemtl glow
f 1 3 4
g seat
f 1 4 2 # trailing comment
";
    let s = load(obj, Some(MTL)).unwrap();
    let names: Vec<_> = s.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["leg", "leg", "seat"]);
    let mats: Vec<_> = s.objects.iter().map(|o| o.material.name.as_str()).collect();
    assert_eq!(mats, ["shiny", "glow", "glow"]);
    assert_eq!(s.objects[0].mesh.positions.len(), 3);
    assert_eq!(s.objects[0].mesh.positions[2], DVec3::Y);
}

#[test]
fn empty_and_whitespace_files_load_as_empty_scenes() {
    for text in [
        "",
        "\n\n",
        "   \t\n# only a comment\n",
        "\\",
        "o\ng\n",
        "v 1 2 3\n",
    ] {
        let s = load(text, None).unwrap();
        assert!(s.objects.is_empty(), "{text:?}");
    }
}

fn random_text(rng: &mut Pcg32, len: usize) -> String {
    const TOKENS: &[&str] = &[
        "v",
        "f",
        "vt",
        "vn",
        "o",
        "g",
        "usemtl",
        "mtllib",
        "l",
        "p",
        "s",
        "1",
        "2",
        "3",
        "-1",
        "0",
        "-7",
        "1/2/3",
        "1//2",
        "/",
        "//",
        "nan",
        "inf",
        "-inf",
        "1e308",
        "1e309",
        "0.5",
        "-0",
        "#",
        "\\",
        "newmtl",
        "Kd",
        "Ks",
        "Ke",
        "Ns",
        "Pr",
        "spectral",
        "x",
        "é",
        "\t",
        "18446744073709551616",
        "9223372036854775807",
        "-9223372036854775808",
        "\r",
        "",
    ];
    let mut s = String::new();
    for _ in 0..len {
        match rng.below(8) {
            0 => s.push('\n'),
            1 => s.push(char::from_u32(rng.below(0x3000)).unwrap_or('?')),
            _ => {
                s.push_str(TOKENS[rng.below(TOKENS.len() as u32) as usize]);
                s.push(' ');
            }
        }
    }
    s
}

/// Loads and checks that a failure is a real input error, never an internal inconsistency,
/// and that a success yields valid meshes.
fn load_checked(obj: &str, mtl: Option<&str>) -> bool {
    match load(obj, mtl) {
        Ok(s) => {
            for o in &s.objects {
                let m = &o.mesh;
                assert!(!m.faces.is_empty());
                assert!(m.positions.iter().all(|p| p.is_finite()));
                for f in &m.faces {
                    assert!(f.len() >= 3);
                    assert!(f.iter().all(|&i| (i as usize) < m.positions.len()));
                }
            }
            true
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(!msg.contains("internal"), "{msg}\n--- obj:\n{obj}");
            false
        }
    }
}

#[test]
fn garbage_never_panics() {
    let mut rng = Pcg32::new(7, 11);
    for i in 0..3000 {
        let obj = random_text(&mut rng, 1 + (i % 200));
        let mtl = random_text(&mut rng, 1 + (i % 60));
        load_checked(&obj, Some(&mtl));
        load_checked(&obj, None);
        load_checked(&format!("mtllib m.mtl\n{obj}"), Some(&mtl));
    }
    // Truncated files (every cut point of the OBJ, then of the MTL): errors are fine, panics not.
    for cut in 0..=CUBE.len() {
        if CUBE.is_char_boundary(cut) {
            load_checked(&CUBE[..cut], Some(MTL));
        }
    }
    for cut in 0..=MTL.len() {
        load_checked(CUBE, Some(&MTL[..cut]));
    }
    // Random bytes (lossily decoded like files on disk).
    for _ in 0..500 {
        let bytes: Vec<u8> = (0..rng.below(400)).map(|_| rng.below(256) as u8).collect();
        let text = String::from_utf8_lossy(&bytes);
        load_checked(&text, Some(&text));
    }
}
