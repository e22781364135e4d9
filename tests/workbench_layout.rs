//! The workbench's tiles (issue 15): the presets at the default 1280×800 window, the picked
//! point it starts with, the persisted layout and the lesson text of every stage.

use crate::workbench::{harness, wait_for_render};
use penumbra::app::layout::{self, Pane, Preset};
use penumbra::app::lesson;
use penumbra::app::{Persisted, WorkbenchApp};
use penumbra::inspect::monte_carlo;

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
        let side = app.state.sphere.sphere_side;
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
            (aspect - h.state().state.aspect).abs() < 0.02,
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
/// used by some step kind.
#[test]
fn every_stage_has_its_lesson_with_the_points_numbers() {
    let h = open(Preset::Teach);
    let ins = h.state().inspector.as_ref().expect("a point is picked");
    let all = &ins.steps;
    assert!(all.len() > 5);
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

/// Exporting the lesson of the picked point (issue 15 item 3): one frame per stage, cropped
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
