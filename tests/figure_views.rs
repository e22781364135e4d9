//! The debugger's views as figures, on every embedded scene at the point the
//! workbench picks on its own: each view's figure, at every stage, parses as SVG (usvg) and
//! as PDF (its objects and content stream), no two of its labels overlap, and the sphere's
//! default framing holds every light's silhouette, facing the eye.

use penumbra::figure::font::{Align, text_width};
use penumbra::figure::{Figure, Item, pdf, svg};
use penumbra::inspect::{Probe, interesting_pixel, probe};
use penumbra::render::RenderContext;
use penumbra::scene::scene_file;
use penumbra::shading::{Method, Stage};
use penumbra::views::labels::overlaps;
use penumbra::views::sphere::{Layers, drawing, region_of_interest};
use penumbra::views::stages::{plane_subject, probe_steps};
use penumbra::views::{self, SphereCamera, Style};

/// The embedded scene's auto-picked point (`inspect::interesting_pixel`, as the workbench
/// picks on first start), probed with the GH steps as a pick records them.
fn auto_probe(name: &str) -> Option<Probe> {
    let scene = scene_file::load_embedded(name).unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let size = (160, 120);
    let pixel = interesting_pixel(&ctx, &cam, size, 24)?;
    Some(probe(&ctx, name, &cam, size, pixel, Method::Analytic, true).unwrap())
}

/// The box a label covers, whatever its alignment (the placer's metrics: 0.8 em above the
/// baseline, 0.25 em below, the stroke font's advance).
fn label_box(text: &str, at: (f32, f32), size: f32, align: Align) -> [f32; 4] {
    let w = text_width(text, size);
    let left = match align {
        Align::Left => at.0,
        Align::Center => at.0 - 0.5 * w,
        Align::Right => at.0 - w,
    };
    [left, at.1 - 0.8 * size, left + w, at.1 + 0.25 * size]
}

/// Every pair of overlapping labels of `fig`, by text.
fn overlapping_labels(fig: &Figure) -> Vec<(String, String)> {
    let boxes: Vec<(&str, [f32; 4])> = fig
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Text { text, at, style } if style.rotate == 0.0 => {
                Some((text.as_str(), label_box(text, *at, style.size, style.align)))
            }
            _ => None,
        })
        .collect();
    let mut out = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            if overlaps(&a.1, &b.1) {
                out.push((a.0.to_string(), b.0.to_string()));
            }
        }
    }
    out
}

/// The document parses as SVG, and the PDF holds one page whose content stream paints every
/// fill and stroke of the figure (one operator each, after the background's fill).
fn check_documents(fig: &Figure, what: &str) {
    let text = svg::to_svg(fig);
    usvg::Tree::from_str(&text, &usvg::Options::default())
        .unwrap_or_else(|e| panic!("{what}: the SVG does not parse: {e}"));
    let bytes = pdf::to_pdf(fig);
    let doc = String::from_utf8_lossy(&bytes);
    assert!(
        doc.starts_with("%PDF-") && doc.trim_end().ends_with("%%EOF"),
        "{what}"
    );
    assert_eq!(
        doc.matches("/Type /Page\n").count() + doc.matches("/Type /Page ").count(),
        1
    );
    let fills = fig
        .items
        .iter()
        .filter(|i| matches!(i, Item::Fill { .. }))
        .count();
    let strokes = fig
        .items
        .iter()
        .filter(|i| matches!(i, Item::Stroke { .. }))
        .count();
    let texts = fig
        .items
        .iter()
        .filter(|i| matches!(i, Item::Text { .. }))
        .count();
    let ops = |op: &str| doc.lines().filter(|l| *l == op).count();
    assert_eq!(ops("f"), fills + 1, "{what}: fills");
    assert_eq!(ops("S"), strokes, "{what}: strokes");
    assert_eq!(ops("BT"), texts, "{what}: labels");
}

#[test]
fn every_view_at_every_stage_parses_and_no_labels_overlap() {
    let mut figures = 0;
    let mut labels = 0;
    for name in scene_file::embedded_scene_names() {
        let Some(p) = auto_probe(name) else {
            eprintln!("{name}: no lit pixel to pick");
            continue;
        };
        let steps = probe_steps(&p);
        let camera = SphereCamera::framed(&region_of_interest(&p, None));
        let stages = std::iter::once(None).chain((0..steps.len()).map(Some));
        for current in stages {
            let step = current.map(|i| &steps[i]);
            let d = drawing(&p, step, &Layers::default());
            let mut figs = vec![
                (
                    "sphere",
                    views::sphere_figure(&d, &camera, 800, Style::Print),
                ),
                (
                    "hemisphere",
                    views::hemisphere_figure(&d, false, 800, Style::Print),
                ),
                (
                    "hemisphere fit",
                    views::hemisphere_figure(&d, true, 640, Style::Screen),
                ),
            ];
            if let Some((sd, phase)) = plane_subject(&p, &steps, current) {
                figs.push((
                    "plane",
                    views::plane_figure(sd, "o", phase, 800, Style::Print),
                ));
            }
            for (view, fig) in figs {
                let what = format!("{name} {view} at stage {current:?}");
                let bad = overlapping_labels(&fig);
                assert!(bad.is_empty(), "{what}: overlapping labels {bad:?}");
                labels += fig
                    .items
                    .iter()
                    .filter(|i| matches!(i, Item::Text { .. }))
                    .count();
                // The documents of every view at every stage: parsing is quick, but the
                // stages of one view differ little; the first and last suffice.
                if current.is_none() || current == Some(steps.len() - 1) {
                    check_documents(&fig, &what);
                }
                figures += 1;
            }
        }
    }
    eprintln!("{figures} figures, {labels} labels, none overlapping");
    assert!(figures > 100, "{figures}");
}

#[test]
fn the_sphere_is_framed_on_every_light() {
    for name in scene_file::embedded_scene_names() {
        let Some(p) = auto_probe(name) else {
            continue;
        };
        let camera = SphereCamera::framed(&region_of_interest(&p, None));
        let (right, up, eye) = camera.basis();
        let size = 800.0;
        let scale = 0.45 * size * camera.zoom as f64;
        for rec in &p.recording.lights {
            for (stage, poly) in &rec.polygons {
                if *stage != Stage::Silhouette {
                    continue;
                }
                let v: Vec<_> = poly.vertices().iter().map(|x| x.normalize()).collect();
                // A silhouette within a hemisphere about its mean direction must face the
                // eye whole; a larger one is seen whole at zoom 1.
                let mean = v.iter().copied().sum::<glam::DVec3>().normalize();
                let within = v.iter().all(|x| x.dot(mean) > 0.0);
                for x in &v {
                    let px = 0.5 * size + x.dot(right) * scale;
                    let py = 0.5 * size - x.dot(up) * scale;
                    assert!(
                        (0.0..=size).contains(&px) && (0.0..=size).contains(&py),
                        "{name}: light {} corner at ({px:.0}, {py:.0}), zoom {}",
                        rec.light,
                        camera.zoom
                    );
                    if within && camera.zoom > 1.0 {
                        assert!(x.dot(eye) >= 0.0, "{name}: a corner behind the sphere");
                    }
                }
            }
        }
        eprintln!("{name}: zoom {:.2}", camera.zoom);
    }
}
