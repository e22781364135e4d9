//! The readers under fuzzing: the OBJ, MTL and scene-file loaders and the debug-dump reader
//! get thousands of random and mutated inputs (deterministic: a seeded PCG, so a failure
//! reproduces). The properties, for every input:
//!
//! * no panic, and no hang (a watchdog fails the test naming the input);
//! * an error names the file, and a line within the file where it names one;
//! * what loads is sound: finite positions, faces of at least 3 vertices in range, physical
//!   materials, bounded warnings; a sample of the loaded scenes is prepared and shaded, and the
//!   value must be finite and non-negative;
//! * a dump that loads replays in the workbench, every step, without a panic.
//!
//! A failing input is written to the temp directory, named in the message.

use glam::DVec3;
use penumbra::math::Pcg32;
use penumbra::scene::obj::{ALPHA_MAX, ALPHA_MIN, load_obj_str};
use penumbra::scene::scene_file::load_scene_str;
use penumbra::scene::{Material, Scene};
use penumbra::shading::{
    Method, NoRecorder, PrepareOptions, PreparedScene, ShadingPoint, ShadingScratch, shade,
};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::mpsc;
use std::time::Duration;

const FIG4_OBJ: &str = include_str!("../assets/scenes/fig4.obj");
const FIG4_MTL: &str = include_str!("../assets/scenes/fig4.mtl");
const CHAIR_OBJ: &str = include_str!("../assets/scenes/chair.obj");
const CHAIR_MTL: &str = include_str!("../assets/scenes/chair.mtl");
const NONCONVEX_OBJ: &str = include_str!("../assets/scenes/nonconvex.obj");
const NONCONVEX_MTL: &str = include_str!("../assets/scenes/nonconvex.mtl");
const LETTERS_MTL: &str = include_str!("../assets/scenes/letters.mtl");
const DEFAULT_TOML: &str = include_str!("../assets/scenes/default.toml");
const FIG4_TOML: &str = include_str!("../assets/scenes/fig4.toml");
const CHAIR_TOML: &str = include_str!("../assets/scenes/chair.toml");
const INSTANCES_TOML: &str = include_str!("../assets/scenes/instances.toml");

/// Tokens that have broken parsers: non-finite and overflowing numbers, signs, empty and
/// malformed values, huge indices, stray bytes.
const SPICY: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e309",
    "-1e309",
    "-0",
    "0",
    "1e-320",
    "4294967296",
    "-4294967297",
    "18446744073709551616",
    "-1",
    "",
    "1/2/3",
    "//",
    "1//",
    "/1",
    "x",
    "1e",
    "--1",
    "0x10",
    "1.#IND",
    "1,5",
    "+.",
    "\u{feff}",
    "é",
    "\0",
    "\\",
    "#",
    "\r",
    "3",
    "2.5",
    "1e30",
    "-1e-30",
    "1000000",
];

/// Statements and lines of all three formats, inserted anywhere.
const LINES: &[&str] = &[
    "f 1 2 3",
    "f 1 2",
    "f -1 -2 -3",
    "f 0 1 2",
    "f 1/1/1 2//2 3/3",
    "f 1 1 1 1",
    "f 3 2 1 4 5 6 7 8 9 10",
    "v 1 2",
    "v 1 2 3 0",
    "v 1 2 3 4 5",
    "v 0 0 0",
    "v 1e300 1e300 1e300",
    "vn",
    "vt x",
    "o",
    "o twin",
    "g a b",
    "usemtl",
    "usemtl nothing",
    "usemtl light",
    "mtllib",
    "mtllib missing.mtl",
    "mtllib fuzz.mtl",
    "newmtl",
    "newmtl m",
    "Kd 1",
    "Kd 1 2 3 4",
    "Ke -1 2 3",
    "Ke 1e308 1e308 1e308",
    "Ns nan",
    "Ns -5",
    "Pr 2",
    "Ks 1 1",
    "Ks 5 5 5",
    "map_Kd tex.png",
    "l 1 2",
    "p 1",
    "s off",
    "curv 0 1 1 2",
    "\\",
    "#",
    "[camera]",
    "[[object]]",
    "obj = \"fig4.obj\"",
    "obj = \"chair.obj\"",
    "obj = \"nowhere.obj\"",
    "obj = \"../../etc/passwd\"",
    "name = \"light\"",
    "name = 7",
    "eye = [1, 2]",
    "eye = [0, 0, 0]",
    "target = [0, 0, 0]",
    "up = [0, 0, 0]",
    "fov = -5",
    "fov = 180",
    "scale = 0",
    "scale = [1, 0, 1]",
    "scale = -1",
    "rotate = { axis = [0, 0, 0], angle = 90 }",
    "rotate = [1e308, 0, 0]",
    "rotate = \"x\"",
    "translate = [1e300, 0, 0]",
    "light = \"yes\"",
    "occluder = false",
    "receiver = 3",
    "unknown = 1",
    "= 3",
    "[x",
    "\"\"\"",
];

