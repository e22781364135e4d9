//! The workbench's tiles: the presets at the default 1280×800 window, the picked
//! point it starts with, the persisted layout and the lesson text of every stage.

use crate::workbench::{harness, wait_for_render};
use penumbra::app::layout::{self, Pane, Preset};
use penumbra::app::lesson;
use penumbra::app::{Persisted, WorkbenchApp};
use penumbra::inspect::monte_carlo;
use penumbra::views::stages::StepKind;

/// Opens the workbench in `preset`, lets the render finish and the first point be picked.
fn open(preset: Preset) -> egui_kittest::Harness<'static, WorkbenchApp> {
    let mut h = harness(Persisted {
        preset,
        ..Persisted::default()
    });
    wait_for_render(&mut h);
    h.run_steps(3);
    h
}

/// In `explore` and `teach` the sphere is on screen before any click, at least 400 px across,
/// and shows a point in a penumbra: the shadowed radiance S, estimated by ray-cast Monte Carlo
/// (an oracle independent of the set differences), lies strictly between 0.1 and 0.9 of the
/// unshadowed U.
#[test]
fn the_presets_show_a_large_sphere_of_a_penumbra_point() {
    for preset in [Preset::Explore, Preset::Teach] {
        let h = open(preset);
        let app = h.state();
        assert!(layout::is_shown(&app.tree, Pane::Sphere), "{preset:?}");
        assert!(layout::is_shown(&app.tree, Pane::Viewport), "{preset:?}");
        let side = app.settings.sphere.sphere_side;
        assert!(side >= 400.0, "{preset:?}: the sphere is {side} px");
        let ins = app.inspector.as_ref().expect("a point is picked at start");
        let p = &ins.probe;
        let ctx = app.render_context().expect("the scene is loaded");
        let mc = monte_carlo(
            &ctx,
            p.point.as_ref().unwrap(),
            p.material.as_ref().unwrap(),
            1 << 16,
            11,
        );
        let u: f64 = p.lights.iter().map(|l| l.unshadowed.element_sum()).sum();
        let s = mc.mean.element_sum();
        let half_width = 3.0 * mc.stderr.element_sum();
        assert!(u > 0.0);
        assert!(
            s - half_width > 0.1 * u && s + half_width < 0.9 * u,
            "{preset:?}: S = {s} ± {half_width}, U = {u}"
        );
    }
    // The benchmark preset: the viewport beside the plots.
    let h = open(Preset::Benchmark);
    assert!(layout::is_shown(&h.state().tree, Pane::Viewport));
    assert!(layout::is_shown(&h.state().tree, Pane::Plots));
}

/// The viewport keeps the camera's aspect in whatever tile it gets.
#[test]
fn the_viewport_keeps_the_aspect() {
    for preset in Preset::ALL {
        let h = open(preset);
        let r = h.state().viewport_rect.expect("the viewport is drawn");
        let aspect = r.width() / r.height();
        assert!(
            (aspect - h.state().settings.aspect).abs() < 0.02,
            "{preset:?}: {aspect}"
        );
    }
}

/// What the user arranged comes back: the tree survives the round trip through the persisted
/// state (serde, as eframe stores it) tile for tile, with the same panes shown.
#[test]
fn the_layout_is_persisted() {
    let mut h = open(Preset::Teach);
    layout::reveal(&mut h.state_mut().tree, Pane::Planar);
    layout::reveal(&mut h.state_mut().tree, Pane::Numbers);
    h.run_steps(2);
    let stored = serde_json::to_string(&h.state().persisted()).unwrap();
    let state: Persisted = serde_json::from_str(&stored).unwrap();
    assert_eq!(state.preset, Preset::Teach);
    let h2 = harness(state);
    for pane in Pane::ALL {
        assert_eq!(
            layout::is_shown(&h.state().tree, pane),
            layout::is_shown(&h2.state().tree, pane),
            "{pane:?}"
        );
    }
    // Tile for tile (the hidden set is a hash set: compared in order).
    let tiles = |t: &egui_tiles::Tree<Pane>| {
        let mut v = serde_json::to_value(&t.tiles).unwrap();
        if let Some(serde_json::Value::Array(a)) = v.get_mut("invisible") {
            a.sort_by_key(|x| x.as_u64());
        }
        v
    };
    assert_eq!(tiles(&h.state().tree), tiles(&h2.state().tree));
    assert!(layout::is_shown(&h2.state().tree, Pane::Planar));
    assert!(!layout::is_shown(&h2.state().tree, Pane::Sphere));
}

