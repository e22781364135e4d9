//! What the unit sphere at a picked point shows, as plain data read from the recording (the
//! data half of the sphere and hemisphere views; `figure` draws it): the regions (light,
//! occluders, visible polygon) as spherical polygons to fill, the curves on the sphere
//! (contour edges, polygon outlines, cones), point markers (apparent intersections, rays),
//! the shading frame's directions and the environment's radiance. Everything is in the
//! shading frame (z = n). Nothing here recomputes a stage.

pub(crate) mod figure;

pub use figure::VELOCITY_LEGEND;

use super::stages::{Step, StepKind};
use crate::figure::Rgb;
use crate::inspect::{Probe, sky_grid_direction};
use crate::shading::{EdgeSupport, EnvironmentSide, LightRecord, RayOutcome, Stage};
use glam::DVec3;

/// Which recorded polygons are drawn.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Layers {
    /// Contour edges (001 Eq. 4.2) of the light and the occluders, each drawn on its own.
    #[serde(default = "yes")]
    pub contours: bool,
    pub light_silhouette: bool,
    pub light_clipped: bool,
    pub occluders: bool,
    pub visible: bool,
    pub ltc: bool,
    pub directions: bool,
    /// Labels at the corners of the current stage's polygons.
    #[serde(default = "yes")]
    pub vertex_labels: bool,
    /// The environment map's radiance as the sphere's background.
    #[serde(default = "yes")]
    pub environment: bool,
    /// The exact method's union terms (static and dynamic).
    #[serde(default = "yes")]
    pub env_terms: bool,
    /// `rt`'s cones (Eq. 4 and merged) and rays.
    #[serde(default = "yes")]
    pub cones: bool,
    #[serde(default = "yes")]
    pub rays: bool,
    /// With a derivative: the visible polygon's moving edges and their velocities.
    #[serde(default = "yes")]
    pub velocities: bool,
}

fn yes() -> bool {
    true
}

impl Default for Layers {
    fn default() -> Self {
        Layers {
            contours: true,
            light_silhouette: true,
            light_clipped: true,
            occluders: true,
            visible: true,
            ltc: false,
            directions: true,
            vertex_labels: true,
            environment: true,
            env_terms: true,
            cones: true,
            rays: true,
            velocities: true,
        }
    }
}

impl Layers {
    /// Only the environment's layers (the environment view): the map, the union terms, the
    /// cones and the rays, with the shading frame's directions.
    pub(crate) fn environment_only() -> Layers {
        Layers {
            contours: false,
            light_silhouette: false,
            light_clipped: false,
            occluders: false,
            visible: false,
            ltc: false,
            vertex_labels: false,
            velocities: false,
            ..Layers::default()
        }
    }
}

/// Colours of the layers (also the legend's and the planar view's). The light, occluder and
/// visible colours are `super::LIGHT`, `super::OCCLUDER` and `super::VISIBLE`, the one
/// scheme of every view.
pub mod colours {
    use crate::figure::Rgb;
    pub(crate) const CONTOUR: Rgb = [235, 235, 245];
    pub(crate) const REJECTED: Rgb = [150, 70, 70];
    pub(crate) const CROSSING: Rgb = [255, 90, 220];
    pub(crate) const LIGHT: Rgb = super::super::LIGHT;
    pub(crate) const LIGHT_CLIPPED: Rgb = [250, 140, 30];
    pub(crate) const OCCLUDER: Rgb = super::super::OCCLUDER;
    pub(crate) const OCCLUDER_CLIPPED: Rgb = [160, 30, 90];
    pub(crate) const VISIBLE: Rgb = super::super::VISIBLE;
    pub(crate) const LTC: Rgb = [170, 90, 230];
    pub(crate) const NORMAL: Rgb = [80, 150, 255];
    pub(crate) const VIEW: Rgb = [200, 200, 200];
    pub(crate) const MIRROR: Rgb = [120, 220, 220];
    pub(crate) const STATIC_TERM: Rgb = [110, 150, 255];
    pub(crate) const DYNAMIC_TERM: Rgb = [255, 90, 40];
    pub(crate) const CONE: Rgb = [190, 190, 130];
    pub(crate) const MERGED_CONE: Rgb = [255, 225, 0];
    pub(crate) const RAY_CULLED: Rgb = [90, 90, 90];
    pub(crate) const RAY_ESCAPED: Rgb = [235, 235, 235];
    pub(crate) const RAY_STATIC: Rgb = [60, 110, 255];
    pub(crate) const RAY_DYNAMIC: Rgb = [255, 30, 30];
    /// A moving edge of the visible polygon (the derivative's).
    pub const MOVING_EDGE: Rgb = [255, 120, 200];
    /// The arrows of the edges' outward normal speed.
    pub const VELOCITY: Rgb = [255, 60, 160];
}