struct Mutator {
    rng: Pcg32,
}

impl Mutator {
    fn pick<'a>(&mut self, list: &[&'a str]) -> &'a str {
        list[self.rng.below(list.len() as u32) as usize]
    }

    fn index(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            self.rng.below(n.min(u32::MAX as usize) as u32) as usize
        }
    }

    /// Spans of characters that look like numbers.
    fn numbers(text: &str) -> Vec<(usize, usize)> {
        let b = text.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        while i < b.len() {
            if b[i].is_ascii_digit() {
                let mut s = i;
                while s > 0 && matches!(b[s - 1], b'-' | b'+' | b'.') {
                    s -= 1;
                }
                let mut e = i;
                while e < b.len() && (b[e].is_ascii_digit() || matches!(b[e], b'.' | b'e' | b'E')) {
                    e += 1;
                }
                out.push((s, e));
                i = e;
            } else {
                i += 1;
            }
        }
        out
    }

    /// One mutation of `text`; `structural` picks byte- and line-level damage too, otherwise
    /// only numbers are replaced (for JSON that should stay parseable).
    fn mutate_once(&mut self, text: &str, structural: bool) -> String {
        let choice = if structural { self.rng.below(8) } else { 0 };
        match choice {
            // Replace a number by a spicy token.
            0 | 1 => {
                let spans = Self::numbers(text);
                if spans.is_empty() {
                    return format!("{text}{}", self.pick(SPICY));
                }
                let (s, e) = spans[self.index(spans.len())];
                let by = if structural || self.rng.below(3) == 0 {
                    self.pick(SPICY).to_owned()
                } else {
                    // Stays a JSON number: small integers, signs, tiny and huge values.
                    self.pick(&[
                        "0", "1", "2", "3", "-1", "7", "1e-300", "1e300", "0.5", "100",
                    ])
                    .to_owned()
                };
                format!("{}{by}{}", &text[..s], &text[e..])
            }
            // Insert a line.
            2 => {
                let mut lines: Vec<&str> = text.split('\n').collect();
                let at = self.index(lines.len() + 1);
                let line = self.pick(LINES);
                lines.insert(at, line);
                lines.join("\n")
            }
            // Delete, duplicate or swap lines.
            3 => {
                let mut lines: Vec<&str> = text.split('\n').collect();
                if lines.is_empty() {
                    return String::new();
                }
                let a = self.index(lines.len());
                let b = self.index(lines.len());
                match self.rng.below(3) {
                    0 => {
                        lines.remove(a);
                    }
                    1 => {
                        let l = lines[a];
                        lines.insert(b, l);
                    }
                    _ => lines.swap(a, b),
                }
                lines.join("\n")
            }
            // Replace a whitespace-separated token.
            4 => {
                let toks: Vec<(usize, &str)> = text
                    .split_inclusive(char::is_whitespace)
                    .scan(0, |pos, t| {
                        let at = *pos;
                        *pos += t.len();
                        Some((at, t.trim_end()))
                    })
                    .filter(|(_, t)| !t.is_empty())
                    .collect();
                if toks.is_empty() {
                    return text.to_owned();
                }
                let (at, t) = toks[self.index(toks.len())];
                format!(
                    "{}{}{}",
                    &text[..at],
                    self.pick(SPICY),
                    &text[at + t.len()..]
                )
            }
            // Byte damage: flip, insert, delete a range (lossily back to text).
            5 => {
                let mut b = text.as_bytes().to_vec();
                if b.is_empty() {
                    return "\u{fffd}".into();
                }
                let i = self.index(b.len());
                match self.rng.below(3) {
                    0 => b[i] ^= 1 << self.rng.below(8),
                    1 => b.insert(i, self.rng.below(256) as u8),
                    _ => {
                        let n = 1 + self.index(16);
                        b.drain(i..(i + n).min(b.len()));
                    }
                }
                String::from_utf8_lossy(&b).into_owned()
            }
            // Truncate.
            6 => {
                let mut i = self.index(text.len() + 1);
                while !text.is_char_boundary(i) {
                    i -= 1;
                }
                text[..i].to_owned()
            }
            // Duplicate a span.
            _ => {
                let mut a = self.index(text.len() + 1);
                while !text.is_char_boundary(a) {
                    a -= 1;
                }
                let mut e = (a + 1 + self.index(200)).min(text.len());
                while !text.is_char_boundary(e) {
                    e -= 1;
                }
                format!("{}{}", &text[..e], &text[a..])
            }
        }
    }

    fn mutate(&mut self, text: &str, structural: bool) -> String {
        let mut t = text.to_owned();
        for _ in 0..1 + self.rng.below(4) {
            t = self.mutate_once(&t, structural);
        }
        t
    }

    /// Text made of random lines of every format and random tokens.
    fn random_text(&mut self) -> String {
        let mut t = String::new();
        for _ in 0..self.rng.below(40) {
            if self.rng.below(3) == 0 {
                for _ in 0..1 + self.rng.below(5) {
                    t += self.pick(SPICY);
                    t.push(' ');
                }
            } else {
                t += self.pick(LINES);
            }
            t.push('\n');
        }
        t
    }
}

