//! Figures as SVG: a chart's one description, written as SVG, parses (usvg), and
//! drawn by an independent SVG renderer (resvg) it shows what the PNG back end draws from the
//! same description: the same pixels up to anti-aliasing, and a layer left out of the SVG shows.

use penumbra::figure::plot::{Chart, Series, chart_figure};
use penumbra::figure::{Figure, Item, raster, svg};

fn chart() -> Chart {
    let line = |name: &str, k: f64| Series {
        name: name.into(),
        points: (0..12)
            .map(|i| {
                let t = 10f64.powf(-2.0 + 0.3 * i as f64);
                (t, k / t.sqrt())
            })
            .collect(),
        connect: true,
    };
    Chart {
        title: "Run time against error".into(),
        x_label: "time (s)".into(),
        y_label: "RMSE".into(),
        x_log: true,
        y_log: true,
        series: vec![
            line("ratio", 0.02),
            line("mc", 0.1),
            Series {
                name: "analytic".into(),
                points: vec![(0.05, 1e-4)],
                connect: false,
            },
        ],
    }
}

/// The figure's items but its labels (SVG text is drawn with a font a headless test may not
/// have; the stroke font draws the PNG's).
pub(crate) fn shapes_only(fig: &Figure) -> Figure {
    Figure {
        items: fig
            .items
            .iter()
            .filter(|i| !matches!(i, Item::Text { .. }))
            .cloned()
            .collect(),
        ..fig.clone()
    }
}

/// `figure`'s SVG drawn by resvg, as straight RGBA bytes.
pub(crate) fn resvg_pixels(figure: &Figure) -> Vec<u8> {
    let text = svg::to_svg(figure);
    let tree = usvg::Tree::from_str(&text, &usvg::Options::default()).expect("the SVG parses");
    let mut pm = resvg::tiny_skia::Pixmap::new(figure.width, figure.height).unwrap();
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pm.as_mut(),
    );
    pm.pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect()
}

fn raster_pixels(figure: &Figure) -> Vec<u8> {
    raster::render(figure)
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect()
}

/// The fraction of pixels where some channel differs by more than 48 of 255.
pub(crate) fn differing(a: &[u8], b: &[u8]) -> f64 {
    let n = a.len() / 4;
    let bad = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > 48))
        .count();
    bad as f64 / n as f64
}

#[test]
fn a_chart_as_svg_parses_and_shows_what_the_png_shows() {
    let fig = chart_figure(&chart(), 480, 320);
    // Every label is an SVG text element, and the whole document parses.
    let text = svg::to_svg(&fig);
    let labels = fig
        .items
        .iter()
        .filter(|i| matches!(i, Item::Text { .. }))
        .count();
    assert!(labels > 10, "{labels} labels");
    assert_eq!(text.matches("<text ").count(), labels);
    usvg::Tree::from_str(&text, &usvg::Options::default()).expect("the SVG parses");

    let shapes = shapes_only(&fig);
    let ours = raster_pixels(&shapes);
    let theirs = resvg_pixels(&shapes);
    let same = differing(&ours, &theirs);
    eprintln!(
        "PNG and SVG back ends differ at {:.4} % of the pixels",
        100.0 * same
    );
    assert!(same < 0.001, "{same}");
    // Each series' line left out of the SVG: the comparison sees it.
    for k in 0..2 {
        let mut missing = shapes.clone();
        let line = missing
            .items
            .iter()
            .enumerate()
            .filter(|(_, i)| matches!(i, Item::Stroke { clip: Some(_), .. }))
            .nth(k)
            .map(|(j, _)| j)
            .expect("a clipped series line");
        missing.items.remove(line);
        let gone = differing(&ours, &resvg_pixels(&missing));
        eprintln!("series {k} left out: {:.4} %", 100.0 * gone);
        assert!(
            gone > 3.0 * same.max(0.0005),
            "series {k}: {gone} vs {same}"
        );
    }
}