/// How a curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveKind {
    /// A polyline on the sphere (arcs sampled densely enough for print).
    Line,
    /// Each point a small circle of fixed size on screen (apparent intersections: they must
    /// stay visible on a small sphere, where a circle on the sphere would shrink to nothing).
    Marker,
    /// Each point a small filled dot (rays).
    Dot,
}

/// A polyline (or markers) on the sphere with how to draw it.
#[derive(Clone, Debug)]
pub struct Curve {
    pub points: Vec<DVec3>,
    pub colour: Rgb,
    /// 1, or less once a later stage is shown (earlier polygons fade).
    pub opacity: f32,
    pub width: f32,
    pub closed: bool,
    pub kind: CurveKind,
    /// What it is, in words (the hover text).
    pub label: String,
    /// Its entry in the legend.
    pub legend: &'static str,
    /// Corners of the polygon drawn (not the arc points between them), labelled with `tag`
    /// and their index; empty for curves whose corners are not labelled.
    pub vertices: Vec<DVec3>,
    pub tag: &'static str,
}

/// A region on the sphere to fill: the loops of one recorded polygon (holes negatively
/// oriented, as every stage keeps them), translucent so that overlaps show.
#[derive(Clone, Debug)]
pub struct Region {
    pub loops: Vec<Vec<DVec3>>,
    pub colour: Rgb,
    pub opacity: f32,
    pub legend: &'static str,
}

/// A shading-frame direction drawn as an arrow from the centre.
#[derive(Clone, Debug)]
pub struct Arrow {
    pub dir: DVec3,
    pub colour: Rgb,
    pub name: &'static str,
}

/// The environment's radiance on the probe's coarse grid, tone-mapped.
#[derive(Clone, Debug)]
pub struct Sky {
    pub rows: u32,
    pub cols: u32,
    /// Row-major display colours, tone-mapped (Reinhard) so that the grid's mean radiance is
    /// mid-grey.
    pub colours: Vec<Rgb>,
}

impl Sky {
    /// The cell's corners (direction, counter-clockwise in the grid) and its centre.
    pub(crate) fn cell(&self, r: u32, c: u32) -> ([DVec3; 4], DVec3) {
        let (rf, cf) = (r as f64, c as f64);
        let d = |a: f64, b: f64| sky_grid_direction(self.rows, self.cols, a, b);
        (
            [
                d(rf, cf),
                d(rf + 1.0, cf),
                d(rf + 1.0, cf + 1.0),
                d(rf, cf + 1.0),
            ],
            d(rf + 0.5, cf + 0.5),
        )
    }
}

/// How fast an edge of the visible polygon moves with the derivative's motion, drawn as an
/// arrow at its midpoint: the boundary there moves by `speed · outward` per unit of θ (the
/// Reynolds transport theorem's `v_n`, docs/derivatives.md), `outward` the unit tangent of
/// the sphere normal to the edge, away from the polygon's side of its circle (−ν).
#[derive(Clone, Debug)]
pub struct Velocity {
    /// The edge's midpoint (a unit vector).
    pub at: DVec3,
    pub outward: DVec3,
    /// `v_n = m · ν̇`: positive where the edge moves outward (the polygon grows there).
    pub speed: f64,
    pub label: String,
}

/// Everything the sphere shows at one step (or at every step, without one).
#[derive(Clone, Debug, Default)]
pub struct Drawing {
    pub regions: Vec<Region>,
    pub curves: Vec<Curve>,
    pub arrows: Vec<Arrow>,
    pub sky: Option<Sky>,
    /// With a derivative: the moving edges' velocities.
    pub velocities: Vec<Velocity>,
}

/// Points along the great-circle arc from `a` to `b` (unit vectors), `a` included, `b` not:
/// one every 0.04 rad (2.3°), dense enough that a polyline reads as the arc in print.
pub(crate) fn arc(a: DVec3, b: DVec3, out: &mut Vec<DVec3>) {
    let theta = a.cross(b).length().atan2(a.dot(b));
    let n = ((theta / 0.04).ceil() as usize).clamp(1, 200);
    let s = theta.sin();
    for i in 0..n {
        let t = i as f64 / n as f64;
        let p = if s.abs() < 1e-9 {
            a.lerp(b, t)
        } else {
            (a * ((1.0 - t) * theta).sin() + b * (t * theta).sin()) / s
        };
        out.push(p.normalize_or_zero());
    }
}