/// Runs `check` on every input in a worker thread; a panic or an input that takes longer than
/// the watchdog's limit fails the test, with the input saved to a file.
fn fuzz(name: &str, inputs: Vec<String>, check: impl Fn(&str) + Send + Sync + 'static) {
    let (tx, rx) = mpsc::channel::<Result<usize, (usize, String)>>();
    let n = inputs.len();
    let inputs = std::sync::Arc::new(inputs);
    let worker_inputs = inputs.clone();
    std::thread::spawn(move || {
        for (i, input) in worker_inputs.iter().enumerate() {
            let r = catch_unwind(AssertUnwindSafe(|| check(input)));
            let msg = match r {
                Ok(()) => Ok(i),
                Err(e) => Err((
                    i,
                    e.downcast_ref::<String>()
                        .cloned()
                        .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default(),
                )),
            };
            let stop = msg.is_err();
            if tx.send(msg).is_err() || stop {
                return;
            }
        }
    });
    let save = |i: usize| {
        let path = std::env::temp_dir().join(format!("penumbra-fuzz-{name}-{i}.txt"));
        let _ = std::fs::write(&path, &inputs[i]);
        path
    };
    let mut done = 0;
    while done < n {
        match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(Ok(i)) => done = i + 1,
            Ok(Err((i, msg))) => {
                panic!("{name}: input {i} ({}) failed: {msg}", save(i).display());
            }
            Err(_) => {
                panic!(
                    "{name}: input {done} ({}) hangs (no answer in 60 s)",
                    save(done).display()
                );
            }
        }
    }
}

fn line_count(text: &str) -> usize {
    text.lines().count().max(1)
}

/// An error names one of `files`, and a line within that file where it names a line.
fn check_error(e: &penumbra::Error, files: &[(&str, &str)]) {
    let msg = e.to_string();
    assert!(!msg.contains("internal error"), "{msg}");
    match e {
        penumbra::Error::Line { file, line, .. } => {
            let known = files.iter().find(|(f, _)| f == file);
            let (_, text) = known.unwrap_or_else(|| panic!("error names no known file: {msg}"));
            assert!(
                *line >= 1 && *line <= line_count(text) + 1,
                "line {line} of {} lines: {msg}",
                line_count(text)
            );
        }
        penumbra::Error::File { file, .. } => {
            // A known file, or one the input itself names (an `obj` or `mtllib` path).
            let named = files
                .iter()
                .any(|(f, t)| f == file || t.contains(file.as_str()));
            assert!(
                !file.is_empty() && msg.starts_with(file.as_str()) && named,
                "error names no known file: {msg}"
            );
        }
        other => panic!("a loader's error names no file: {other}"),
    }
}

fn check_material(m: &Material) {
    for v in [m.kd, m.ks, m.ke] {
        assert!(v.is_finite() && v.min_element() >= 0.0, "{m:?}");
    }
    assert!((ALPHA_MIN..=ALPHA_MAX).contains(&m.alpha), "{m:?}");
}

