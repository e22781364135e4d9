//! The workbench driven headlessly with egui_kittest (no window, no GPU needed for the logic):
//! it starts on the default scene, renders, a click picks a pixel, the stages step, and a
//! debug dump replays without the scene.

use egui::{Event, PointerButton, Pos2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use penumbra::app::layout::{self, Pane};
use penumbra::app::{Persisted, WorkbenchApp};
use penumbra::inspect::probe;
use penumbra::shading::Method;
use penumbra::views::stages::StepKind;
use std::time::{Duration, Instant};

pub(crate) fn harness(state: Persisted) -> Harness<'static, WorkbenchApp> {
    let app = WorkbenchApp::new(state, Default::default(), || {});
    Harness::builder()
        .with_size((1280.0, 800.0))
        .build_ui_state(|ui, app: &mut WorkbenchApp| app.frame_ui(ui), app)
}

/// Steps the UI until the viewport's render has finished.
pub(crate) fn wait_for_render(h: &mut Harness<'static, WorkbenchApp>) {
    let start = Instant::now();
    loop {
        h.step();
        if h.state().render_finished() {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the render did not finish"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

pub(crate) fn click(h: &mut Harness<'static, WorkbenchApp>, pos: Pos2) {
    h.event(Event::PointerMoved(pos));
    h.step();
    for pressed in [true, false] {
        h.event(Event::PointerButton {
            pos,
            button: PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        });
        h.step();
    }
}

#[test]
fn pick_a_penumbra_pixel_and_step_through_its_stages() {
    let mut h = harness(Persisted::default());
    wait_for_render(&mut h);
    let frame = h.state().latest_frame().expect("a frame");
    let img = frame.frame.output.image.clone();
    let size = (img.width, img.height);
    assert_eq!(frame.frame.scale, 1);

    // Find a pixel in a penumbra (a light partly hidden) with the library, away from edges.
    let scene = penumbra::scene::scene_file::load_embedded("default").unwrap();
    let ctx = penumbra::render::RenderContext::new(&scene);
    let mut target = None;
    'scan: for y in (size.1 / 2..size.1 - 4).step_by(7) {
        for x in (4..size.0 - 4).step_by(7) {
            let p = probe(
                &ctx,
                "default",
                &frame.camera,
                size,
                (x as f64, y as f64),
                Method::Analytic,
                false,
            )
            .unwrap();
            if p.lights.iter().any(|l| {
                let f = l.visible_fraction();
                f > 0.1 && f < 0.9
            }) {
                target = Some((x, y));
                break 'scan;
            }
        }
    }
    let (x, y) = target.expect("the default scene has penumbra pixels");

    // Click it in the viewport.
    let rect = h.state().viewport_rect.expect("viewport drawn");
    let pos = Pos2::new(
        rect.min.x + (x as f32 + 0.5) / size.0 as f32 * rect.width(),
        rect.min.y + (y as f32 + 0.5) / size.1 as f32 * rect.height(),
    );
    click(&mut h, pos);
    let ins = h
        .state()
        .inspector
        .as_ref()
        .expect("the click picked a point");
    assert_eq!(ins.probe.pixel, (x as f64, y as f64));
    // The same numbers, because it is the same code: the recorded point's radiance is the
    // rendered pixel, bit for bit, and the recorded per-light integrals add up to it.
    let pixel = img.at(x, y);
    assert_eq!(ins.probe.radiance, pixel);
    let sum: glam::DVec3 = ins
        .probe
        .lights
        .iter()
        .map(|l| l.shadowed)
        .sum::<glam::DVec3>()
        + ins.probe.emitted;
    assert!((sum - pixel).length() <= 1e-12 * pixel.length().max(1e-300));
    let n_steps = ins.steps.len();
    assert!(n_steps > 5);

    // The panel shows the point's numbers and the stepper.
    // The panel is drawn before the viewport that handled the click: one more frame.
    h.step();
    // The numbers are a tab behind the stages in the explore preset.
    layout::reveal(&mut h.state_mut().tree, Pane::Numbers);
    h.step();
    h.get_by_label("radiance");
    layout::reveal(&mut h.state_mut().tree, Pane::Stages);
    h.step();
    h.get_by_label("next >").click_accesskit();
    h.run_steps(2);
    assert_eq!(h.state().inspector.as_ref().unwrap().step, Some(0));
    let first = h.state().inspector.as_ref().unwrap().steps[0].label.clone();
    // Shown as the current stage, in the list and above the sphere.
    assert_eq!(h.query_all_by_label(&first).count(), 3);
    // Walk with the keyboard to the first set difference, then through its GH phases.
    let sd = h
        .state()
        .inspector
        .as_ref()
        .unwrap()
        .steps
        .iter()
        .position(|s| matches!(s.kind, StepKind::SetDifference { .. }))
        .expect("a penumbra point has a set difference");
    for _ in 0..sd {
        h.key_press(egui::Key::ArrowRight);
        h.step();
    }
    let ins = h.state().inspector.as_ref().unwrap();
    assert_eq!(ins.step, Some(sd));
    assert!(matches!(
        ins.current().unwrap().kind,
        StepKind::SetDifference { .. }
    ));
    // At a set difference the projected plane comes forward in the sphere's place.
    assert!(layout::is_shown(&h.state().tree, Pane::Planar));
    assert!(!layout::is_shown(&h.state().tree, Pane::Sphere));
    assert_eq!(
        h.query_all_by_label(&ins.current().unwrap().label.clone())
            .count(),
        2
    );
    for _ in 0..3 {
        h.key_press(egui::Key::ArrowRight);
        h.step();
    }
    h.key_press(egui::Key::Home);
    h.step();
    assert_eq!(h.state().inspector.as_ref().unwrap().step, None);
}

#[test]
fn a_debug_dump_replays_without_the_scene() {
    let scene = penumbra::scene::scene_file::load_embedded("fig4").unwrap();
    let ctx = penumbra::render::RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let p = probe(
        &ctx,
        "fig4",
        &cam,
        (64, 64),
        (30.0, 44.0),
        Method::Analytic,
        true,
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("penumbra-dump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("probe.json");
    penumbra::app::files::save_dump(&p, &path).unwrap();

    // A workbench whose scene does not exist: it shows the error and still replays the dump.
    let state = Persisted {
        scene: "no-such-scene.toml".into(),
        ..Persisted::default()
    };
    let mut h = harness(state);
    h.step();
    h.state_mut().open_path(&path);
    h.step();
    let ins = h.state().inspector.as_ref().expect("the dump is open");
    assert_eq!(ins.probe.radiance, p.radiance);
    assert_eq!(
        serde_json::to_string(&ins.probe.recording).unwrap(),
        serde_json::to_string(&p.recording).unwrap()
    );
    let n = ins.steps.len();
    for _ in 0..n {
        h.key_press(egui::Key::ArrowRight);
        h.step();
    }
    assert_eq!(h.state().inspector.as_ref().unwrap().step, Some(n - 1));
    std::fs::remove_dir_all(&dir).ok();
}

/// The first pixel of a scan of `ctx`'s scene whose probe took light `light` whole and looked
/// its silhouette up in its tree and found it there (or, for a light without a tree,
/// recorded its contour): the point, and the light's record.
fn probe_through_the_tree(
    ctx: &penumbra::render::RenderContext,
    scene: &penumbra::scene::Scene,
    light: usize,
) -> (glam::DVec3, penumbra::shading::LightRecord) {
    let id = ctx.prepared.lights[light].0 as usize;
    let has_tree = ctx.prepared.objects[id].silhouette_tree().is_some();
    let size = (48, 48);
    let camera = scene.camera.expect("the scene has a camera");
    for j in 0..size.1 {
        for i in 0..size.0 {
            let Ok(p) = probe(
                ctx,
                "test",
                &camera,
                size,
                (i as f64, j as f64),
                Method::Analytic,
                false,
            ) else {
                continue;
            };
            let Some(point) = p.point else {
                continue;
            };
            if let Some(r) = p.recording.lights.into_iter().find(|r| {
                r.light == light
                    && r.piece.is_none()
                    && if has_tree {
                        r.trees.iter().any(|t| t.occluder.is_none() && t.answered)
                    } else {
                        r.contour_points
                            .iter()
                            .any(|(o, e)| o.is_none() && !e.is_empty())
                    }
            }) {
                return (point.position, r);
            }
        }
    }
    panic!("no pixel looks light {light} up in its tree");
}

/// Draws `obj` in a light view with `view`'s settings: the shape count and what was drawn.
fn light_view_shapes(
    view: penumbra::app::light_view::LightView,
    obj: &penumbra::shading::PreparedObject,
    x: glam::DVec3,
    record: &penumbra::shading::LightRecord,
) -> (usize, penumbra::views::light::Drawn) {
    use penumbra::app::light_view::LightView;
    let mut h = Harness::new_ui_state(
        |ui, v: &mut LightView| v.ui(ui, obj, Some(x), Some(record)),
        view,
    );
    h.run();
    let n = h.output().shapes.len();
    (n, h.state().drawn.clone())
}

#[test]
fn the_light_view_draws_the_bsp_planes_of_a_non_convex_light() {
    use penumbra::app::light_view::LightView;
    let scene = penumbra::scene::scene_file::load_embedded("nonconvex").unwrap();
    let ctx = penumbra::render::RenderContext::new(&scene);
    let light = ctx
        .prepared
        .lights
        .iter()
        .position(|&(id, _)| ctx.prepared.objects[id as usize].name == "u_light")
        .expect("the U-shaped light");
    let obj = &ctx.prepared.objects[ctx.prepared.lights[light].0 as usize];
    assert!(
        obj.exact_tree().is_some(),
        "a closed non-convex light has a tree"
    );
    let (x, record) = probe_through_the_tree(&ctx, &scene, light);
    let lookup = record.trees.iter().find(|t| t.occluder.is_none()).unwrap();
    let depth = lookup.steps.len();
    assert!(depth > 0);

    let (without, drawn) = light_view_shapes(
        LightView {
            path_planes: false,
            ..LightView::default()
        },
        obj,
        x,
        &record,
    );
    assert_eq!(drawn.path_planes, 0);
    assert_eq!(drawn.leaf_depth, Some(depth));
    let (with_path, drawn) = light_view_shapes(LightView::default(), obj, x, &record);
    // Every plane on the path cuts its node's cell: one section each, a fill and an outline
    // per section, and a depth label.
    assert_eq!(drawn.path_planes, depth);
    assert!(with_path >= without + 3 * depth, "{with_path} vs {without}");
    let (_, drawn) = light_view_shapes(
        LightView {
            levels: 2,
            ..LightView::default()
        },
        obj,
        x,
        &record,
    );
    assert!((1..=3).contains(&drawn.level_planes), "{drawn:?}");
}

/// The light view shows the tree the renderer looked the light up in, and the contour edges
/// it recorded, not a tree or a contour of its own: on hoisted trees, whose
/// layout differs from the tree they come from, and on a convex hull standing in for a mesh
/// written by Blender.
#[test]
fn the_light_view_shows_the_tree_the_renderer_used() {
    use penumbra::app::light_view::LightView;
    use penumbra::geometry::TreeKind;
    let cases: [(&str, bool); 2] = [
        ("nonconvex", true),
        (
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/tests/data/blender/primitives.toml"
            ),
            false,
        ),
    ];
    let mut stand_ins = 0;
    for (name, hoist) in cases {
        let mut scene = penumbra::scene::scene_file::load_scene_by_name(name).unwrap();
        // Blender's UV sphere, convex only up to the 6 digits of its OBJ, made a light: the
        // convex hull stands in for it, with a tree of its own.
        if let Some(o) = scene.objects.iter_mut().find(|o| o.name == "UVSphere") {
            o.material.ke = glam::DVec3::splat(3.0);
            o.flags.light = true;
        }
        let mut ctx = penumbra::render::RenderContext::new(&scene);
        if hoist {
            ctx.prepared.use_hoisted_trees();
        }
        for (light, &(id, _)) in ctx.prepared.lights.iter().enumerate() {
            let obj = &ctx.prepared.objects[id as usize];
            let tree = obj.silhouette_tree();
            if hoist {
                let kind = tree.map(|t| t.kind());
                assert!(
                    matches!(kind, Some(TreeKind::HoistedConvex | TreeKind::HoistedExact)),
                    "{name}: {} has {kind:?}",
                    obj.name
                );
            }
            stand_ins += obj.stand_in().is_some() as usize;
            let (x, record) = probe_through_the_tree(&ctx, &scene, light);
            let lookup = record.trees.iter().find(|t| t.occluder.is_none());
            assert_eq!(
                lookup.map(|l| l.kind),
                tree.map(|t| t.kind()),
                "{name}: {}",
                obj.name
            );
            let (_, drawn) = light_view_shapes(LightView::default(), obj, x, &record);
            assert_eq!(drawn.tree, tree.map(|t| t.kind()), "{name}: {}", obj.name);
            assert_eq!(drawn.leaf_depth, lookup.map(|l| l.steps.len()));
            // The contour drawn is the recorded one: a convex silhouette's cycle (read from a
            // tree or chained at the point); an exact tree computes no contour.
            let recorded = record
                .contour_points
                .iter()
                .find(|(o, _)| o.is_none())
                .map_or(0, |(_, e)| e.len());
            assert_eq!(drawn.contour_edges, recorded);
            let exact = matches!(
                tree.map(|t| t.kind()),
                Some(TreeKind::Exact | TreeKind::HoistedExact)
            );
            assert_eq!(recorded == 0, exact, "{name}: {}", obj.name);
            if let Some(s) = obj.stand_in() {
                // The hull is what was shaded and what is drawn: its vertices, not the mesh's.
                assert!(obj.poly.vertices.len() <= s.mesh_vertices);
                let on_hull = |p: glam::DVec3| obj.poly.vertices.contains(&p);
                let (_, edges) = record
                    .contour_points
                    .iter()
                    .find(|(o, _)| o.is_none())
                    .unwrap();
                assert!(edges.iter().flatten().all(|&p| on_hull(p)));
            }
        }
    }
    assert!(
        stand_ins > 0,
        "the Blender sphere light is drawn as its stand-in hull"
    );
}

/// The environment light in the workbench: a scene file's `[environment]`
/// lights the viewport through the panel's choice; a picked point shows the environment's
/// numbers and union terms; switching the panel's method to `rt` restarts the render, whose
/// frames carry the environment's rays, and picks the point again with its rays recorded.
#[test]
fn the_environment_panel_drives_the_render_and_the_picked_point() {
    use penumbra::scene::environment_spec::EnvMethod;
    use penumbra::shading::RayOutcome;
    let state = Persisted {
        scene: "env_figures".into(),
        ..Persisted::default()
    };
    let mut h = harness(state);
    wait_for_render(&mut h);
    assert_eq!(
        h.state().settings.environment.map,
        penumbra::app::environment_panel::MapChoice::Sky
    );
    let frame = h.state().latest_frame().expect("a frame");
    assert!(frame.frame.output.environment.is_some());
    let size = (
        frame.frame.output.image.width,
        frame.frame.output.image.height,
    );
    // A floor point in a figure's shadow: the figures stand at the middle of the image.
    let mut target = None;
    'scan: for y in (size.1 * 3 / 4..size.1 - 2).step_by(5) {
        for x in (size.0 / 4..size.0 * 3 / 4).step_by(5) {
            h.state_mut().pick(x as f64, y as f64);
            let p = &h.state().inspector.as_ref().unwrap().probe;
            if p.recording
                .environment
                .samples
                .first()
                .is_some_and(|s| s.occluded.is_some_and(|o| o.max_element() > 1e-3))
            {
                target = Some((x, y));
                break 'scan;
            }
        }
    }
    let (x, y) = target.expect("env_figures has floor points in a figure's shadow");
    let ins = h.state().inspector.as_ref().unwrap();
    assert_eq!(ins.probe.radiance, frame.frame.output.image.at(x, y));
    assert!(!ins.probe.recording.environment.terms.is_empty());
    layout::reveal(&mut h.state_mut().tree, Pane::Numbers);
    h.run_steps(2);
    h.get_by_label("E_occluded");
    h.get_by_label("union terms integrated:");

    let mut choice = h.state().settings.environment.clone();
    choice.method = EnvMethod::Rt;
    choice.spp = 16;
    h.state_mut().set_environment(choice);
    wait_for_render(&mut h);
    let frame = h.state().latest_frame().unwrap();
    let stats = frame.frame.output.environment.as_ref().unwrap().stats;
    assert!(stats.rays_traced > 0 && stats.rays_traced < stats.rays_total);
    let rec = &h
        .state()
        .inspector
        .as_ref()
        .unwrap()
        .probe
        .recording
        .environment;
    assert_eq!(rec.rays.len(), 16);
    assert!(rec.rays.iter().any(|r| r.outcome != RayOutcome::Culled));
    h.run_steps(2);
    // The rays' row of the numbers (the layer's check box is in the sphere's menu, closed).
    assert_eq!(h.query_all_by_label("rays").count(), 1);
    assert!(h.state().settings.sphere.layers.rays);
}

/// The command palette (Ctrl+P) finds a command by the words of its name and runs the same
/// command its shortcut runs; while it is open, plain keys go to it and not to the workbench.
#[test]
fn the_command_palette_runs_a_command_by_name() {
    let mut h = harness(Persisted::default());
    h.run_steps(2);
    assert!(!h.state().palette_open() && !h.state().help_shown());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::P);
    h.run_steps(2);
    assert!(h.state().palette_open());
    // "R" would reset the camera, "P" play the stages: typed here, they are text.
    h.event(Event::Text("this help".into()));
    h.run_steps(2);
    h.key_press(egui::Key::Enter);
    h.run_steps(2);
    assert!(!h.state().palette_open(), "Enter runs the match and closes");
    assert!(h.state().help_shown(), "the palette ran ToggleHelp");
    // Esc closes it without running anything.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::P);
    h.run_steps(2);
    assert!(h.state().palette_open());
    h.key_press(egui::Key::Escape);
    h.run_steps(2);
    assert!(!h.state().palette_open());
    assert!(h.state().help_shown());
}

/// File ▸ Embedded scenes and File ▸ Recent issue commands carrying the scene: each opens it
/// and puts it first among the recent scenes.
#[test]
fn the_scene_menus_open_scenes_by_command() {
    use penumbra::app::command::Command;
    let mut h = harness(Persisted::default());
    h.run_steps(2);
    h.state_mut().run_command(Command::OpenEmbedded("fig4"));
    assert_eq!(h.state().settings.scene, "fig4");
    assert_eq!(h.state().settings.recent[0], "fig4");
    h.state_mut()
        .run_command(Command::OpenRecent("default".to_string()));
    assert_eq!(h.state().settings.scene, "default");
    assert_eq!(h.state().settings.recent[..2], ["default", "fig4"]);
    h.run_steps(2);
}

/// Export ▸ Figure: at the point the workbench picks on its own, every view pane's
/// figure is written as SVG, PDF and PNG, the SVG parses, and a view with nothing to show
/// says why instead of writing an empty file. On env_figures, the environment's figure too.
#[test]
fn every_view_exports_its_figure_from_the_workbench() {
    use penumbra::app::figure_export::FigureView;
    let dir = std::env::temp_dir().join(format!("penumbra-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut h = harness(Persisted::default());
    wait_for_render(&mut h);
    h.step();
    assert!(h.state().inspector.is_some(), "a point is picked at start");
    h.state_mut().select_light("panel_light");
    let mut written = 0;
    for view in FigureView::ALL {
        for ext in ["svg", "pdf", "png"] {
            let path = dir.join(format!("{}.{ext}", view.file_stem()));
            match h.state_mut().export_figure(view, &path) {
                Ok(()) => {
                    let bytes = std::fs::read(&path).unwrap();
                    assert!(bytes.len() > 500, "{view:?} {ext}: {} bytes", bytes.len());
                    if ext == "svg" {
                        let text = String::from_utf8(bytes).unwrap();
                        usvg::Tree::from_str(&text, &usvg::Options::default())
                            .unwrap_or_else(|e| panic!("{view:?}: {e}"));
                    }
                    written += 1;
                }
                Err(why) => {
                    // Only the views that need what the default scene lacks.
                    assert!(
                        matches!(view, FigureView::Environment | FigureView::BenchChart),
                        "{view:?}: {why}"
                    );
                    assert!(!path.exists(), "{view:?}: {why}");
                }
            }
        }
    }
    assert_eq!(
        written,
        3 * 4,
        "sphere, hemisphere, plane and light structure"
    );
    // The environment's figure, at a floor point of env_figures.
    let state = Persisted {
        scene: "env_figures".into(),
        ..Persisted::default()
    };
    let mut h = harness(state);
    wait_for_render(&mut h);
    let frame = h.state().latest_frame().expect("a frame");
    let (w, ht) = (
        frame.frame.output.image.width,
        frame.frame.output.image.height,
    );
    h.state_mut().pick((w / 2) as f64, (ht * 7 / 8) as f64);
    let path = dir.join("environment.pdf");
    h.state_mut()
        .export_figure(FigureView::Environment, &path)
        .expect("the environment's figure");
    assert!(std::fs::metadata(&path).unwrap().len() > 1000);
    let _ = std::fs::remove_dir_all(&dir);
}

/// At a point on Blender's monkey the renderer subtracts the monkey face by face, hundreds of
/// stages: the stepper lists them as a few groups, steps over a group at once (to the step
/// that draws all of it), and through it one stage at a time once it is opened.
#[test]
fn a_mesh_taken_face_by_face_is_stepped_as_groups() {
    use penumbra::app::inspector::Inspector;
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender/suzanne.glb");
    let scene = penumbra::scene::scene_file::load_scene(&path).unwrap();
    let ctx = penumbra::render::RenderContext::new(&scene);
    let camera = scene.camera.unwrap();
    let size = (32, 32);
    let found = (0..size.0 * size.1).find_map(|i| {
        let px = ((i % size.0) as f64, (i / size.0) as f64);
        let p = probe(&ctx, "suzanne", &camera, size, px, Method::Analytic, false).ok()?;
        let ins = Inspector::new(p);
        ins.groups.iter().any(|g| g.len > 50).then_some(ins)
    });
    let mut ins = found.expect("a point of the monkey taken face by face");
    let (steps, groups) = (ins.steps.len(), ins.groups.len());
    assert!(groups * 5 < steps, "{groups} groups of {steps} stages");
    // Closed groups: one step each, each landing on its group's last stage.
    let mut landed = Vec::new();
    for _ in 0..groups {
        ins.next();
        landed.push(ins.step.unwrap());
    }
    let lasts: Vec<usize> = ins.groups.iter().map(|g| g.last()).collect();
    assert_eq!(landed, lasts);
    for _ in 0..groups {
        ins.previous();
    }
    assert_eq!(ins.step, None);
    // An opened group: through its stages one by one, then on to the next group.
    let g = ins.groups.iter().position(|g| g.len > 50).unwrap();
    let group = ins.groups[g].clone();
    ins.open_group = Some(g);
    ins.step = Some(group.first);
    for k in 1..group.len {
        ins.next();
        assert_eq!(ins.step, Some(group.first + k));
    }
    ins.next();
    assert_eq!(ins.step, Some(ins.groups[g + 1].last()));
    ins.previous();
    assert_eq!(ins.step, Some(group.last()));
}

/// The derivative in the workbench (issue 40 item 4), on the default scene with the sphere
/// moving along tx: without a selected object the derivative AOV says so and renders nothing
/// of its own; with the sphere selected the viewport shows the derivative (its frame carries
/// the rate, the mapped AOV image and the screenshot both have red and blue pixels); a click
/// on the pixel of largest rate probes it with the rate, whose recording holds moving edges,
/// a stepper stage "derivative: moving edges", the numbers of each edge, and a sphere figure
/// with velocity arrows, drawn on screen. The screenshot is written to
/// `$CARGO_TARGET_TMPDIR/derivative_workbench.png`.
#[test]
fn the_derivative_aov_and_the_moving_edges_on_the_sphere() {
    use penumbra::app::tonemap::Aov;
    use penumbra::figure::Item;
    use penumbra::shading::derivative::Axis;
    use penumbra::views::sphere::{VELOCITY_LEGEND, colours, drawing};
    use penumbra::views::{FigureRequest, recording_figure};

    let mut h = harness(Persisted::default());
    wait_for_render(&mut h);
    assert!(
        h.state()
            .latest_frame()
            .unwrap()
            .frame
            .output
            .derivative
            .is_none()
    );

    // No object selected: the AOV says why and the render is the plain image.
    h.state_mut().settings.aov = Aov::Derivative;
    wait_for_render(&mut h);
    let why = h.state().derivative_motion().unwrap_err();
    assert!(why.contains("select an object"), "{why}");
    assert!(
        h.state()
            .latest_frame()
            .unwrap()
            .frame
            .output
            .derivative
            .is_none()
    );

    // The sphere along tx.
    h.state_mut().select_object("sphere");
    h.state_mut().editor.set_axis(Axis::Tx);
    wait_for_render(&mut h);
    h.run_steps(2);
    let ctx = h.state().render_context().unwrap();
    let sphere = ctx
        .scene
        .objects
        .iter()
        .position(|o| o.name == "sphere")
        .unwrap();
    let frame = h.state().latest_frame().expect("a frame");
    assert_eq!(frame.frame.scale, 1);
    let d = frame
        .frame
        .output
        .derivative
        .as_ref()
        .expect("the derivative AOV renders the derivative");
    assert_eq!(
        (d.motion.object as usize, d.motion.axis),
        (sphere, Axis::Tx)
    );
    let size = (d.derivative.width, d.derivative.height);
    let lum: Vec<f64> = d
        .derivative
        .pixels
        .iter()
        .map(|&c| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z)
        .collect();
    let unmasked = |i: usize| d.mask.pixels[i].x == 0.0;
    let positive = (0..lum.len())
        .filter(|&i| unmasked(i) && lum[i] > 0.0)
        .count();
    let negative = (0..lum.len())
        .filter(|&i| unmasked(i) && lum[i] < 0.0)
        .count();
    assert!(
        positive > 100 && negative > 100,
        "{positive} > 0, {negative} < 0"
    );
    // The AOV as the render thread mapped it: red where the image brightens, blue where it
    // darkens, grey where masked.
    let (_, img, range) = frame.display.as_ref().expect("mapped for display");
    let (_, top) = range.expect("the scale of the colour map");
    assert!(top > 0.0);
    let red = |c: &egui::Color32| c.r() > 200 && c.g() < 140 && c.b() < 140;
    let blue = |c: &egui::Color32| c.b() > 200 && c.r() < 140 && c.g() < 140;
    let (reds, blues) = (
        img.pixels.iter().filter(|c| red(c)).count(),
        img.pixels.iter().filter(|c| blue(c)).count(),
    );
    assert!(reds > 50 && blues > 50, "{reds} red, {blues} blue pixels");
    let status = h.state().derivative_label(&d.motion);
    assert_eq!(status, "d/dtx of sphere");

    // Pick the unmasked pixel of largest rate in the sphere's shadow on another object (off
    // the image's border), as a click picks it (a click could land on the sphere's handles,
    // which take the pointer first). There some edges of the visible polygon move (the
    // sphere's outline) and others stay (the light's).
    let (w, ht) = size;
    let basis = frame.camera.basis().unwrap();
    let on_other = |x: u32, y: u32| {
        let ray = penumbra::accel::Ray {
            origin: basis.eye,
            dir: basis.direction(x as f64 + 0.5, y as f64 + 0.5, w, ht),
        };
        ctx.primary_hit(&ray)
            .is_some_and(|hit| hit.point.object.is_some_and(|o| o as usize != sphere))
    };
    let best = (0..lum.len())
        .filter(|&i| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            unmasked(i) && x > 2 && y > 2 && x + 3 < w && y + 3 < ht && on_other(x, y)
        })
        .max_by(|&a, &b| lum[a].abs().total_cmp(&lum[b].abs()))
        .unwrap();
    let (x, y) = (best as u32 % w, best as u32 / w);
    h.state_mut().pick(x as f64, y as f64);
    h.step();
    let ins = h.state().inspector.as_ref().expect("picked");
    assert_eq!(ins.probe.pixel, (x as f64, y as f64));
    let pd = ins.probe.derivative.as_ref().expect("probed with the rate");
    assert_eq!(pd.label(), "d/dtx of sphere");
    // The probe's rate is the rendered pixel's (`--aa 1`: one sample, the same function).
    let rendered = d.derivative.pixels[best];
    assert!(
        (pd.rate - rendered).abs().max_element() <= 1e-9 * rendered.abs().max_element(),
        "{} against {rendered}",
        pd.rate
    );
    let moving = ins
        .probe
        .recording
        .lights
        .iter()
        .flat_map(|l| &l.moving_edges)
        .filter(|e| penumbra::views::stages::moves(e))
        .count();
    let edges = ins
        .probe
        .recording
        .lights
        .iter()
        .map(|l| l.moving_edges.len())
        .sum::<usize>();
    assert!(
        moving > 0 && moving < edges,
        "{moving} of {edges} edges move"
    );
    let stage = ins
        .steps
        .iter()
        .position(|s| s.kind == StepKind::Derivative)
        .expect("a derivative stage");
    assert!(
        ins.steps[stage].label.contains("moving edges"),
        "{}",
        ins.steps[stage].label
    );

    // The sphere's figure (what the pane paints and `penumbra figure` writes) has the arrows:
    // their legend and their heads.
    let fig = recording_figure(&ins.probe, None, &FigureRequest::default()).unwrap();
    assert!(
        fig.items
            .iter()
            .any(|i| matches!(i, Item::Text { text, .. } if text == VELOCITY_LEGEND))
    );
    let heads = fig
        .items
        .iter()
        .filter(|i| matches!(i, Item::Fill { color, .. } if *color == colours::VELOCITY))
        .count();
    let arrows = drawing(&ins.probe, None, &Default::default()).velocities;
    assert!(!arrows.is_empty());
    assert_eq!(heads, arrows.len());
    // Each arrow is v_n = m · dν/dθ along −ν of its edge.
    for v in &arrows {
        assert!((v.outward.length() - 1.0).abs() < 1e-9 && v.outward.dot(v.at).abs() < 1e-9);
    }

    // The stepper at the derivative's stage, the numbers of its edges.
    h.state_mut().inspector.as_mut().unwrap().step = Some(stage);
    layout::reveal(&mut h.state_mut().tree, Pane::Numbers);
    h.run_steps(2);
    assert!(h.query_all_by_label("diffuse share").count() > 0);
    assert!(h.query_all_by_label("lobe share").count() > 0);
    layout::reveal(&mut h.state_mut().tree, Pane::Stages);
    layout::reveal(&mut h.state_mut().tree, Pane::Sphere);
    h.run_steps(2);
    assert!(h.query_all_by_label(&ins_label(&h, stage)).count() > 0);

    // The screenshot: the derivative's colours in the viewport, the arrows on the sphere.
    let shot = h.render().expect("the harness renders");
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("derivative_workbench.png");
    shot.save(&path).unwrap();
    eprintln!("screenshot: {}", path.display());
    let ppp = h.ctx.pixels_per_point();
    let count = |r: egui::Rect, f: &dyn Fn([u8; 3]) -> bool| {
        let (x0, y0) = ((r.min.x * ppp) as u32, (r.min.y * ppp) as u32);
        let (x1, y1) = ((r.max.x * ppp) as u32, (r.max.y * ppp) as u32);
        let mut n = 0;
        for y in y0..y1.min(shot.height()) {
            for x in x0..x1.min(shot.width()) {
                let p = shot.get_pixel(x, y).0;
                n += f([p[0], p[1], p[2]]) as u32;
            }
        }
        n
    };
    let view = h.state().viewport_rect.unwrap();
    let on_screen_red = count(view, &|c| c[0] > 200 && c[1] < 140 && c[2] < 140);
    let on_screen_blue = count(view, &|c| c[2] > 200 && c[0] < 140 && c[1] < 140);
    assert!(
        on_screen_red > 100 && on_screen_blue > 100,
        "{on_screen_red} red, {on_screen_blue} blue in the viewport"
    );
    let sphere_rect = h.state().settings.sphere.sphere_side;
    assert!(sphere_rect > 100.0);
    let [vr, vg, vb] = colours::VELOCITY;
    let near =
        |c: [u8; 3]| c[0].abs_diff(vr) < 30 && c[1].abs_diff(vg) < 30 && c[2].abs_diff(vb) < 30;
    let arrow_pixels = count(
        egui::Rect::from_min_size(Pos2::ZERO, egui::vec2(1280.0, 800.0)),
        &near,
    ) - count(view, &near);
    assert!(
        arrow_pixels > 20,
        "{arrow_pixels} pixels of velocity arrows"
    );

    // Back to the plain image: no derivative is rendered.
    h.state_mut().settings.aov = Aov::Final;
    wait_for_render(&mut h);
    assert!(
        h.state()
            .latest_frame()
            .unwrap()
            .frame
            .output
            .derivative
            .is_none()
    );
}

fn ins_label(h: &Harness<'static, WorkbenchApp>, stage: usize) -> String {
    h.state().inspector.as_ref().unwrap().steps[stage]
        .label
        .clone()
}