/// Every stage of the recording has its lesson from `docs/analytic-pipeline.md`, with an
/// equation and every `{name}` replaced by a number of this point; every stage of the page is
/// used by some step kind. The point is recorded again with the derivative AOV on (its
/// occluder along tx), which adds the derivative's stage.
#[test]
fn every_stage_has_its_lesson_with_the_points_numbers() {
    let mut h = open(Preset::Teach);
    h.state_mut().settings.aov = penumbra::app::tonemap::Aov::Derivative;
    // The occluder of the point's first set difference: its motion moves edges there.
    let occluder = h.state().picked_occluder().expect("a penumbra point");
    h.state_mut().select_object(&occluder.to_string());
    h.run_steps(2);
    let ins = h.state().inspector.as_ref().expect("a point is picked");
    assert!(ins.probe.derivative.is_some(), "probed again with the rate");
    let all = &ins.steps;
    assert!(all.len() > 5);
    assert!(all.iter().any(|s| s.kind == StepKind::Derivative));
    let mut keys = std::collections::BTreeSet::new();
    for step in all {
        let l = lesson::lesson(&ins.probe, step)
            .unwrap_or_else(|| panic!("no lesson for {:?}", step.kind));
        assert!(!l.text.is_empty() && !l.equation.is_empty(), "{}", l.key);
        // Equations may hold braces of their own (set notation); the `Here:` line is all numbers.
        for text in [&l.text, &l.equation, &l.here] {
            assert!(!text.contains("?}"), "{}: {text}", l.key);
        }
        assert!(
            !l.here.is_empty() && !l.here.contains('{'),
            "{}: {}",
            l.key,
            l.here
        );
        keys.insert(l.key);
    }
    let page: std::collections::BTreeSet<String> =
        lesson::stages().iter().map(|s| s.key.clone()).collect();
    assert!(page.len() >= 10);
    // A penumbra point of the default scene goes through every stage but the environment's.
    let missing: Vec<_> = page.difference(&keys).collect();
    assert!(missing.len() <= 3, "stages never shown: {missing:?}");
}

