//! The sphere and hemisphere views as figures: a [`Drawing`] (what the recording shows)
//! projected orthographically, seen from outside the sphere (the 3-D view, framed on the
//! lights by default) or from above the normal (the hemisphere, where the area a region covers
//! is its form factor: Nusselt's analogue). Regions are clipped exactly to the half of the
//! sphere facing the eye ([`clip_to_horizon`] in the eye's frame) before they are filled, so
//! that a region reaching behind the sphere does not fold over itself.

use super::{CurveKind, Drawing, arc_loop};
use crate::figure::font::TextStyle;
use crate::figure::{Figure, Rect, Rgb, Shape, Subpath};
use crate::geometry::{HorizonScratch, SphericalPolygon, clip_to_horizon};
use crate::views::Style;
use crate::views::labels::{LabelPlacer, Placement};
use glam::DVec3;

/// The legend's entry of the moving edges' velocity arrows.
pub const VELOCITY_LEGEND: &str = "edge velocity (v_n along the outward normal)";

/// An orthographic camera around the unit sphere.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SphereCamera {
    /// Azimuth and elevation of the eye (radians, shading frame).
    pub yaw: f32,
    pub pitch: f32,
    /// Magnification about the sphere's centre (1: the whole sphere fills 90 % of the side).
    pub zoom: f32,
}

impl Default for SphereCamera {
    /// The oblique view of the whole sphere.
    fn default() -> Self {
        SphereCamera {
            yaw: -1.2,
            pitch: 0.45,
            zoom: 1.0,
        }
    }
}

/// Largest magnification of the framed camera: a light a few degrees across still shows the
/// horizon's curve and the normal for context (the hemisphere view's "fit" shows detail).
pub(crate) const MAX_FRAMING_ZOOM: f32 = 8.0;

impl SphereCamera {
    /// (right, up, toward the eye).
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let (yaw, pitch) = (self.yaw as f64, self.pitch as f64);
        let e = DVec3::new(
            pitch.cos() * yaw.cos(),
            pitch.cos() * yaw.sin(),
            pitch.sin(),
        );
        let right = DVec3::Z.cross(e).try_normalize().unwrap_or(DVec3::X);
        (right, e.cross(right), e)
    }

    /// The camera framed on `directions` (the region of interest,
    /// [`super::region_of_interest`]): looking at their mean direction, magnified until they fill about
    /// two thirds of the side (at most `MAX_FRAMING_ZOOM`). The default camera without any.
    pub fn framed(directions: &[DVec3]) -> SphereCamera {
        let Some(mean) = directions.iter().copied().sum::<DVec3>().try_normalize() else {
            return SphereCamera::default();
        };
        let mut cam = SphereCamera {
            yaw: mean.y.atan2(mean.x) as f32,
            pitch: mean.z.clamp(-1.0, 1.0).asin() as f32,
            zoom: 1.0,
        };
        let (right, up, eye) = cam.basis();
        let extent = directions
            .iter()
            .map(|p| {
                if p.dot(eye) < 0.0 {
                    1.0
                } else {
                    p.dot(right).abs().max(p.dot(up).abs())
                }
            })
            .fold(0.0, f64::max) as f32;
        cam.zoom = (0.667 / extent.max(1e-6)).clamp(1.0, MAX_FRAMING_ZOOM);
        // Slightly above the mean, so that the horizon (a line through the picture when seen
        // edge on) reads as an ellipse and the normal as an arrow; by less when magnified,
        // where the same angle would push the light out of the middle.
        cam.pitch = (cam.pitch + 0.15 / cam.zoom).min(1.5);
        cam
    }
}

/// How directions land on the figure: orthographic along `eye`, `scale` pixels per unit,
/// `offset` (in units of the picture plane) at `centre`.
pub(crate) struct Projection {
    right: DVec3,
    up: DVec3,
    eye: DVec3,
    centre: (f32, f32),
    offset: (f64, f64),
    scale: f64,
}

impl Projection {
    fn px(&self, x: f64, y: f64) -> (f32, f32) {
        (
            self.centre.0 + ((x - self.offset.0) * self.scale) as f32,
            self.centre.1 - ((y - self.offset.1) * self.scale) as f32,
        )
    }