/// A closed loop of unit vectors sampled along its great-circle edges.
pub(crate) fn arc_loop(vertices: &[DVec3]) -> Vec<DVec3> {
    let mut points = Vec::new();
    for k in 0..vertices.len() {
        arc(vertices[k], vertices[(k + 1) % vertices.len()], &mut points);
    }
    points
}

/// Style of one polygon's outline: colour, opacity, width, hover label, legend entry and
/// corner tag.
struct Outline<'a> {
    colour: Rgb,
    opacity: f32,
    width: f32,
    label: &'a str,
    legend: &'static str,
    tag: &'static str,
}

fn push_outlines(loops: &[Vec<DVec3>], o: Outline, out: &mut Vec<Curve>) {
    for v in loops.iter().filter(|l| l.len() >= 2) {
        out.push(Curve {
            points: arc_loop(v),
            colour: o.colour,
            opacity: o.opacity,
            width: o.width,
            closed: true,
            kind: CurveKind::Line,
            label: o.label.into(),
            legend: o.legend,
            vertices: if o.tag.is_empty() {
                Vec::new()
            } else {
                v.clone()
            },
            tag: o.tag,
        });
    }
}

fn unit_loops(poly: &crate::geometry::PolygonLoops) -> Vec<Vec<DVec3>> {
    poly.loops()
        .map(|l| l.iter().map(|p| p.normalize_or_zero()).collect())
        .collect()
}

/// An open polyline (an edge or an arc piece), `a` to `b`.
fn edge_curve(a: DVec3, b: DVec3, colour: Rgb, opacity: f32, width: f32) -> Curve {
    let mut points = Vec::new();
    arc(a, b, &mut points);
    points.push(b);
    open_curve(points, colour, opacity, width)
}

/// An open polyline through `points`, unlabelled.
fn open_curve(points: Vec<DVec3>, colour: Rgb, opacity: f32, width: f32) -> Curve {
    Curve {
        points,
        colour,
        opacity,
        width,
        closed: false,
        kind: CurveKind::Line,
        label: String::new(),
        legend: "",
        vertices: Vec::new(),
        tag: "",
    }
}

/// The outline of the union of `loops` (polygons of a mesh's faces on the sphere), as open
/// polylines: the edges that no other loop runs along the other way (so not the edges two
/// neighbouring faces share), sampled, without the stretches that lie inside another face.
/// Ends are matched to 1e-9 rad: the faces' shared corners are computed from the same mesh
/// vertices, or cut from the same edge by the horizon.
fn union_outline(loops: &[Vec<DVec3>]) -> Vec<Vec<DVec3>> {
    use crate::geometry::SphericalPolygon;
    use std::collections::HashSet;
    let loops: Vec<&Vec<DVec3>> = loops.iter().filter(|l| l.len() >= 3).collect();
    let key = |p: DVec3| (p * 1e9).round().as_i64vec3().to_array();
    let edges = || {
        loops
            .iter()
            .enumerate()
            .flat_map(|(f, l)| (0..l.len()).map(move |i| (f, [l[i], l[(i + 1) % l.len()]])))
    };
    let directed: HashSet<([i64; 3], [i64; 3])> =
        edges().map(|(_, [a, b])| (key(a), key(b))).collect();
    // Each face as a polygon with a bounding cap (centre, cosine of its radius), to skip the
    // faces far from a sample quickly.
    let faces: Vec<(SphericalPolygon, DVec3, f64)> = loops
        .iter()
        .map(|l| {
            let mut p = SphericalPolygon::new();
            p.push_loop(l.iter().copied());
            let c = l.iter().sum::<DVec3>().normalize_or_zero();
            let cos = l.iter().map(|v| v.dot(c)).fold(1.0f64, f64::min);
            (p, c, cos)
        })
        .collect();
    let hidden = |p: DVec3, own: usize| {
        faces.iter().enumerate().any(|(f, (poly, c, cos))| {
            f != own && p.dot(*c) >= *cos - 1e-12 && poly.contains_within(p, 0.0)
        })
    };
    let mut out = Vec::new();
    for (f, [a, b]) in edges() {
        if directed.contains(&(key(b), key(a))) {
            continue;
        }
        let mut points = Vec::new();
        arc(a, b, &mut points);
        points.push(b);
        // At least 8 stretches per edge, each kept when its middle is in no other face.
        let mut dense = Vec::with_capacity(points.len() * 8);
        for w in points.windows(2) {
            for i in 0..8 {
                dense.push(w[0].lerp(w[1], i as f64 / 8.0).normalize_or_zero());
            }
        }
        dense.push(b);
        let mut run: Vec<DVec3> = Vec::new();
        for w in dense.windows(2) {
            if hidden(w[0].lerp(w[1], 0.5).normalize_or_zero(), f) {
                if run.len() >= 2 {
                    out.push(std::mem::take(&mut run));
                }
                run.clear();
            } else {
                if run.is_empty() {
                    run.push(w[0]);
                }
                run.push(w[1]);
            }
        }
        if run.len() >= 2 {
            out.push(run);
        }
    }
    out
}

