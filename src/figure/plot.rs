//! Scatter and line charts, described once as a [`Figure`] ([`chart_figure`]) and drawn from
//! it as PNG (tiny-skia and the stroke font of [`font`](mod@super::font)) or written as SVG.
//!
//! A chart has a white background, a frame, ticks at nice values with grid lines and labels
//! (1-2-5 steps on a linear axis; decades subdivided at 2 and 5 on a log axis), axis labels, a
//! title and a legend. Series take colours from the Okabe–Ito palette (told apart with the
//! common forms of colour blindness) and marker shapes from `MARKERS`; the two cycle with
//! different periods, so the first 56 series differ in colour or marker.
//!
//! Points that cannot be placed are skipped, never a panic: a coordinate that is NaN or
//! infinite, or that is not positive on a log axis. A connected series breaks its line at a
//! skipped point rather than jumping over it.

use crate::error::InFile;

use super::description::{Figure, Item, Shape, Subpath};
use super::font::{self, Align, TextStyle};
use super::{raster, svg};
use std::path::Path;
use tiny_skia::Pixmap;

/// One set of points of a chart.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// The legend entry (no entry when empty).
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// Join consecutive points with lines, in the order given.
    pub connect: bool,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
}

/// Okabe & Ito's colour-blind-safe palette, in the order series use it (yellow last: it is
/// faint on white).
pub(crate) const PALETTE: [[u8; 3]; 8] = [
    [0, 114, 178],   // blue
    [213, 94, 0],    // vermillion
    [0, 158, 115],   // bluish green
    [204, 121, 167], // reddish purple
    [230, 159, 0],   // orange
    [86, 180, 233],  // sky blue
    [0, 0, 0],       // black
    [240, 228, 66],  // yellow
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
    Cross,
    Plus,
}

pub(crate) const MARKERS: [Marker; 7] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
    Marker::Cross,
    Marker::Plus,
];

/// Colour and marker of the `i`-th series.
pub(crate) fn series_style(i: usize) -> ([u8; 3], Marker) {
    (PALETTE[i % PALETTE.len()], MARKERS[i % MARKERS.len()])
}

/// A tick of an axis.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tick {
    pub value: f64,
    /// Major ticks get darker grid lines (all ticks of a linear axis, decades of a log axis).
    pub major: bool,
    /// `None` for a tick drawn without a label.
    pub label: Option<String>,
}

/// The range and ticks of one axis; the range always starts and ends on a tick.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Axis {
    pub min: f64,
    pub max: f64,
    pub log: bool,
    pub ticks: Vec<Tick>,
}

/// 10^e, correctly rounded (so ticks are the same numbers as their decimal labels).
fn pow10(e: i32) -> f64 {
    format!("1e{e}").parse().expect("a float literal")
}

/// k·10^e, correctly rounded for |k| < 2^53.
fn scaled(k: i64, e: i32) -> f64 {
    if e >= 0 {
        k as f64 * pow10(e)
    } else {
        k as f64 / pow10(-e)
    }
}

/// The decade of a positive `v`: 10^k ≤ v < 10^(k+1).
fn decade(v: f64) -> i32 {
    let mut k = v.log10().floor() as i32;
    while pow10(k + 1) <= v {
        k += 1;
    }
    while pow10(k) > v {
        k -= 1;
    }
    k
}

const STEPS: [i64; 3] = [1, 2, 5];