    /// Where the direction `p` is drawn (figure pixels).
    pub fn project(&self, p: DVec3) -> (f32, f32) {
        self.px(p.dot(self.right), p.dot(self.up))
    }

    /// Whether `p` faces the eye (is drawn solid).
    pub(crate) fn front(&self, p: DVec3) -> bool {
        p.dot(self.eye) >= 0.0
    }

    /// The region's loops clipped to the half of the sphere facing the eye, sampled along
    /// their arcs and projected.
    fn front_region(&self, loops: &[Vec<DVec3>], scratch: &mut HorizonScratch) -> Shape {
        let mut input = SphericalPolygon::new();
        for lp in loops.iter().filter(|l| l.len() >= 3) {
            input.push_loop(
                lp.iter()
                    .map(|p| DVec3::new(p.dot(self.right), p.dot(self.up), p.dot(self.eye))),
            );
        }
        let mut clipped = SphericalPolygon::new();
        clip_to_horizon(&input, &mut clipped, scratch);
        Shape::Path(
            clipped
                .loops()
                .map(|lp| Subpath {
                    points: arc_loop(lp).iter().map(|q| self.px(q.x, q.y)).collect(),
                    closed: true,
                })
                .collect(),
        )
    }
}

/// The projection of the 3-D sphere's figure, `size` pixels square.
pub(crate) fn sphere_projection(camera: &SphereCamera, size: u32) -> Projection {
    let s = size.clamp(64, 8192) as f32;
    let (right, up, eye) = camera.basis();
    Projection {
        right,
        up,
        eye,
        centre: (0.5 * s, 0.5 * s),
        offset: (0.0, 0.0),
        scale: 0.45 * s as f64 * camera.zoom as f64,
    }
}