/// What loaded is sound; every `every`-th scene is also prepared and shaded at a point of each
/// receiver.
fn check_scene(s: &Scene, shade_it: bool) {
    assert!(s.warnings.len() <= 41, "{} warnings", s.warnings.len());
    for o in &s.objects {
        let m = &o.mesh;
        assert!(m.positions.iter().all(|p| p.is_finite()), "{}", o.name);
        assert!(m.rounding.is_finite() && m.rounding >= 0.0, "{}", o.name);
        for f in &m.faces {
            assert!(f.len() >= 3, "{}: face {f:?}", o.name);
            assert!(f.iter().all(|&i| (i as usize) < m.positions.len()));
        }
        check_material(&o.material);
    }
    if let Some(c) = s.camera {
        assert!(c.eye.is_finite() && c.target.is_finite() && c.fov_deg.is_finite());
    }
    if !shade_it {
        return;
    }
    let options = PrepareOptions {
        ..PrepareOptions::default()
    };
    let prepared = PreparedScene::prepare(s, options);
    let mut scratch = ShadingScratch::default();
    for (k, o) in s.objects.iter().enumerate().take(6) {
        let Some(f) = o.mesh.faces.first() else {
            continue;
        };
        let pts: Vec<DVec3> = f.iter().map(|&i| o.mesh.positions[i as usize]).collect();
        let Some(n) = penumbra::math::polygon_area_vector(pts.iter().copied()).try_normalize()
        else {
            continue;
        };
        let c = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
        let sp = ShadingPoint {
            position: c + n * 1e-3 * (1.0 + c.length()),
            normal: n,
            view: n,
            object: Some(k as u32),
            face: None,
        };
        for method in [Method::Analytic, Method::PerTriangle] {
            let v = shade(
                &prepared,
                &sp,
                &o.material,
                method,
                &mut scratch,
                &mut NoRecorder,
            );
            assert!(
                v.is_finite() && v.min_element() >= -1e-9 * (1.0 + v.max_element().abs()),
                "{}: {method:?} gives {v}",
                o.name
            );
        }
    }
}

fn inputs(seeds: &[&str], count: usize, stream: u64, structural: bool) -> Vec<String> {
    let mut m = Mutator {
        rng: Pcg32::new(0xf022, stream),
    };
    (0..count)
        .map(|i| {
            if structural && i % 10 == 9 {
                m.random_text()
            } else {
                let seed = seeds[i % seeds.len()];
                m.mutate(seed, structural)
            }
        })
        .collect()
}

#[test]
fn obj_files_under_fuzzing_load_or_fail_with_file_and_line() {
    let seeds = [
        FIG4_OBJ,
        CHAIR_OBJ,
        NONCONVEX_OBJ,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nmtllib fuzz.mtl\nusemtl light\nf 1 2 3 4\n",
    ];
    let all = inputs(&seeds, 3000, 1, true);
    fuzz("obj", all, |obj| {
        let r = load_obj_str(obj, Some(FIG4_MTL), "fuzz.obj");
        match r {
            Ok(s) => {
                let shade_it = obj.len() % 16 == 0;
                check_scene(&s, shade_it);
            }
            // Every `mtllib` is served the same MTL text, under the name the OBJ gives.
            Err(e) => check_error(
                &e,
                &[
                    ("fuzz.obj", obj),
                    ("fuzz.mtl", FIG4_MTL),
                    ("fig4.mtl", FIG4_MTL),
                    ("chair.mtl", FIG4_MTL),
                    ("nonconvex.mtl", FIG4_MTL),
                ],
            ),
        }
    });
}

#[test]
fn mtl_files_under_fuzzing_load_or_fail_with_file_and_line() {
    let seeds = [FIG4_MTL, CHAIR_MTL, NONCONVEX_MTL, LETTERS_MTL];
    let all = inputs(&seeds, 3000, 2, true);
    fuzz("mtl", all, |mtl| {
        match load_obj_str(CHAIR_OBJ, Some(mtl), "fuzz.obj") {
            Ok(s) => check_scene(&s, false),
            Err(e) => check_error(&e, &[("fuzz.obj", CHAIR_OBJ), ("chair.mtl", mtl)]),
        }
    });
}