/// Exporting the lesson of the picked point: one frame per stage, cropped
/// to the sphere's tile, as numbered PNGs, an animated GIF with the same frames (decoded back
/// here) and the lesson text with every stage's label; the pictures change as the stages do.
#[test]
fn the_lesson_exports_as_frames_a_gif_and_text() {
    use image::AnimationDecoder;
    let mut h = open(Preset::Teach);
    let n = h.state().inspector.as_ref().unwrap().steps.len();
    let labels: Vec<String> = h
        .state()
        .inspector
        .as_ref()
        .unwrap()
        .steps
        .iter()
        .map(|s| s.label.clone())
        .collect();
    let dir = std::env::temp_dir().join(format!("penumbra-lesson-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    assert!(h.state_mut().export_lesson(dir.clone()));
    let mut frames = 0;
    while h.state().exporting_lesson() {
        h.step();
        frames += 1;
        assert!(frames < 40 * n + 100, "the export did not finish");
    }
    let status = h.state().status.clone();
    assert!(status.starts_with(&format!("wrote {n} frames")), "{status}");
    let pngs: Vec<image::RgbaImage> = (0..n)
        .map(|i| {
            image::open(dir.join(format!("frame_{i:03}.png")))
                .unwrap()
                .to_rgba8()
        })
        .collect();
    assert!(!dir.join(format!("frame_{n:03}.png")).exists());
    // The sphere's tile: at least 400 px on its short side in the teach preset.
    let (w, hgt) = pngs[0].dimensions();
    assert!(w.min(hgt) >= 400, "{w}×{hgt}");
    assert!(pngs.iter().all(|p| p.dimensions() == (w, hgt)));
    // Consecutive stages do not all look the same.
    let differing = pngs.windows(2).filter(|p| p[0] != p[1]).count();
    assert!(
        differing * 2 >= n - 1,
        "{differing} of {} pairs differ",
        n - 1
    );
    let gif = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("lesson.gif")).unwrap(),
    ))
    .unwrap();
    let decoded = gif.into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), n);
    assert!(decoded.iter().all(|f| f.buffer().dimensions() == (w, hgt)));
    let text = std::fs::read_to_string(dir.join("lesson.md")).unwrap();
    for (i, l) in labels.iter().enumerate() {
        assert!(text.contains(&format!("## Frame {i:03}: {l}")), "{l}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Dragging an occluder's arrow in the viewport: the object moves along the
/// arrow, the picked point's recording changes and equals a probe of a scene prepared from
/// scratch with the object where it now is (an independent preparation), the render starts
/// again; Ctrl+Z puts everything back bit for bit.
#[test]
fn dragging_an_occluder_changes_the_recording_and_undo_restores_it() {
    use egui::{Event, Modifiers, PointerButton};
    use penumbra::app::gizmo::{Gizmo, Handle};
    let mut h = open(Preset::Teach);
    let before = h.state().inspector.as_ref().unwrap().probe.clone();
    let ctx = h.state().render_context().unwrap();
    // The occluder subtracted first at the picked point.
    let sd = before
        .recording
        .lights
        .iter()
        .flat_map(|l| l.set_differences.iter())
        .next()
        .expect("the picked point has a set difference");
    let object = ctx.prepared.objects[sd.occluder].object as usize;
    h.state_mut().editor.selected = Some(object);
    h.run_steps(2);
    let rect = h.state().viewport_rect.unwrap();
    let camera = h.state().orbit.camera();
    let pivot = h.state_mut().editor.pivot(&ctx, object).unwrap();
    let gizmo = Gizmo::new(camera.basis().unwrap(), rect, pivot);
    // Grab the x arrow two thirds along and drag it by its own screen length.
    let c = gizmo.project(pivot).unwrap();
    let e = gizmo
        .project(pivot + glam::DVec3::X * gizmo.length)
        .unwrap();
    let from = c + (e - c) * 0.66;
    assert_eq!(gizmo.hit(from), Some(Handle::Axis(0)));
    let generation = h.state().latest_frame().map(|f| f.generation);
    h.event(Event::PointerMoved(from));
    h.step();
    h.event(Event::PointerButton {
        pos: from,
        button: PointerButton::Primary,
        pressed: true,
        modifiers: Modifiers::default(),
    });
    h.step();
    let steps = 6;
    for k in 1..=steps {
        let p = from + (e - c) * (k as f32 / steps as f32);
        h.event(Event::PointerMoved(p));
        h.step();
    }
    let to = from + (e - c);
    h.event(Event::PointerButton {
        pos: to,
        button: PointerButton::Primary,
        pressed: false,
        modifiers: Modifiers::default(),
    });
    h.step();
    let moved_ctx = h.state().render_context().unwrap();
    let before_pos = &ctx.scene.objects[object].mesh.positions;
    let after_pos = &moved_ctx.scene.objects[object].mesh.positions;
    let shift = after_pos[0] - before_pos[0];
    assert!(
        (shift.x - gizmo.length).abs() < 0.05 * gizmo.length && shift.y.abs() < 1e-12,
        "moved by {shift}, arrow length {}",
        gizmo.length
    );
    let after = h.state().inspector.as_ref().unwrap().probe.clone();
    assert_eq!(after.pixel, before.pixel);
    assert_ne!(
        serde_json::to_value(&after.recording).unwrap(),
        serde_json::to_value(&before.recording).unwrap()
    );
    // The oracle: the moved scene prepared from scratch, probed at the same pixel.
    let fresh = penumbra::render::RenderContext::new(&moved_ctx.scene);
    let p = penumbra::inspect::probe(
        &fresh,
        &after.scene,
        &camera,
        after.size,
        after.pixel,
        penumbra::shading::Method::Analytic,
        false,
    )
    .unwrap();
    let tol = 1e-12 * p.radiance.length().max(1e-300);
    assert!(
        (p.radiance - after.radiance).length() <= tol,
        "{} vs {}",
        p.radiance,
        after.radiance
    );
    wait_for_render(&mut h);
    assert_ne!(h.state().latest_frame().map(|f| f.generation), generation);

    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    h.run_steps(2);
    let undone = h.state().render_context().unwrap();
    assert_eq!(&undone.scene.objects[object].mesh.positions, before_pos);
    let again = &h.state().inspector.as_ref().unwrap().probe;
    assert_eq!(again.radiance, before.radiance);
    // Every stage recorded the same; only the point at which a moved object's tree was looked
    // up went through the move and its inverse (the tree is kept, under the composed map into
    // its frame: 001 Sect. 5.4), so it equals the first to rounding, in the same leaf.
    let mut again_rec = again.recording.clone();
    for (a, b) in again_rec.lights.iter_mut().zip(&before.recording.lights) {
        assert_eq!(a.trees.len(), b.trees.len());
        for (ta, tb) in a.trees.iter_mut().zip(&b.trees) {
            assert!((ta.tree_point - tb.tree_point).length() <= 1e-12);
            ta.tree_point = tb.tree_point;
        }
    }
    assert_eq!(
        serde_json::to_value(&again_rec).unwrap(),
        serde_json::to_value(&before.recording).unwrap()
    );
}

/// A `.glb` dropped on the window opens as the scene, with its camera, and
/// renders: the image is finite, the light's floor is lit, and the point picked at start has
/// the radiance a probe of the same file loaded by the library gives.
#[test]
fn a_dropped_glb_opens_and_renders() {
    use crate::gltf_loading::{Form, temp_dir, test_scene, write};
    use std::path::{Path, PathBuf};
    #[derive(Debug)]
    struct Dropped(PathBuf);
    impl egui::DroppedFile for Dropped {
        fn path(&self) -> &Path {
            &self.0
        }
        fn bytes(&self) -> Result<Vec<u8>, String> {
            std::fs::read(&self.0).map_err(|e| e.to_string())
        }
    }
    let (doc, bin) = test_scene();
    let path = write(&temp_dir("drop"), "dropped", doc, &bin, Form::Glb);
    let mut h = open(Preset::Explore);
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(path.clone())));
    h.step();
    let name = path.display().to_string();
    assert_eq!(h.state().settings.scene, name, "{}", h.state().status);
    wait_for_render(&mut h);
    h.run_steps(3);
    let scene = penumbra::scene::scene_file::load_scene(&path).unwrap();
    let cam = scene.camera.expect("the file has a camera");
    assert_eq!(h.state().orbit.camera().eye, cam.eye);
    let frame = h.state().latest_frame().unwrap();
    let img = &frame.frame.output.image;
    let (mut lit, mut n) = (0usize, 0usize);
    for y in 0..img.height {
        for x in 0..img.width {
            let c = img.at(x, y);
            assert!(c.is_finite());
            n += 1;
            if c.max_element() > 1e-3 {
                lit += 1;
            }
        }
    }
    assert!(lit * 10 > n, "{lit} of {n} pixels lit");
    if let Some(ins) = &h.state().inspector {
        let ctx = penumbra::render::RenderContext::new(&scene);
        let p = penumbra::inspect::probe(
            &ctx,
            &name,
            &h.state().orbit.camera(),
            ins.probe.size,
            ins.probe.pixel,
            penumbra::shading::Method::Analytic,
            false,
        )
        .unwrap();
        assert_eq!(p.radiance, ins.probe.radiance);
    }
}