impl Axis {
    /// A linear axis covering [lo, hi], in 1-2-5 steps (about five of them), widened to whole
    /// steps. An empty or invalid range gives [0, 1]; a single value is widened by half its size
    /// (by 1 at 0).
    pub(crate) fn linear(lo: f64, hi: f64) -> Axis {
        let (lo, hi) = if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            (0.0, 1.0)
        } else if lo == hi {
            let d = if lo == 0.0 { 1.0 } else { 0.5 * lo.abs() };
            (lo - d, hi + d)
        } else {
            (lo, hi)
        };
        let raw = (hi - lo) / 5.0;
        if !(raw.is_finite() && raw > 1e-290) {
            return Axis::linear(0.0, 1.0);
        }
        let e = decade(raw);
        let norm = raw / pow10(e);
        let (m, e) = match STEPS.iter().find(|&&m| norm <= m as f64 * (1.0 + 1e-9)) {
            Some(&m) => (m, e),
            None => (1, e + 1),
        };
        let step = scaled(m, e);
        let k0 = (lo / step + 1e-9).floor() as i64;
        let k1 = (hi / step - 1e-9).ceil() as i64;
        let ticks: Vec<Tick> = (k0..=k1)
            .map(|k| {
                let value = scaled(k * m, e);
                Tick {
                    value,
                    major: true,
                    label: Some(linear_label(value, e)),
                }
            })
            .collect();
        Axis {
            min: ticks[0].value,
            max: ticks[ticks.len() - 1].value,
            log: false,
            ticks,
        }
    }

    /// A log axis covering [lo, hi], widened to the nearest 1, 2 or 5 times a power of ten
    /// beyond each end. Ticks at every 1, 2 and 5 × 10^k inside; decades are major. Spanning at
    /// most two decades, every tick is labelled; beyond, only decades, and only every n-th
    /// decade past eight of them. A range that is not positive and finite gives [1, 10]; the
    /// ends are clamped to [1e−300, 1e300].
    pub(crate) fn log(lo: f64, hi: f64) -> Axis {
        let ok = |v: f64| v > 0.0 && v.is_finite();
        if !(ok(lo) && ok(hi) && lo <= hi) {
            return Axis::log(1.0, 10.0);
        }
        // Keep the ends and their neighbouring decades representable.
        let (lo, hi) = (lo.clamp(1e-300, 1e300), hi.clamp(1e-300, 1e300));
        // Nice values 1, 2, 5 × 10^k around a decade.
        let nice = |k: i32| STEPS.map(|m| scaled(m, k));
        let kl = decade(lo);
        let mut min = nice(kl)
            .into_iter()
            .rfind(|&v| v <= lo)
            .expect("10^k <= lo");
        let kh = decade(hi);
        let mut max = nice(kh)
            .into_iter()
            .chain([pow10(kh + 1)])
            .find(|&v| v >= hi)
            .expect("hi < 10^(k+1)");
        if min == max {
            // A single nice value: one step either way.
            let mut below = nice(kl - 1).into_iter().chain(nice(kl));
            min = below.rfind(|&v| v < min).expect("a smaller value");
            max = nice(kh)
                .into_iter()
                .chain(nice(kh + 1))
                .find(|&v| v > max)
                .expect("a larger value");
        }
        let decades = (max / min).log10();
        let stride = if decades > 8.0 {
            (decades / 8.0).ceil() as i32
        } else {
            1
        };
        let mut ticks = Vec::new();
        for k in decade(min)..=decade(max) {
            for m in STEPS {
                let value = scaled(m, k);
                if value < min || value > max {
                    continue;
                }
                let labelled = if decades <= 2.0 + 1e-9 {
                    true
                } else {
                    m == 1 && k.rem_euclid(stride) == 0
                };
                ticks.push(Tick {
                    value,
                    major: m == 1,
                    label: labelled.then(|| log_label(m, k)),
                });
            }
        }
        Axis {
            min,
            max,
            log: true,
            ticks,
        }
    }

    /// The axis for some data: values the axis cannot show (see [`Axis::accepts`]) are left
    /// out.
    pub(crate) fn from_data(values: impl IntoIterator<Item = f64>, log: bool) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            if accepts(log, v) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if log {
            Axis::log(lo, hi)
        } else {
            Axis::linear(lo, hi)
        }
    }

    /// Whether `v` can be placed: finite, and positive on a log axis.
    pub(crate) fn accepts(&self, v: f64) -> bool {
        accepts(self.log, v)
    }

    fn scale(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    /// The position of `v` along the axis: 0 at `min`, 1 at `max` (linear in v, or in log v).
    pub(crate) fn map(&self, v: f64) -> f64 {
        let (a, b) = (self.scale(self.min), self.scale(self.max));
        (self.scale(v) - a) / (b - a)
    }

    /// The inverse of [`Axis::map`].
    #[cfg(test)]
    pub(crate) fn unmap(&self, f: f64) -> f64 {
        let (a, b) = (self.scale(self.min), self.scale(self.max));
        let s = a + f * (b - a);
        if self.log { 10f64.powf(s) } else { s }
    }
}

fn accepts(log: bool, v: f64) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// A linear tick label with as many decimals as the step 10^e needs.
fn linear_label(v: f64, e: i32) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if !(-5..6).contains(&e) {
        format!("{v:e}")
    } else {
        format!("{:.*}", (-e).max(0) as usize, v)
    }
}

/// The label of m·10^k: plain from 0.001 to 10000, `me k` beyond.
fn log_label(m: i64, k: i32) -> String {
    if (-3..=4).contains(&k) {
        format!("{:.*}", (-k).max(0) as usize, scaled(m, k))
    } else {
        format!("{m}e{k}")
    }
}