/// How far through a light record's stages a step is, to draw everything up to it.
fn rank(k: &StepKind) -> u8 {
    match k {
        StepKind::LightSilhouette => 0,
        StepKind::LightClipped => 1,
        StepKind::Culling => 2,
        StepKind::OccluderSilhouette { .. } | StepKind::OccluderClipped { .. } => 3,
        StepKind::SetDifference { .. } => 4,
        StepKind::Visible => 5,
        StepKind::LtcTransformed { .. } | StepKind::LtcClipped { .. } => 6,
        StepKind::Integral => 7,
        StepKind::Derivative => 8,
    }
}

/// Opacity of what an earlier stage drew once the visible polygon is shown.
const FADED: f32 = 0.35;

/// What the step (or everything, without a step) shows of one light record.
fn light_record(
    rec: &LightRecord,
    step: Option<&Step>,
    layers: &Layers,
    occluder_name: &dyn Fn(usize) -> String,
    out: &mut Drawing,
) {
    let upto = step.map_or(8, |s| rank(&s.kind));
    if layers.contours {
        // The light's contour with its silhouette; an occluder's from its first step on. They
        // are drawn edge by edge, as the stage sees them, before they are chained into loops.
        for (who, edges) in &rec.contours {
            let (from, label) = match who {
                None => (0, "light contour edge".to_string()),
                Some(oi) => (3, format!("occluder {} contour edge", occluder_name(*oi))),
            };
            if upto < from {
                continue;
            }
            let opacity = if upto >= 5 || (who.is_none() && upto >= 3) {
                0.3
            } else {
                1.0
            };
            for [a, b] in edges {
                let mut c = edge_curve(*a, *b, colours::CONTOUR, opacity, 1.0);
                c.label = label.clone();
                c.legend = "contour edge";
                out.curves.push(c);
            }
        }
        // Exact silhouettes of non-convex meshes: the contour pieces the ray test rejected
        // (dim red) and the apparent intersections where pieces were cut.
        for ex in &rec.exact {
            let from = if ex.occluder.is_some() { 3 } else { 0 };
            if upto < from {
                continue;
            }
            let who = match ex.occluder {
                None => "light".to_string(),
                Some(oi) => format!("occluder {}", occluder_name(oi)),
            };
            for [a, b] in &ex.rejected {
                let mut c = edge_curve(*a, *b, colours::REJECTED, 1.0, 1.5);
                c.label = format!("{who}: contour piece rejected by the ray test");
                c.legend = "rejected contour piece";
                out.curves.push(c);
            }
            let source = if ex.from_tree {
                "from the BSP tree"
            } else {
                "on the fly"
            };
            if !ex.crossings.is_empty() {
                out.curves.push(Curve {
                    points: ex.crossings.clone(),
                    colour: colours::CROSSING,
                    opacity: 1.0,
                    width: 1.5,
                    closed: false,
                    kind: CurveKind::Marker,
                    label: format!("{who}: apparent intersection (Eq. 4.4), silhouette {source}"),
                    legend: "apparent intersection",
                    vertices: Vec::new(),
                    tag: "",
                });
            }
        }
    }
    for (stage, poly) in &rec.polygons {
        let (show, colour, width, name, r, fill) = match stage {
            Stage::Silhouette => (
                layers.light_silhouette,
                colours::LIGHT,
                1.5,
                "light silhouette",
                0,
                0.4,
            ),
            Stage::HorizonClipped => (
                layers.light_clipped,
                colours::LIGHT_CLIPPED,
                2.0,
                "light, clipped",
                1,
                0.0,
            ),
            Stage::Visible => (
                layers.visible,
                colours::VISIBLE,
                3.0,
                "visible polygon",
                5,
                0.6,
            ),
            _ => continue,
        };
        if !show || r > upto {
            continue;
        }
        // Once the visible polygon is shown, the earlier light polygons fade.
        let opacity = if upto >= 5 && r < 5 { FADED } else { 1.0 };
        // The corners of the current stage's polygon are labelled (l: light, v: visible).
        let tag = match (r == upto || (step.is_none() && r == 5), r) {
            (false, _) => "",
            (true, 5) => "v",
            (true, _) => "l",
        };
        let loops = unit_loops(poly);
        if fill > 0.0 {
            out.regions.push(Region {
                loops: loops.clone(),
                colour,
                // Regions fade less than outlines: the light's region stays the ground the
                // visible polygon is read against.
                opacity: fill * opacity.max(0.7),
                legend: name,
            });
        }
        let o = Outline {
            colour,
            opacity,
            width,
            label: name,
            legend: name,
            tag,
        };
        push_outlines(&loops, o, &mut out.curves);
    }
    if layers.occluders && upto >= 3 {
        // At an occluder step, only that occluder's polygons so far.
        let last = match step.map(|s| s.kind) {
            Some(StepKind::OccluderSilhouette { k } | StepKind::OccluderClipped { k }) => k,
            _ => usize::MAX,
        };
        let opacity = if upto >= 5 { FADED } else { 1.0 };
        let tag = if (3..=4).contains(&upto) { "o" } else { "" };
        let style = |stage: &Stage| match stage {
            Stage::Silhouette => (colours::OCCLUDER, 1.5, "occluder silhouette", 0.0),
            _ => (colours::OCCLUDER_CLIPPED, 2.0, "occluder, clipped", 0.3),
        };
        let shown = rec
            .occluder_polygons
            .iter()
            .enumerate()
            .take_while(|&(k, _)| k <= last);
        // An occluder's region, filled at the stages that fill it.
        let region = |loops: &[Vec<DVec3>], fill: f32| Region {
            loops: loops.to_vec(),
            colour: colours::OCCLUDER,
            opacity: fill * opacity.max(0.7),
            legend: "occluder",
        };
        for (_, (oi, _, stage, poly)) in shown.clone().filter(|(_, p)| p.1.is_none()) {
            let (colour, width, legend, fill) = style(stage);
            let loops = unit_loops(poly);
            if fill > 0.0 {
                out.regions.push(region(&loops, fill));
            }
            let label = format!("occluder {}", occluder_name(*oi));
            let o = Outline {
                colour,
                opacity,
                width,
                label: &label,
                legend,
                tag,
            };
            push_outlines(&loops, o, &mut out.curves);
        }
        // A mesh the renderer took face by face: per occluder and stage, its faces as one
        // region (filled by the nonzero rule, so overlapping faces do not darken it) outlined
        // where no other face of it continues, as a student reads the mesh's outline.
        let mut faced: Vec<(usize, bool)> = shown
            .clone()
            .filter(|(_, p)| p.1.is_some())
            .map(|(_, p)| (p.0, p.2 == Stage::Silhouette))
            .collect();
        faced.sort_unstable();
        faced.dedup();
        for (oi, silhouette) in faced {
            let polys = shown
                .clone()
                .map(|(_, p)| p)
                .filter(|p| p.0 == oi && p.1.is_some() && (p.2 == Stage::Silhouette) == silhouette);
            let loops: Vec<Vec<DVec3>> = polys.flat_map(|p| unit_loops(&p.3)).collect();
            let stage = if silhouette {
                Stage::Silhouette
            } else {
                Stage::HorizonClipped
            };
            let (colour, width, legend, fill) = style(&stage);
            if fill > 0.0 {
                out.regions.push(region(&loops, fill));
            }
            let faces = loops.len();
            for points in union_outline(&loops) {
                let mut c = open_curve(points, colour, opacity, width);
                c.label = format!(
                    "occluder {}, face by face ({faces} faces)",
                    occluder_name(oi)
                );
                c.legend = legend;
                out.curves.push(c);
            }
        }
    }
    if layers.velocities && upto >= 8 {
        moving_edges(rec, out);
    }
    if layers.ltc && upto >= 6 {
        for (lobe, transformed, clipped, integral) in &rec.lobes {
            let name = format!("{lobe:?} lobe, LTC space (integral {integral:.5})");
            let faint = Outline {
                colour: colours::LTC,
                opacity: 0.5,
                width: 1.5,
                label: &name,
                legend: "LTC space",
                tag: "",
            };
            push_outlines(&unit_loops(transformed), faint, &mut out.curves);
            let o = Outline {
                colour: colours::LTC,
                opacity: 1.0,
                width: 2.5,
                label: &name,
                legend: "LTC space",
                tag: "t",
            };
            push_outlines(&unit_loops(clipped), o, &mut out.curves);
        }
    }
}

