//! The workbench paints a view's figure (`app::figure_painter`) as an independent SVG renderer
//! (resvg) draws the same figure's SVG: on the sphere at a penumbra point of fig4,
//! the two images agree up to anti-aliasing, and leaving one layer out of the SVG (the visible
//! region, the light's region) shows as a difference several times larger. Labels are left
//! out of both: egui draws its own font, a headless resvg has none.

use crate::figure_svg::{resvg_pixels, shapes_only};
use egui_kittest::Harness;
use penumbra::app::figure_painter::{self, FigureRect};
use penumbra::figure::{Figure, Item};
use penumbra::inspect::{interesting_pixel, probe};
use penumbra::render::RenderContext;
use penumbra::scene::scene_file;
use penumbra::shading::Method;
use penumbra::views::sphere::{Layers, drawing, region_of_interest};
use penumbra::views::{self, SphereCamera, Style};

/// `figure` painted by egui through the workbench's painter, rendered by wgpu, as straight
/// RGBA bytes.
fn egui_pixels(figure: &Figure) -> Vec<u8> {
    let fig = figure.clone();
    let size = egui::Vec2::new(fig.width as f32, fig.height as f32);
    let mut h = Harness::builder()
        .with_size(size)
        .with_pixels_per_point(1.0)
        .build_ui(move |ui| {
            let painter = ui.ctx().layer_painter(egui::LayerId::background());
            let at = FigureRect {
                origin: egui::Pos2::ZERO,
                scale: 1.0,
            };
            figure_painter::paint(&painter, &fig, at);
        });
    h.run();
    let img = h.render().expect("the harness renders");
    assert_eq!((img.width(), img.height()), (figure.width, figure.height));
    img.into_raw()
}

/// The fraction of pixels where some channel differs by more than 24 of 255 (a translucent
/// region over white changes its pixels by about 40 to 130).
fn differing(a: &[u8], b: &[u8]) -> f64 {
    let bad = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > 24))
        .count();
    bad as f64 / (a.len() / 4) as f64
}

#[test]
fn egui_paints_what_the_svg_shows() {
    let scene = scene_file::load_embedded("fig4").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let size = (160, 120);
    let pixel = interesting_pixel(&ctx, &cam, size, 24).expect("a penumbra pixel");
    let p = probe(&ctx, "fig4", &cam, size, pixel, Method::Analytic, true).unwrap();
    let d = drawing(&p, None, &Layers::default());
    let camera = SphereCamera::framed(&region_of_interest(&p, None));
    let fig = shapes_only(&views::sphere_figure(&d, &camera, 320, Style::Print));
    let ours = egui_pixels(&fig);
    let theirs = resvg_pixels(&fig);
    let same = differing(&ours, &theirs);
    eprintln!(
        "egui and resvg differ at {:.3} % of the pixels",
        100.0 * same
    );
    assert!(same < 0.02, "{same}");
    // Each translucent region left out of the SVG in turn: where its absence changes a
    // noticeable part of resvg's own picture, the comparison with egui's sees it.
    let mut seen = 0;
    for (k, item) in fig.items.iter().enumerate() {
        if !matches!(item, Item::Fill { opacity, .. } if *opacity < 0.7) {
            continue;
        }
        let mut missing = fig.clone();
        missing.items.remove(k);
        let without = resvg_pixels(&missing);
        let effect = differing(&theirs, &without);
        if effect < 0.005 {
            continue;
        }
        let gone = differing(&ours, &without);
        eprintln!(
            "region {k} left out: changes {:.2} % of the SVG's pixels; egui's differ at {:.2} %",
            100.0 * effect,
            100.0 * gone
        );
        assert!(gone > same + 0.5 * effect, "region {k}: {gone} vs {same}");
        seen += 1;
    }
    assert!(seen >= 2, "{seen} regions large enough to see");
}