// Layout, in pixels.
const LABEL: f32 = 11.0;
const TITLE: f32 = 13.0;
const PAD: f32 = 10.0;
const GAP: f32 = 5.0;
const TICK: f32 = 4.0;
const MARKER_R: f32 = 3.5;
const LEGEND_SAMPLE: f32 = 24.0;
const LEGEND_ROW: f32 = 16.0;
const TEXT: [u8; 3] = [34, 34, 34];

/// The plot area in pixels; edges lie on pixel centres so the frame is crisp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlotRect {
    pub left: f32,
    pub top: f32,
    pub right: f32,
    pub bottom: f32,
}

/// Where everything of a chart goes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ChartLayout {
    pub width: u32,
    pub height: u32,
    pub plot: PlotRect,
    pub x: Axis,
    pub y: Axis,
    /// The legend box (left, top, right, bottom), if any series has a name.
    pub legend: Option<PlotRect>,
}

/// Largest image side [`render_chart`] draws.
pub(crate) use super::raster::MAX_SIDE;

impl ChartLayout {
    /// Axes from the placeable points, then the margins their labels need. The size is clamped
    /// to 1..=[`MAX_SIDE`] per side.
    pub fn new(chart: &Chart, width: u32, height: u32) -> Self {
        let (width, height) = (width.clamp(1, MAX_SIDE), height.clamp(1, MAX_SIDE));
        let placeable = || {
            chart
                .series
                .iter()
                .flat_map(|s| &s.points)
                .filter(|&&(x, y)| accepts(chart.x_log, x) && accepts(chart.y_log, y))
        };
        let x = Axis::from_data(placeable().map(|p| p.0), chart.x_log);
        let y = Axis::from_data(placeable().map(|p| p.1), chart.y_log);

        let descent = font::descent(LABEL);
        let label_widths = |a: &Axis| {
            a.ticks
                .iter()
                .filter_map(|t| t.label.as_deref())
                .map(|l| font::text_width(l, LABEL))
                .fold(0.0f32, f32::max)
        };
        let mut left = PAD + label_widths(&y) + GAP + TICK;
        if !chart.y_label.is_empty() {
            left += LABEL + GAP;
        }
        let mut top = PAD + 0.5 * LABEL;
        if !chart.title.is_empty() {
            top = PAD + font::cap_height(TITLE) + 2.0 * GAP + 0.5 * LABEL;
        }
        let mut bottom = height as f32 - (PAD + TICK + GAP + font::cap_height(LABEL) + descent);
        if !chart.x_label.is_empty() {
            bottom -= LABEL + GAP;
        }
        let names: Vec<&str> = chart.series.iter().map(|s| s.name.as_str()).collect();
        let legend_w = names
            .iter()
            .filter(|n| !n.is_empty())
            .map(|n| font::text_width(n, LABEL))
            .fold(None, |m: Option<f32>, w| Some(m.map_or(w, |m| m.max(w))))
            // (+1: the strokes' half width on either side)
            .map(|w| 2.0 * GAP + LEGEND_SAMPLE + GAP + w + 1.0);
        let mut right = width as f32 - PAD - legend_w.map_or(0.0, |w| w + PAD);
        // Keep a plot area however small the image.
        right = right.max(left + 10.0);
        bottom = bottom.max(top + 10.0);
        let crisp = |v: f32| v.round() + 0.5;
        let plot = PlotRect {
            left: crisp(left),
            top: crisp(top),
            right: crisp(right),
            bottom: crisp(bottom),
        };
        let legend = legend_w.map(|w| {
            let rows = names.iter().filter(|n| !n.is_empty()).count() as f32;
            PlotRect {
                left: plot.right + PAD,
                top: plot.top,
                right: plot.right + PAD + w,
                bottom: plot.top + GAP + rows * LEGEND_ROW + GAP,
            }
        });
        ChartLayout {
            width,
            height,
            plot,
            x,
            y,
            legend,
        }
    }

    /// The pixel position of a data point, `None` where it cannot be placed.
    pub(crate) fn to_pixel(&self, x: f64, y: f64) -> Option<(f32, f32)> {
        if !(self.x.accepts(x) && self.y.accepts(y)) {
            return None;
        }
        let (fx, fy) = (self.x.map(x), self.y.map(y));
        let near = |f: f64| (-0.5..=1.5).contains(&f);
        if !(near(fx) && near(fy)) {
            return None;
        }
        let p = &self.plot;
        let px = p.left as f64 + fx * (p.right - p.left) as f64;
        let py = p.bottom as f64 - fy * (p.bottom - p.top) as f64;
        Some((px as f32, py as f32))
    }
}