/// The visible polygon's edges that move with the derivative's motion
/// ([`super::stages::moves`]), each drawn over the polygon with its velocity at the midpoint:
/// `v_n = m · ν̇` along the outward normal −ν, ν = a × b / |a × b| (the normal on the polygon's
/// side of an edge a → b of a positively oriented loop; a hole's edges move the same way, the
/// region's outside being the hole).
fn moving_edges(rec: &LightRecord, out: &mut Drawing) {
    for e in rec.moving_edges.iter().filter(|e| super::stages::moves(e)) {
        let (a, b) = (e.a.normalize_or_zero(), e.b.normalize_or_zero());
        let support = match e.support {
            EdgeSupport::Horizon => "on the horizon".to_string(),
            EdgeSupport::MeshEdge { moving: true, .. } => "on an edge of the moving object".into(),
            EdgeSupport::MeshEdge { object, .. } => {
                format!("on an edge of prepared object {object}, which stays")
            }
            EdgeSupport::Still => "still".to_string(),
            EdgeSupport::NotFound => "support not found".to_string(),
        };
        let nu = a.cross(b);
        let m = (a + b).normalize_or_zero();
        let speed = m.dot(e.normal_rate);
        let label = format!(
            "moving edge{} ({support}): v_n = {speed:+.4e} at its midpoint; share of dE/dθ \
             {:+.4e} (diffuse), {:+.4e} (lobe)",
            if e.in_hole { " of the hole" } else { "" },
            e.diffuse,
            e.lobe
        );
        let mut c = edge_curve(a, b, colours::MOVING_EDGE, 1.0, 3.5);
        c.label = label.clone();
        c.legend = "moving edge";
        out.curves.push(c);
        if nu.length() > 1e-12 && m != DVec3::ZERO && speed != 0.0 && speed.is_finite() {
            out.velocities.push(Velocity {
                at: m,
                outward: -nu.normalize(),
                speed,
                label,
            });
        }
    }
}