/// The 3-D sphere, `size` pixels square, seen through `camera`.
pub fn sphere_figure(d: &Drawing, camera: &SphereCamera, size: u32, style: Style) -> Figure {
    let size = size.clamp(64, 8192);
    let proj = sphere_projection(camera, size);
    let scale = proj.scale;
    let mut fig = Figure::new(size, size, style.background());
    sky(&mut fig, d, &proj, false);
    fig.stroke(
        Shape::Circle {
            centre: proj.centre,
            radius: scale as f32,
        },
        style.faint(),
        1.0,
    );
    // The horizon: the great circle z = 0.
    let horizon: Vec<DVec3> = (0..256)
        .map(|k| {
            let a = k as f64 / 256.0 * std::f64::consts::TAU;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    polyline(
        &mut fig,
        &proj,
        &horizon,
        true,
        style.ink(),
        1.0,
        1.0,
        false,
    );
    draw(&mut fig, d, &proj, style, true, None);
    fig
}

/// The projection of the hemisphere's figure of `d`, `size` pixels square: the whole disk, or
/// with `fit` the box of what is drawn above the horizon.
pub(crate) fn hemisphere_projection(d: &Drawing, fit: bool, size: u32) -> Projection {
    let s = size.clamp(64, 8192) as f32;
    let (offset, half) = match fit.then(|| fit_box(d)).flatten() {
        Some((lo, hi)) => (
            (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1)),
            ((hi.0 - lo.0).max(hi.1 - lo.1) * 0.6).max(1e-4),
        ),
        None => ((0.0, 0.0), 1.0),
    };
    Projection {
        right: DVec3::X,
        up: DVec3::Y,
        eye: DVec3::Z,
        centre: (0.5 * s, 0.5 * s),
        offset,
        scale: 0.45 * s as f64 / half,
    }
}

/// The hemisphere seen from above the normal, `size` pixels square: the whole disk, or with
/// `fit` the box of what is drawn above the horizon (its magnification noted in the corner).
pub fn hemisphere_figure(d: &Drawing, fit: bool, size: u32, style: Style) -> Figure {
    let size = size.clamp(64, 8192);
    let proj = hemisphere_projection(d, fit, size);
    let (scale, half) = (proj.scale, 0.45 * size as f64 / proj.scale);
    let mut fig = Figure::new(size, size, style.background());
    sky(&mut fig, d, &proj, true);
    fig.stroke(
        Shape::Circle {
            centre: proj.px(0.0, 0.0),
            radius: scale as f32,
        },
        style.ink(),
        1.0,
    );
    let zoom_note = fit.then(|| format!("x{:.1}", 1.0 / half));
    draw(&mut fig, d, &proj, style, false, zoom_note);
    fig
}

/// The box (in the flat view's x, y) of every curve point and region corner above the horizon.
fn fit_box(d: &Drawing) -> Option<((f64, f64), (f64, f64))> {
    let curves = d.curves.iter().flat_map(|c| &c.points);
    let regions = d.regions.iter().flat_map(|r| r.loops.iter().flatten());
    let mut pts = curves.chain(regions).filter(|p| p.z >= 0.0);
    let first = pts.next()?;
    let init = ((first.x, first.y), (first.x, first.y));
    Some(pts.fold(init, |(lo, hi), p| {
        (
            (lo.0.min(p.x), lo.1.min(p.y)),
            (hi.0.max(p.x), hi.1.max(p.y)),
        )
    }))
}

/// The environment's radiance as filled cells under everything else: cells facing the eye
/// (above the horizon only on the hemisphere), dimmed so that the curves stay legible, and
/// dimmer below the horizon.
fn sky(fig: &mut Figure, d: &Drawing, proj: &Projection, hemisphere_only: bool) {
    let Some(sky) = &d.sky else {
        return;
    };
    for r in 0..sky.rows {
        for c in 0..sky.cols {
            let (corners, centre) = sky.cell(r, c);
            if !proj.front(centre) || (hemisphere_only && centre.z < 0.0) {
                continue;
            }
            let dim = if centre.z < 0.0 { 0.25 } else { 0.7 };
            let colour = sky.colours[(r * sky.cols + c) as usize].map(|v| (v as f32 * dim) as u8);
            // Each cell grown by half a pixel about its centre: anti-aliased neighbours would
            // otherwise leave the background showing along every seam.
            let pts: Vec<(f32, f32)> = corners.iter().map(|p| proj.project(*p)).collect();
            let c = pts
                .iter()
                .fold((0.0, 0.0), |a, p| (a.0 + 0.25 * p.0, a.1 + 0.25 * p.1));
            let grown = pts
                .iter()
                .map(|p| {
                    let (dx, dy) = (p.0 - c.0, p.1 - c.1);
                    let len = dx.hypot(dy).max(1e-6);
                    (p.0 + 0.5 * dx / len, p.1 + 0.5 * dy / len)
                })
                .collect();
            fig.fill(
                Shape::Path(vec![Subpath {
                    points: grown,
                    closed: true,
                }]),
                colour,
            );
        }
    }
}

/// Strokes a polyline on the sphere: solid where it faces the eye, thin and faint behind;
/// `arrows` puts an arrowhead about every third of a closed curve (its orientation).
#[allow(clippy::too_many_arguments)]
fn polyline(
    fig: &mut Figure,
    proj: &Projection,
    pts: &[DVec3],
    closed: bool,
    colour: Rgb,
    width: f32,
    opacity: f32,
    arrows: bool,
) {
    let n = pts.len();
    if n < 2 {
        return;
    }
    let segs = if closed { n } else { n - 1 };
    // Runs of segments on one side, each one subpath.
    let mut runs: Vec<(bool, Vec<(f32, f32)>)> = Vec::new();
    for k in 0..segs {
        let (a, b) = (pts[k], pts[(k + 1) % n]);
        let front = proj.front(a) && proj.front(b);
        let (pa, pb) = (proj.project(a), proj.project(b));
        match runs.last_mut() {
            Some((f, run)) if *f == front => run.push(pb),
            _ => runs.push((front, vec![pa, pb])),
        }
        if arrows && front && k % (n / 3).max(1) == n / 6 {
            let (dx, dy) = (pb.0 - pa.0, pb.1 - pa.1);
            let len = dx.hypot(dy);
            if len > 1e-6 {
                let (ux, uy) = (dx / len, dy / len);
                let tip = pb;
                let head = vec![
                    tip,
                    (tip.0 - 8.0 * ux - 4.0 * uy, tip.1 - 8.0 * uy + 4.0 * ux),
                    (tip.0 - 8.0 * ux + 4.0 * uy, tip.1 - 8.0 * uy - 4.0 * ux),
                ];
                fig.translucent(
                    Shape::Path(vec![Subpath {
                        points: head,
                        closed: true,
                    }]),
                    colour,
                    opacity,
                );
            }
        }
    }
    for front in [false, true] {
        let subpaths: Vec<Subpath> = runs
            .iter()
            .filter(|(f, _)| *f == front)
            .map(|(_, points)| Subpath {
                points: points.clone(),
                closed: false,
            })
            .collect();
        if subpaths.is_empty() {
            continue;
        }
        let (w, o) = if front {
            (width, opacity)
        } else {
            (0.6 * width, 0.25 * opacity)
        };
        fig.faded_stroke(Shape::Path(subpaths), colour, w, o);
    }
}

/// Pixel size of labels in a figure `side` pixels square.
fn label_size(side: f32) -> f32 {
    (side * 0.024).clamp(12.0, 24.0)
}

/// Draws the drawing's regions, curves, arrows, labels and legend through `proj`. `arrows_3d`
/// draws the frame's directions as arrows from the centre (else as dots where they pierce the
/// disk); `note` goes in the top right corner.
fn draw(
    fig: &mut Figure,
    d: &Drawing,
    proj: &Projection,
    style: Style,
    arrows_3d: bool,
    note: Option<String>,
) {
    let s = fig.width as f32;
    let ink = |c: Rgb| style.on_background(c);
    let mut scratch = HorizonScratch::default();
    for r in &d.regions {
        let shape = proj.front_region(&r.loops, &mut scratch);
        fig.translucent(shape, ink(r.colour), r.opacity);
    }
    for cv in &d.curves {
        let colour = ink(cv.colour);
        match cv.kind {
            CurveKind::Line => polyline(
                fig,
                proj,
                &cv.points,
                cv.closed,
                colour,
                cv.width,
                cv.opacity,
                // Orientation arrowheads on the current stage's polygons only: on a mesh
                // taken face by face (an open mesh from an exporter) every face's outline
                // would carry three, and hide the regions.
                cv.closed && !cv.tag.is_empty(),
            ),
            CurveKind::Marker | CurveKind::Dot => {
                for &p in &cv.points {
                    let o = if proj.front(p) { 1.0 } else { 0.25 } * cv.opacity;
                    let circle = |radius| Shape::Circle {
                        centre: proj.project(p),
                        radius,
                    };
                    if cv.kind == CurveKind::Dot {
                        fig.translucent(circle(1.0 + cv.width), colour, o);
                    } else {
                        fig.faded_stroke(circle(4.5), colour, cv.width, o);
                    }
                }
            }
        }
    }
    velocities(fig, d, proj, &ink);
    // The legend first, in the corner that hides least of the regions and labelled corners;
    // labels keep out of it.
    let size = label_size(s);
    let mut placer = LabelPlacer::new([0.0, 0.0, s, s]);
    let note_box = [s - 80.0, 0.0, s, 12.0 + size];
    let mut busy: Vec<Rect> = Vec::new();
    let mut bound = |pts: &mut dyn Iterator<Item = (f32, f32)>| {
        let init = [
            f32::INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NEG_INFINITY,
        ];
        let b = pts.fold(init, |b, q| {
            [b[0].min(q.0), b[1].min(q.1), b[2].max(q.0), b[3].max(q.1)]
        });
        if b[0] <= b[2] {
            busy.push(b);
        }
    };
    for r in &d.regions {
        bound(
            &mut r
                .loops
                .iter()
                .flatten()
                .filter(|p| proj.front(**p))
                .map(|p| proj.project(*p)),
        );
    }
    for c in d.curves.iter().filter(|c| !c.tag.is_empty()) {
        bound(
            &mut c
                .vertices
                .iter()
                .filter(|p| proj.front(**p))
                .map(|p| proj.project(*p)),
        );
    }
    if note.is_some() {
        busy.push(note_box);
    }
    if let Some(box_) = legend(fig, d, style, size, &busy) {
        placer.block(box_);
    }
    if let Some(note) = note {
        let st = TextStyle::new(size, style.ink()).align(crate::figure::font::Align::Right);
        fig.text(&note, (s - 6.0, 6.0 + size), st);
        placer.block(note_box);
    }
    let centre = proj.project(DVec3::ZERO);
    for a in &d.arrows {
        let tip = proj.project(a.dir);
        let front = proj.front(a.dir) || !arrows_3d;
        let o = if front { 1.0 } else { 0.3 };
        let colour = ink(a.colour);
        if arrows_3d {
            fig.faded_stroke(Shape::segment(centre, tip), colour, 2.0, o);
        } else if a.dir.z < 0.0 {
            continue;
        }
        fig.translucent(
            Shape::Circle {
                centre: tip,
                radius: 3.0,
            },
            colour,
            o,
        );
        if let Some(Placement { at, .. }) = placer.place(a.name, tip, size, 4.0) {
            fig.text(a.name, at, TextStyle::new(size, colour));
        }
    }
    // Vertex labels of the current stage's polygons, where the view is large enough to read
    // them: the tag and the corner's index in its loop (v0, v1, ... of the visible polygon).
    if s < 260.0 {
        return;
    }
    let small = 0.9 * size;
    for cv in d.curves.iter().filter(|c| !c.tag.is_empty()) {
        let colour = ink(cv.colour);
        // Corners closer than a label's height share one label ("v2,3"): separate labels
        // could not sit beside them without hiding each other.
        let mut groups: Vec<((f32, f32), Vec<usize>)> = Vec::new();
        for (i, &p) in cv.vertices.iter().enumerate() {
            let q = proj.project(p);
            if !proj.front(p) || q.0 < 0.0 || q.1 < 0.0 || q.0 > s || q.1 > s {
                continue;
            }
            fig.fill(
                Shape::Circle {
                    centre: q,
                    radius: 2.5,
                },
                colour,
            );
            let near = |a: (f32, f32)| (a.0 - q.0).hypot(a.1 - q.1) < small;
            match groups.iter_mut().find(|(a, _)| near(*a)) {
                Some((_, members)) => members.push(i),
                None => groups.push((q, vec![i])),
            }
        }
        for (q, members) in groups {
            let list: Vec<String> = members.iter().map(|i| i.to_string()).collect();
            let text = format!("{}{}", cv.tag, list.join(","));
            if let Some(pl) = placer.place(&text, q, small, 3.0) {
                if pl.far {
                    let end = (pl.at.0, pl.at.1 - 0.3 * small);
                    fig.faded_stroke(Shape::segment(q, end), colour, 0.8, 0.6);
                }
                fig.text(&text, pl.at, TextStyle::new(small, colour));
            }
        }
    }
}

/// The moving edges' velocities as arrows from their midpoints along the outward normal
/// speed times the outward normal, the fastest a fixed share of the figure long (the arrows
/// compare the edges' speeds at one point; their unit, per scene unit or per radian of θ, is
/// the motion's). On the 3-D sphere they are foreshortened as the sphere is; behind it faint.
fn velocities(fig: &mut Figure, d: &Drawing, proj: &Projection, ink: &dyn Fn(Rgb) -> Rgb) {
    let fastest = d
        .velocities
        .iter()
        .map(|v| v.speed.abs())
        .fold(0.0, f64::max);
    if fastest <= 0.0 {
        return;
    }
    let colour = ink(super::colours::VELOCITY);
    // The fastest arrow 0.14 of the figure's side (in sphere units at the figure's scale).
    let longest = 0.14 * fig.width as f64 / proj.scale;
    for v in &d.velocities {
        let from = proj.project(v.at);
        let tip = proj.project(v.at + v.outward * (longest * v.speed / fastest));
        let (dx, dy) = (tip.0 - from.0, tip.1 - from.1);
        let len = dx.hypot(dy);
        if len < 1e-3 {
            continue;
        }
        let o = if proj.front(v.at) { 1.0 } else { 0.3 };
        fig.faded_stroke(Shape::segment(from, tip), colour, 2.5, o);
        let (ux, uy) = (dx / len, dy / len);
        let head = 9.0f32.min(0.6 * len + 4.0);
        let wing = 0.5 * head;
        fig.translucent(
            Shape::Path(vec![Subpath {
                points: vec![
                    tip,
                    (tip.0 - head * ux - wing * uy, tip.1 - head * uy + wing * ux),
                    (tip.0 - head * ux + wing * uy, tip.1 - head * uy - wing * ux),
                ],
                closed: true,
            }]),
            colour,
            o,
        );
    }
}

/// The legend in the top left corner: one entry per kind drawn (regions by their fill, curves
/// by their stroke), over a veil so that curves behind do not garble it. Returns its box.
fn legend(fig: &mut Figure, d: &Drawing, style: Style, size: f32, busy: &[Rect]) -> Option<Rect> {
    enum Swatch {
        Fill(f32),
        Line(f32),
        Marker(f32),
        Dot,
    }
    let mut entries: Vec<(&str, Rgb, Swatch)> = Vec::new();
    for r in &d.regions {
        if !entries.iter().any(|e| e.0 == r.legend) {
            entries.push((r.legend, r.colour, Swatch::Fill(r.opacity.max(0.3))));
        }
    }
    for c in &d.curves {
        if c.legend.is_empty() || entries.iter().any(|e| e.0 == c.legend) {
            continue;
        }
        let sw = match c.kind {
            CurveKind::Line => Swatch::Line(c.width.max(2.0)),
            CurveKind::Marker => Swatch::Marker(c.width),
            CurveKind::Dot => Swatch::Dot,
        };
        entries.push((c.legend, c.colour, sw));
    }
    if !d.velocities.is_empty() {
        entries.push((VELOCITY_LEGEND, super::colours::VELOCITY, Swatch::Line(2.5)));
    }
    if entries.is_empty() {
        return None;
    }
    let line = 1.35 * size;
    let widest = entries
        .iter()
        .map(|e| crate::figure::font::text_width(e.0, size))
        .fold(0.0, f32::max);
    let (w, h) = (2.6 * size + widest + 6.0, entries.len() as f32 * line + 6.0);
    let (fw, fh) = (fig.width as f32, fig.height as f32);
    // The corner whose box covers least of the busy areas (top left on a tie).
    let covered = |b: &Rect| -> f32 {
        busy.iter()
            .map(|a| {
                let x = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
                let y = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
                x * y
            })
            .sum()
    };
    let corners = [
        (4.0, 4.0),
        (fw - 4.0 - w, 4.0),
        (4.0, fh - 4.0 - h),
        (fw - 4.0 - w, fh - 4.0 - h),
    ];
    let (x0, y0) = corners
        .into_iter()
        .map(|(x, y)| ((x, y), covered(&[x, y, x + w, y + h])))
        .fold(((4.0, 4.0), f32::INFINITY), |best, c| {
            if c.1 < best.1 { c } else { best }
        })
        .0;
    let box_ = [x0, y0, x0 + w, y0 + h];
    fig.translucent(Shape::rect(box_), style.background(), 0.8);
    for (k, (name, colour, sw)) in entries.into_iter().enumerate() {
        let colour = style.on_background(colour);
        let y = y0 + 3.0 + (k as f32 + 0.5) * line;
        let a = (x0 + 4.0, y);
        let b = (x0 + 4.0 + 1.6 * size, y);
        match sw {
            Swatch::Fill(o) => {
                let r = [a.0, y - 0.4 * size, b.0, y + 0.4 * size];
                fig.translucent(Shape::rect(r), colour, o);
            }
            Swatch::Line(w) => fig.stroke(Shape::segment(a, b), colour, w),
            Swatch::Marker(w) => fig.stroke(
                Shape::Circle {
                    centre: (0.5 * (a.0 + b.0), y),
                    radius: 4.0,
                },
                colour,
                w,
            ),
            Swatch::Dot => fig.fill(
                Shape::Circle {
                    centre: (0.5 * (a.0 + b.0), y),
                    radius: 3.0,
                },
                colour,
            ),
        }
        fig.text(
            name,
            (b.0 + 0.6 * size, y + 0.35 * size),
            TextStyle::new(size, style.ink()),
        );
    }
    Some(box_)
}