/// The shape of `marker` at `(x, y)`, and whether it is filled (else stroked 2 px wide).
fn marker_shape(marker: Marker, (x, y): (f32, f32)) -> (Shape, bool) {
    let r = MARKER_R;
    let polygon = |pts: &[(f32, f32)]| {
        Shape::Path(vec![Subpath {
            points: pts.iter().map(|p| (x + p.0, y + p.1)).collect(),
            closed: true,
        }])
    };
    let strokes = |segments: [[(f32, f32); 2]; 2]| {
        Shape::Path(
            segments
                .iter()
                .map(|s| Subpath {
                    points: s.to_vec(),
                    closed: false,
                })
                .collect(),
        )
    };
    match marker {
        Marker::Circle => (
            Shape::Circle {
                centre: (x, y),
                radius: r,
            },
            true,
        ),
        Marker::Square => {
            let h = 0.9 * r;
            (polygon(&[(-h, -h), (h, -h), (h, h), (-h, h)]), true)
        }
        Marker::TriangleUp => {
            let h = 1.15 * r;
            (polygon(&[(0.0, -h), (h, 0.75 * h), (-h, 0.75 * h)]), true)
        }
        Marker::TriangleDown => {
            let h = 1.15 * r;
            (polygon(&[(0.0, h), (h, -0.75 * h), (-h, -0.75 * h)]), true)
        }
        Marker::Diamond => {
            let h = 1.25 * r;
            (polygon(&[(0.0, -h), (h, 0.0), (0.0, h), (-h, 0.0)]), true)
        }
        Marker::Cross => {
            let h = r;
            (
                strokes([
                    [(x - h, y - h), (x + h, y + h)],
                    [(x - h, y + h), (x + h, y - h)],
                ]),
                false,
            )
        }
        Marker::Plus => {
            let h = 1.2 * r;
            (
                strokes([[(x - h, y), (x + h, y)], [(x, y - h), (x, y + h)]]),
                false,
            )
        }
    }
}

/// Adds `marker` at `at` to `fig`.
fn add_marker(fig: &mut Figure, marker: Marker, color: [u8; 3], at: (f32, f32)) {
    match marker_shape(marker, at) {
        (shape, true) => fig.fill(shape, color),
        (shape, false) => fig.stroke(shape, color, 2.0),
    }
}

/// A label candidate along an axis: its centre and half extent along the axis.
struct Placed {
    at: f32,
    half: f32,
    major: bool,
    text: String,
}

/// Keeps labels that do not overlap, major ticks first.
fn thin_labels(mut labels: Vec<Placed>, gap: f32) -> Vec<Placed> {
    labels.sort_by_key(|l| !l.major);
    let mut kept: Vec<Placed> = Vec::new();
    for l in labels {
        if kept
            .iter()
            .all(|k| (k.at - l.at).abs() >= k.half + l.half + gap)
        {
            kept.push(l);
        }
    }
    kept
}