/// The environment's layers at the picked point: the exact method's union terms, `rt`'s cones
/// and rays, as curves on the sphere (shading frame).
fn environment(
    probe: &Probe,
    layers: &Layers,
    occluder_name: &dyn Fn(usize) -> String,
    out: &mut Drawing,
) {
    let rec = &probe.recording.environment;
    let terms = match &probe.environment {
        Some(e) if rec.terms.is_empty() => &e.exact_terms,
        _ => &rec.terms,
    };
    if layers.env_terms {
        for t in terms {
            let (colour, legend, side) = match t.side {
                EnvironmentSide::Static => (
                    colours::STATIC_TERM,
                    "static term (S_k minus the earlier S)",
                    "static",
                ),
                EnvironmentSide::Dynamic => (
                    colours::DYNAMIC_TERM,
                    "dynamic term (D_i minus S and the earlier D)",
                    "dynamic",
                ),
            };
            let v = t.integral;
            let name = format!(
                "{side} term of {}: integral of L cos = ({:.5}, {:.5}, {:.5})",
                occluder_name(t.occluder),
                v.x,
                v.y,
                v.z
            );
            let loops = unit_loops(&t.polygon);
            out.regions.push(Region {
                loops: loops.clone(),
                colour,
                opacity: 0.3,
                legend,
            });
            let o = Outline {
                colour,
                opacity: 1.0,
                width: 2.0,
                label: &name,
                legend,
                tag: "",
            };
            push_outlines(&loops, o, &mut out.curves);
        }
    }
    if layers.cones {
        let circle = |c: &crate::environment::Cone| -> Vec<DVec3> {
            let a = c.axis.normalize_or_zero();
            let u = a.any_orthonormal_vector();
            let v = a.cross(u);
            let (s, co) = c.half_angle.min(std::f64::consts::PI).sin_cos();
            (0..96)
                .map(|k| {
                    let t = k as f64 / 96.0 * std::f64::consts::TAU;
                    (a * co + (u * t.cos() + v * t.sin()) * s).normalize_or_zero()
                })
                .collect()
        };
        let cones = rec.cones.iter().map(|c| (c, false));
        let merged = rec.merged_cones.iter().map(|c| (c, true));
        for (i, (c, is_merged)) in cones.chain(merged).enumerate() {
            let (colour, width, legend, what) = if is_merged {
                (
                    colours::MERGED_CONE,
                    2.0,
                    "merged cone (Alg. 1)",
                    "merged cone (Alg. 1)",
                )
            } else {
                (colours::CONE, 1.0, "cone (Eq. 4)", "cone (002 Eq. 4)")
            };
            out.curves.push(Curve {
                points: circle(c),
                colour,
                opacity: 1.0,
                width,
                closed: true,
                kind: CurveKind::Line,
                label: format!(
                    "{what} {i}: half-angle {:.2} deg, h = {:.3}",
                    c.half_angle.to_degrees(),
                    c.height
                ),
                legend,
                vertices: Vec::new(),
                tag: "",
            });
        }
    }
    if layers.rays {
        for outcome in [
            RayOutcome::Culled,
            RayOutcome::Escaped,
            RayOutcome::Static,
            RayOutcome::Dynamic,
        ] {
            let points: Vec<DVec3> = rec
                .rays
                .iter()
                .filter(|r| r.outcome == outcome)
                .map(|r| r.dir)
                .collect();
            if points.is_empty() {
                continue;
            }
            // Culled rays smaller: the traced ones are what the eye should find.
            let (colour, legend, width) = match outcome {
                RayOutcome::Culled => (colours::RAY_CULLED, "ray culled", 0.6),
                RayOutcome::Escaped => (colours::RAY_ESCAPED, "ray traced, escaped", 1.4),
                RayOutcome::Static => (colours::RAY_STATIC, "ray traced, hit static", 1.4),
                RayOutcome::Dynamic => (colours::RAY_DYNAMIC, "ray traced, hit dynamic", 1.4),
            };
            out.curves.push(Curve {
                points,
                colour,
                opacity: 1.0,
                width,
                closed: false,
                kind: CurveKind::Dot,
                label: legend.to_string(),
                legend,
                vertices: Vec::new(),
                tag: "",
            });
        }
    }
    if layers.environment
        && let Some(env) = &probe.environment
    {
        out.sky = sky(env);
    }
}