#[test]
fn scene_files_under_fuzzing_load_or_fail_with_file_and_line() {
    let seeds = [DEFAULT_TOML, FIG4_TOML, CHAIR_TOML, INSTANCES_TOML];
    let all = inputs(&seeds, 2000, 3, true);
    fuzz("toml", all, |toml| {
        // The scene files name embedded OBJ files; the resolver loads them as the scene
        // loader would, from memory.
        let resolve = |rel: &str| {
            let (obj, mtl) = match rel {
                "fig4.obj" => (FIG4_OBJ, FIG4_MTL),
                "chair.obj" => (CHAIR_OBJ, CHAIR_MTL),
                "nonconvex.obj" => (NONCONVEX_OBJ, NONCONVEX_MTL),
                _ => {
                    return Err(penumbra::Error::File {
                        file: rel.to_owned(),
                        message: "no such file".into(),
                    });
                }
            };
            load_obj_str(obj, Some(mtl), rel)
        };
        match load_scene_str(toml, "fuzz.toml", &resolve) {
            Ok(s) => check_scene(&s, toml.len() % 8 == 0),
            // The scene file's own errors, or those of the OBJ it names (which name that
            // file, and their line in it).
            Err(e) => check_error(
                &e,
                &[
                    ("fuzz.toml", toml),
                    ("fig4.obj", FIG4_OBJ),
                    ("fig4.mtl", FIG4_MTL),
                    ("chair.obj", CHAIR_OBJ),
                    ("chair.mtl", CHAIR_MTL),
                    ("nonconvex.obj", NONCONVEX_OBJ),
                    ("nonconvex.mtl", NONCONVEX_MTL),
                ],
            ),
        }
    });
}

#[cfg(feature = "gui")]
#[test]
fn debug_dumps_under_fuzzing_load_or_fail_with_file_and_line_and_replay() {
    use egui_kittest::Harness;
    use penumbra::app::{Persisted, WorkbenchApp};
    use penumbra::inspect::{Probe, probe};

    let mut dumps = Vec::new();
    for (name, pixel) in [("fig4", (30.0, 44.0)), ("nonconvex", (20.0, 40.0))] {
        let scene = penumbra::scene::scene_file::load_embedded(name).unwrap();
        let ctx = penumbra::render::RenderContext::new(&scene);
        let cam = scene.camera.unwrap();
        let p = probe(&ctx, name, &cam, (64, 64), pixel, Method::Analytic, true).unwrap();
        dumps.push(serde_json::to_string_pretty(&p).unwrap());
    }
    let seeds: Vec<&str> = dumps.iter().map(String::as_str).collect();
    // Most mutations keep the JSON valid (numbers replaced by numbers), so that they reach
    // the checks after parsing; a third damage it anywhere.
    let mut all = inputs(&seeds, 800, 4, false);
    all.extend(inputs(&seeds, 400, 5, true));
    let dir = std::env::temp_dir().join(format!("penumbra-fuzz-dumps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let replayed = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let counter = replayed.clone();
    fuzz("dump", all, move |text| {
        match Probe::from_json(text, "fuzz.json") {
            Ok(p) => {
                // Replay a sample in the workbench, stepping through every stage.
                if counter.load(std::sync::atomic::Ordering::Relaxed) >= 40 {
                    return;
                }
                counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let path = dir.join("dump.json");
                std::fs::write(&path, text).unwrap();
                let state = Persisted {
                    scene: "no-such-scene.toml".into(),
                    ..Persisted::default()
                };
                let app = WorkbenchApp::new(state, Default::default(), || {});
                let mut h = Harness::builder()
                    .with_size((1280.0, 800.0))
                    .build_ui_state(|ui, app: &mut WorkbenchApp| app.frame_ui(ui), app);
                h.step();
                h.state_mut().open_path(&path);
                h.step();
                let n = h.state().inspector.as_ref().map_or(0, |i| i.steps.len());
                assert!(n > 0 || p.recording.lights.is_empty(), "the dump opened");
                for _ in 0..n {
                    h.key_press(egui::Key::ArrowRight);
                    h.step();
                }
            }
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.starts_with("fuzz.json"), "{msg}");
                if let Some(rest) = msg.strip_prefix("fuzz.json:")
                    && let Some(line) = rest.split(':').next().and_then(|l| l.parse::<usize>().ok())
                {
                    assert!(line >= 1 && line <= line_count(text) + 1, "{msg}");
                }
            }
        }
    });
    assert!(
        replayed.load(std::sync::atomic::Ordering::Relaxed) >= 20,
        "enough mutated dumps load to be replayed"
    );
}