/// `chart` as a figure of `width`×`height` pixels (each side clamped to 1..=`MAX_SIDE`): the
/// one description the PNG (`render_chart`) and the SVG (`chart_svg`) are drawn from.
pub fn chart_figure(chart: &Chart, width: u32, height: u32) -> Figure {
    let lay = ChartLayout::new(chart, width, height);
    let mut fig = Figure::new(lay.width, lay.height, [255; 3]);
    let p = lay.plot;
    let crisp = |v: f32| v.floor() + 0.5;

    // Grid, then ticks and their labels.
    let mut x_labels = Vec::new();
    for t in &lay.x.ticks {
        let Some((px, _)) = lay.to_pixel(t.value, lay.y.min) else {
            continue;
        };
        let px = crisp(px);
        let grid = if t.major { [200; 3] } else { [232; 3] };
        fig.stroke(Shape::segment((px, p.top), (px, p.bottom)), grid, 1.0);
        let len = if t.major { TICK } else { 0.6 * TICK };
        fig.stroke(
            Shape::segment((px, p.bottom), (px, p.bottom + len)),
            [60; 3],
            1.0,
        );
        if let Some(text) = &t.label {
            x_labels.push(Placed {
                at: px,
                half: 0.5 * font::text_width(text, LABEL),
                major: t.major,
                text: text.clone(),
            });
        }
    }
    let mut y_labels = Vec::new();
    for t in &lay.y.ticks {
        let Some((_, py)) = lay.to_pixel(lay.x.min, t.value) else {
            continue;
        };
        let py = crisp(py);
        let grid = if t.major { [200; 3] } else { [232; 3] };
        fig.stroke(Shape::segment((p.left, py), (p.right, py)), grid, 1.0);
        let len = if t.major { TICK } else { 0.6 * TICK };
        fig.stroke(
            Shape::segment((p.left - len, py), (p.left, py)),
            [60; 3],
            1.0,
        );
        if let Some(text) = &t.label {
            y_labels.push(Placed {
                at: py,
                half: 0.5 * font::cap_height(LABEL),
                major: t.major,
                text: text.clone(),
            });
        }
    }
    let style = TextStyle::new(LABEL, TEXT);
    let x_base = p.bottom + TICK + GAP + font::cap_height(LABEL);
    for l in thin_labels(x_labels, 6.0) {
        fig.text(&l.text, (l.at, x_base), style.align(Align::Center));
    }
    for l in thin_labels(y_labels, 4.0) {
        let y = l.at + 0.5 * font::cap_height(LABEL);
        fig.text(&l.text, (p.left - TICK - GAP, y), style.align(Align::Right));
    }

    // Frame.
    let plot_rect = [p.left, p.top, p.right, p.bottom];
    fig.stroke(Shape::rect(plot_rect), [60; 3], 1.0);

    // Axis labels and title.
    let descent = font::descent(LABEL);
    if !chart.x_label.is_empty() {
        let y = lay.height as f32 - PAD - descent;
        let st = style.align(Align::Center);
        fig.text(&chart.x_label, (0.5 * (p.left + p.right), y), st);
    }
    if !chart.y_label.is_empty() {
        let st = style.align(Align::Center).rotate(-90.0);
        let x = PAD + font::cap_height(LABEL);
        fig.text(&chart.y_label, (x, 0.5 * (p.top + p.bottom)), st);
    }
    if !chart.title.is_empty() {
        let st = TextStyle::new(TITLE, TEXT).align(Align::Center).weight(1.5);
        let y = PAD + font::cap_height(TITLE);
        fig.text(&chart.title, (0.5 * (p.left + p.right), y), st);
    }

    // Series: all lines (clipped to the plot area), then all markers on top.
    let pixels: Vec<Vec<Option<(f32, f32)>>> = chart
        .series
        .iter()
        .map(|s| s.points.iter().map(|&(x, y)| lay.to_pixel(x, y)).collect())
        .collect();
    for (i, (s, pts)) in chart.series.iter().zip(&pixels).enumerate() {
        if !s.connect {
            continue;
        }
        // A point that cannot be placed breaks the line.
        let mut subpaths: Vec<Subpath> = Vec::new();
        let mut pen_down = false;
        for q in pts {
            match (q, pen_down) {
                (Some(q), false) => subpaths.push(Subpath {
                    points: vec![*q],
                    closed: false,
                }),
                (Some(q), true) => {
                    if let Some(last) = subpaths.last_mut() {
                        last.points.push(*q);
                    }
                }
                (None, _) => {}
            }
            pen_down = q.is_some();
        }
        subpaths.retain(|s| s.points.len() > 1);
        if !subpaths.is_empty() {
            fig.items.push(Item::Stroke {
                shape: Shape::Path(subpaths),
                color: series_style(i).0,
                width: 1.6,
                opacity: 1.0,
                clip: Some(plot_rect),
            });
        }
    }
    for (i, pts) in pixels.iter().enumerate() {
        let (color, marker) = series_style(i);
        for q in pts.iter().flatten() {
            add_marker(&mut fig, marker, color, *q);
        }
    }

    // Legend.
    if let Some(box_) = lay.legend {
        let rect = [box_.left, box_.top, box_.right, box_.bottom];
        fig.fill(Shape::rect(rect), [255; 3]);
        fig.stroke(Shape::rect(rect), [160; 3], 1.0);
        let named = chart
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.name.is_empty());
        for (row, (i, s)) in named.enumerate() {
            let (color, marker) = series_style(i);
            let mid = box_.top + GAP + (row as f32 + 0.5) * LEGEND_ROW;
            let x0 = box_.left + GAP;
            if s.connect {
                fig.stroke(
                    Shape::segment((x0, mid), (x0 + LEGEND_SAMPLE, mid)),
                    color,
                    1.6,
                );
            }
            add_marker(&mut fig, marker, color, (x0 + 0.5 * LEGEND_SAMPLE, mid));
            let y = mid + 0.5 * font::cap_height(LABEL);
            fig.text(&s.name, (x0 + LEGEND_SAMPLE + GAP, y), style);
        }
    }
    fig
}