/// The map's radiance on the probe's grid, Reinhard tone-mapped at an exposure that puts the
/// mean luminance at mid-grey; `None` when the probe has no grid.
fn sky(env: &crate::inspect::EnvironmentProbe) -> Option<Sky> {
    let (rows, cols) = (env.sky_rows, env.sky_cols);
    if rows == 0 || env.sky.len() != (rows * cols) as usize {
        return None;
    }
    let mean = env
        .sky
        .iter()
        .map(|c| crate::environment::luminance(*c))
        .sum::<f64>()
        / env.sky.len() as f64;
    let scale = if mean > 0.0 { 1.0 / mean } else { 1.0 };
    let encode = |v: f64| {
        let x = if v.is_finite() {
            (v * scale).max(0.0)
        } else {
            0.0
        };
        (crate::raster::io::srgb_oetf(x / (1.0 + x)) * 255.0)
            .round()
            .clamp(0.0, 255.0) as u8
    };
    Some(Sky {
        rows,
        cols,
        colours: env
            .sky
            .iter()
            .map(|c| [encode(c.x), encode(c.y), encode(c.z)])
            .collect(),
    })
}

/// Everything the sphere shows of `probe` at `step` (every stage without one), with `layers`.
pub fn drawing(probe: &Probe, step: Option<&Step>, layers: &Layers) -> Drawing {
    let names = |i: usize| {
        probe
            .occluder_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("#{i}"))
    };
    let mut out = Drawing::default();
    for (r, rec) in probe.recording.lights.iter().enumerate() {
        match step {
            Some(s) if s.record != r => continue,
            _ => light_record(rec, step, layers, &names, &mut out),
        }
    }
    // The environment's layers do not belong to a light's stages: shown at every step.
    if probe.environment.is_some() {
        environment(probe, layers, &names, &mut out);
    }
    if !layers.vertex_labels {
        for c in &mut out.curves {
            c.tag = "";
            c.vertices.clear();
        }
    }
    if layers.directions {
        out.arrows.push(Arrow {
            dir: DVec3::Z,
            colour: colours::NORMAL,
            name: "normal n",
        });
        if let Some(sp) = probe.point {
            let to_local = |w: DVec3| {
                DVec3::new(
                    w.dot(probe.frame_x),
                    w.dot(probe.frame_y),
                    w.dot(probe.frame_z),
                )
            };
            let v = to_local(sp.view);
            out.arrows.push(Arrow {
                dir: v,
                colour: colours::VIEW,
                name: "view v",
            });
            out.arrows.push(Arrow {
                dir: DVec3::new(-v.x, -v.y, v.z),
                colour: colours::MIRROR,
                name: "mirror r",
            });
        }
    }
    out
}