/// Draws `chart` on a `width`×`height` image (each side clamped to 1..=[`MAX_SIDE`]).
pub(crate) fn render_chart(chart: &Chart, width: u32, height: u32) -> Pixmap {
    raster::render(&chart_figure(chart, width, height))
}

/// `chart` as an SVG document of `width`×`height` pixels.
pub(crate) fn chart_svg(chart: &Chart, width: u32, height: u32) -> String {
    svg::to_svg(&chart_figure(chart, width, height))
}

/// Writes `chart` as SVG.
pub(crate) fn save_chart_svg(
    chart: &Chart,
    width: u32,
    height: u32,
    path: &Path,
) -> crate::Result<()> {
    std::fs::write(path, chart_svg(chart, width, height)).in_file(path.display(), "writing SVG")
}

/// Renders `chart` and writes it as an 8-bit RGBA PNG.
pub(crate) fn save_chart_png(
    chart: &Chart,
    width: u32,
    height: u32,
    path: &Path,
) -> crate::Result<()> {
    save_pixmap_png(&render_chart(chart, width, height), path)
        .in_file(path.display(), "writing PNG")
}

/// Writes a tiny-skia pixmap (premultiplied) as an 8-bit straight-alpha RGBA PNG.
/// The pixmap's RGBA with straight (not premultiplied) alpha, as PNG stores it.
fn straight_rgba(pm: &tiny_skia::Pixmap) -> Vec<u8> {
    pm.pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
        .collect()
}

/// [`save_pixmap_png`]'s file as bytes.
pub(crate) fn pixmap_png_bytes(pm: &tiny_skia::Pixmap) -> image::ImageResult<Vec<u8>> {
    use image::ImageEncoder;
    let rgba = straight_rgba(pm);
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out).write_image(
        &rgba,
        pm.width(),
        pm.height(),
        image::ExtendedColorType::Rgba8,
    )?;
    Ok(out)
}