/// The directions the default sphere camera frames: the corners of the silhouette of the
/// step's light (every light's without a step), so that the camera holds still while stepping
/// through one light's stages; at a point lit by the environment alone, the corners of its
/// union terms (the occluders' shapes).
pub fn region_of_interest(probe: &Probe, step: Option<&Step>) -> Vec<DVec3> {
    let unit = |p: &DVec3| p.normalize_or_zero();
    let mut out: Vec<DVec3> = probe
        .recording
        .lights
        .iter()
        .enumerate()
        .filter(|(r, _)| step.is_none_or(|s| s.record == *r))
        .flat_map(|(_, rec)| &rec.polygons)
        .filter(|(stage, _)| *stage == Stage::Silhouette)
        .flat_map(|(_, poly)| poly.vertices().iter().map(unit))
        .collect();
    if out.is_empty() {
        let rec = &probe.recording.environment;
        let terms = match &probe.environment {
            Some(e) if rec.terms.is_empty() => &e.exact_terms,
            _ => &rec.terms,
        };
        out = terms
            .iter()
            .flat_map(|t| t.polygon.vertices().iter().map(unit))
            .collect();
    }
    out.retain(|p| *p != DVec3::ZERO);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn length(polylines: &[Vec<DVec3>]) -> f64 {
        polylines
            .iter()
            .flat_map(|l| l.windows(2))
            .map(|w| w[0].cross(w[1]).length().atan2(w[0].dot(w[1])))
            .sum()
    }

    fn dir(x: f64, y: f64) -> DVec3 {
        DVec3::new(x, y, 1.0).normalize()
    }

    /// Two triangles sharing a diagonal outline their quad: the diagonal is not drawn, and
    /// the outline is as long as the quad's four arcs. A face inside another is not outlined.
    #[test]
    fn the_union_of_faces_is_outlined_without_their_shared_and_covered_edges() {
        let (a, b, c, d) = (
            dir(-0.3, -0.2),
            dir(0.3, -0.2),
            dir(0.3, 0.2),
            dir(-0.3, 0.2),
        );
        let arc_len = |p: DVec3, q: DVec3| p.cross(q).length().atan2(p.dot(q));
        let perimeter = arc_len(a, b) + arc_len(b, c) + arc_len(c, d) + arc_len(d, a);
        let quad = vec![vec![a, b, c], vec![a, c, d]];
        let outline = union_outline(&quad);
        assert!((length(&outline) - perimeter).abs() < 1e-9 * perimeter);
        // A small triangle inside the first adds nothing.
        let mut with_inner = quad.clone();
        with_inner.push(vec![dir(0.05, -0.15), dir(0.2, -0.15), dir(0.2, -0.05)]);
        let outline = union_outline(&with_inner);
        assert!((length(&outline) - perimeter).abs() < 1e-9 * perimeter);
        // A triangle sticking out over edge b–c (x = 0.3 in the gnomonic plane, where arcs
        // are lines): b–c is outlined outside it (|y| > 1/15), the triangle outside the quad.
        // The stretches are decided at the samples, 1/8 of the arcs' sampling step apart.
        let tip = dir(0.5, 0.0);
        let (p1, p2) = (dir(0.3, -1.0 / 15.0), dir(0.3, 1.0 / 15.0));
        let mut over = quad.clone();
        over.push(vec![dir(0.2, -0.1), tip, dir(0.2, 0.1)]);
        let outline = union_outline(&over);
        let expected = perimeter - arc_len(p1, p2) + arc_len(p1, tip) + arc_len(tip, p2);
        assert!(
            (length(&outline) - expected).abs() < 4.0 * 0.04 / 8.0,
            "{} {expected}",
            length(&outline)
        );
        let inside_both = |p: &DVec3| {
            let (x, y) = (p.x / p.z, p.y / p.z);
            x > 0.2 + 1e-3 && x < 0.3 - 1e-3 && y.abs() < 0.1 * (0.5 - x) / 0.3 - 1e-3
        };
        assert!(!outline.iter().flatten().any(inside_both));
    }
}