pub(crate) fn save_pixmap_png(pm: &tiny_skia::Pixmap, path: &Path) -> image::ImageResult<()> {
    std::fs::write(path, pixmap_png_bytes(pm)?).map_err(image::ImageError::IoError)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(a: &Axis) -> Vec<f64> {
        a.ticks.iter().map(|t| t.value).collect()
    }

    fn labels(a: &Axis) -> Vec<&str> {
        a.ticks.iter().filter_map(|t| t.label.as_deref()).collect()
    }

    #[test]
    fn linear_ticks() {
        let a = Axis::linear(0.0, 1.0);
        assert_eq!(values(&a), [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(labels(&a), ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        assert_eq!((a.min, a.max), (0.0, 1.0));

        let a = Axis::linear(3.0, 97.0);
        assert_eq!(values(&a), [0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
        assert_eq!(labels(&a), ["0", "20", "40", "60", "80", "100"]);

        let a = Axis::linear(-1.3, 2.1);
        assert_eq!(values(&a), [-2.0, -1.0, 0.0, 1.0, 2.0, 3.0]);

        let a = Axis::linear(0.0012, 0.0031);
        assert_eq!(values(&a), [0.001, 0.0015, 0.002, 0.0025, 0.003, 0.0035]);
        assert_eq!(labels(&a)[2], "0.0020");

        let a = Axis::linear(5.0, 5.0);
        assert_eq!((a.min, a.max), (2.0, 8.0));
        assert_eq!(Axis::linear(f64::NAN, 1.0), Axis::linear(0.0, 1.0));
        assert_eq!(labels(&Axis::linear(0.0, 4e7))[1], "1e7");
    }

    #[test]
    fn log_ticks() {
        let a = Axis::log(0.013, 7.2);
        assert_eq!((a.min, a.max), (0.01, 10.0));
        let v = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0];
        assert_eq!(values(&a), v);
        assert_eq!(labels(&a), ["0.01", "0.1", "1", "10"]);
        let majors: Vec<f64> = a
            .ticks
            .iter()
            .filter(|t| t.major)
            .map(|t| t.value)
            .collect();
        assert_eq!(majors, [0.01, 0.1, 1.0, 10.0]);

        // Within two decades every tick is labelled.
        let a = Axis::log(3.0, 40.0);
        assert_eq!(values(&a), [2.0, 5.0, 10.0, 20.0, 50.0]);
        assert_eq!(labels(&a), ["2", "5", "10", "20", "50"]);

        // Exactly on nice values: kept, not widened.
        let a = Axis::log(1e-3, 1.0);
        assert_eq!((a.min, a.max), (1e-3, 1.0));
        assert_eq!(labels(&a), ["0.001", "0.01", "0.1", "1"]);

        // Twelve decades: every other decade labelled, in e-notation beyond 10^4.
        let a = Axis::log(1e-7, 1e5);
        assert_eq!(values(&a).len(), 12 * 3 + 1);
        assert_eq!(labels(&a), ["1e-6", "1e-4", "0.01", "1", "100", "10000"]);

        // One value: one nice step either way.
        let a = Axis::log(2.0, 2.0);
        assert_eq!((a.min, a.max), (1.0, 5.0));
        assert_eq!(Axis::log(-1.0, 10.0), Axis::log(1.0, 10.0));
    }

    #[test]
    fn mapping_round_trip() {
        for a in [Axis::linear(-3.0, 7.0), Axis::log(1e-4, 30.0)] {
            assert_eq!(a.map(a.min), 0.0);
            assert!((a.map(a.max) - 1.0).abs() < 1e-15);
            for v in [1e-4, 2e-3, 0.5, 1.0, 6.9, 29.0] {
                let back = a.unmap(a.map(v));
                assert!((back - v).abs() <= 1e-13 * v.abs().max(1.0), "{v} → {back}");
            }
        }
        let a = Axis::log(1.0, 100.0);
        assert!((a.map(10.0) - 0.5).abs() < 1e-15);
        assert!(!a.accepts(0.0) && !a.accepts(-1.0) && !a.accepts(f64::NAN));
        assert!(Axis::linear(0.0, 1.0).accepts(-1.0));
    }

    fn pixel(pm: &Pixmap, (x, y): (f32, f32)) -> [u8; 3] {
        let c = pm.pixel(x as u32, y as u32).unwrap().demultiply();
        [c.red(), c.green(), c.blue()]
    }

    /// Each data point's pixel, computed from the axis mapping, carries its series' colour;
    /// the plot background between grid lines is white.
    #[test]
    fn markers_land_where_the_axes_map_them() {
        let chart = Chart {
            title: "Test chart".into(),
            x_label: "time (s)".into(),
            y_label: "RMSE".into(),
            x_log: true,
            y_log: true,
            series: vec![
                Series {
                    name: "a".into(),
                    points: vec![(0.01, 0.5), (1.0, 0.05), (100.0, 0.005)],
                    connect: true,
                },
                Series {
                    name: "b".into(),
                    points: vec![(0.3, 0.2)],
                    connect: false,
                },
            ],
        };
        let (w, h) = (480, 320);
        let pm = render_chart(&chart, w, h);
        let lay = ChartLayout::new(&chart, w, h);
        assert_eq!(
            (lay.x.min, lay.x.max, lay.y.min, lay.y.max),
            (0.01, 100.0, 0.005, 0.5)
        );
        let p = lay.plot;
        for (i, s) in chart.series.iter().enumerate() {
            for &(x, y) in &s.points {
                // By hand from the axis mapping, not through to_pixel.
                let px = p.left + lay.x.map(x) as f32 * (p.right - p.left);
                let py = p.bottom - lay.y.map(y) as f32 * (p.bottom - p.top);
                let (qx, qy) = lay.to_pixel(x, y).unwrap();
                assert!((qx - px).abs() < 1e-3 && (qy - py).abs() < 1e-3);
                assert_eq!(pixel(&pm, (px, py)), PALETTE[i], "series {i} at ({x}, {y})");
            }
        }
        // The decade 1 s maps to the middle of the log axis (0.01 .. 100).
        let mid = lay.to_pixel(1.0, 0.05).unwrap().0;
        assert!((mid - 0.5 * (p.left + p.right)).abs() < 1e-3);
        // Empty plot area, far from points, lines and grid: white.
        let empty = lay.to_pixel(30.0, 0.35).unwrap();
        assert_eq!(pixel(&pm, empty), [255; 3]);
        // The frame is drawn.
        assert_eq!(pixel(&pm, (p.left, 0.5 * (p.top + p.bottom))), [60; 3]);
    }

    /// NaN, infinities, zeros on log axes, empty series and absurd sizes never panic.
    #[test]
    fn bad_data_never_panics() {
        let chart = Chart {
            title: "bad ☃".into(),
            x_log: true,
            y_log: false,
            series: vec![
                Series {
                    name: "nan".into(),
                    points: vec![(f64::NAN, 1.0), (1.0, f64::NAN), (0.0, 1.0), (-1.0, 2.0)],
                    connect: true,
                },
                Series {
                    name: "".into(),
                    points: vec![(f64::INFINITY, 1.0), (2.0, f64::NEG_INFINITY)],
                    connect: true,
                },
                Series {
                    name: "ok".into(),
                    points: vec![(1.0, 1.0), (f64::NAN, 2.0), (10.0, 3.0), (1e300, -1e300)],
                    connect: true,
                },
                Series {
                    name: "extremes".into(),
                    points: vec![(1e-320, 1e308), (f64::MAX, -f64::MAX), (1e300, 1.0)],
                    connect: false,
                },
                Series::default(),
            ],
            ..Chart::default()
        };
        for (w, h) in [(640, 400), (1, 1), (0, 0), (30, 20), (100_000, 3)] {
            let pm = render_chart(&chart, w, h);
            assert!(pm.width() >= 1 && pm.height() >= 1);
        }
        render_chart(&Chart::default(), 200, 100);
        let mut log_log = chart.clone();
        log_log.y_log = true;
        render_chart(&log_log, 300, 200);
        assert_eq!(Axis::log(1e-320, f64::MAX).min, 1e-300);
        let lay = ChartLayout::new(&chart, 640, 400);
        assert!(lay.to_pixel(0.0, 1.0).is_none() && lay.to_pixel(1.0, f64::NAN).is_none());
    }

    /// Writes example charts under `target/` to look at: an equal-time chart and a font sheet.
    #[test]
    fn example_chart_png() {
        use crate::bench::equal_time::{ErrorMetric, error_vs_time_chart};
        use crate::bench::table::BenchRow;
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-examples");
        std::fs::create_dir_all(&dir).unwrap();
        let row = |method: &str, spp: Option<u32>, seconds: f64, rmse: f64| BenchRow {
            scene: "fig4".into(),
            method: method.into(),
            spp,
            seconds,
            mae: rmse,
            rmse,
            relative_rmse: rmse,
            rmse_corrected: rmse,
            ..Default::default()
        };
        let mut rows = vec![
            row("analytic", None, 0.42, 2.1e-3),
            row("per-triangle", None, 3.1, 2.1e-3),
            row("unshadowed", None, 0.11, 4.8e-2),
        ];
        for spp in [1u32, 2, 4, 8, 16, 32, 64, 128, 256] {
            let s = spp as f64;
            rows.push(row("ray-traced", Some(spp), 0.05 * s, 0.09 / s.sqrt()));
            rows.push(row(
                "ltc + shadow rays",
                Some(spp),
                0.08 * s,
                0.03 / s.sqrt(),
            ));
        }
        let chart = error_vs_time_chart(&rows, ErrorMetric::Rmse, "fig4: RMSE vs time, equal-time");
        let path = dir.join("error_vs_time.png");
        save_chart_png(&chart, 720, 480, &path).unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() > 1000);

        let sheet = Chart {
            title: "ABCDEFGHIJKLM NOPQRSTUVWXYZ".into(),
            x_label: "abcdefghijklm nopqrstuvwxyz 0123456789".into(),
            y_label: ". - + / ( ) % × : _ , = [ ]".into(),
            x_log: false,
            y_log: false,
            series: vec![Series {
                name: "Speed-up (x) = 12.5% :_,".into(),
                points: vec![(0.0, 0.0), (0.5, 0.75), (1.0, 1.0)],
                connect: true,
            }],
        };
        save_chart_png(&sheet, 560, 300, &dir.join("font_sheet.png")).unwrap();

        // Every glyph at the label size, blown up 4× (nearest) to judge the strokes.
        let lines = [
            "ABCDEFGHIJKLMNOPQRSTUVWXYZ",
            "abcdefghijklmnopqrstuvwxyz",
            "0123456789 .-+/()%×:_,=[]",
            "RMSE vs time (s): 1e-4, 2.5%",
        ];
        let mut small = Pixmap::new(200, 16 * lines.len() as u32 + 4).unwrap();
        small.fill(tiny_skia::Color::WHITE);
        for (i, l) in lines.iter().enumerate() {
            let y = 14.0 + 16.0 * i as f32;
            font::draw_text(&mut small, l, 3.0, y, &TextStyle::new(LABEL, TEXT));
        }
        let z = 4;
        let (w, h) = (small.width() * z, small.height() * z);
        let mut big = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h {
            for x in 0..w {
                let c = small.pixel(x / z, y / z).unwrap().demultiply();
                big.extend([c.red(), c.green(), c.blue(), 255]);
            }
        }
        let path = dir.join("font_zoom.png");
        image::save_buffer(&path, &big, w, h, image::ExtendedColorType::Rgba8).unwrap();
    }
}
