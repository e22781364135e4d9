//! The unit sphere at the picked shading point, drawing what the renderer recorded: a
//! rotatable 3D sphere (back hemisphere dimmed, horizon, normal, view and mirror directions)
//! and the flat hemisphere seen from above (orthographic: the area a polygon covers there is
//! its diffuse form factor, Nusselt's analogue). Everything is in the shading frame (z = n).

use super::tonemap::{ToneMap, tonemap};
use crate::inspect::{Probe, sky_grid_direction};
use crate::shading::{EnvironmentSide, LightRecord, RayOutcome, Stage};
use crate::views::stages::{Step, StepKind};
use egui::{Color32, Pos2, Rect, Sense, Shape, Stroke, Ui, Vec2};
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
        }
    }
}

/// Colours of the layers (also used by the legend and the planar view).
pub mod colours {
    use egui::Color32;
    pub const CONTOUR: Color32 = Color32::from_rgb(235, 235, 245);
    pub const REJECTED: Color32 = Color32::from_rgb(150, 70, 70);
    pub const CROSSING: Color32 = Color32::from_rgb(255, 90, 220);
    pub const LIGHT: Color32 = Color32::from_rgb(240, 200, 40);
    pub const LIGHT_CLIPPED: Color32 = Color32::from_rgb(250, 140, 30);
    pub const OCCLUDER: Color32 = Color32::from_rgb(220, 60, 60);
    pub const OCCLUDER_CLIPPED: Color32 = Color32::from_rgb(160, 30, 90);
    pub const VISIBLE: Color32 = Color32::from_rgb(60, 200, 90);
    pub const LTC: Color32 = Color32::from_rgb(170, 90, 230);
    pub const NORMAL: Color32 = Color32::from_rgb(80, 150, 255);
    pub const VIEW: Color32 = Color32::from_rgb(200, 200, 200);
    pub const MIRROR: Color32 = Color32::from_rgb(120, 220, 220);
    pub const STATIC_TERM: Color32 = Color32::from_rgb(110, 150, 255);
    pub const DYNAMIC_TERM: Color32 = Color32::from_rgb(255, 90, 40);
    pub const CONE: Color32 = Color32::from_rgb(190, 190, 130);
    pub const MERGED_CONE: Color32 = Color32::from_rgb(255, 225, 0);
    pub const RAY_CULLED: Color32 = Color32::from_rgb(90, 90, 90);
    pub const RAY_ESCAPED: Color32 = Color32::from_rgb(235, 235, 235);
    pub const RAY_STATIC: Color32 = Color32::from_rgb(60, 110, 255);
    pub const RAY_DYNAMIC: Color32 = Color32::from_rgb(255, 30, 30);
}

/// State of the sphere view: orientation, layers, the vertex under the mouse.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SphereView {
    /// Azimuth and elevation of the eye around the sphere, radians.
    pub yaw: f32,
    pub pitch: f32,
    pub layers: Layers,
    /// Magnify the flat view to the polygons drawn (small lights cover a few pixels of the
    /// whole hemisphere); off, the disk is the whole hemisphere, whose areas are form factors.
    #[serde(default)]
    pub fit: bool,
    #[serde(skip)]
    pub hovered: Option<String>,
    /// Side of the 3D sphere's square drawn last (points).
    #[serde(skip)]
    pub sphere_side: f32,
}

impl Default for SphereView {
    fn default() -> Self {
        SphereView {
            yaw: -1.2,
            pitch: 0.45,
            layers: Layers::default(),
            fit: false,
            hovered: None,
            sphere_side: 0.0,
        }
    }
}

/// A polyline on the sphere with how to draw it.
struct Curve {
    points: Vec<DVec3>,
    colour: Color32,
    width: f32,
    closed: bool,
    /// A single direction drawn as a small circle of fixed size on screen.
    marker: bool,
    /// Directions drawn as small filled dots (rays).
    dot: bool,
    label: String,
    /// Its entry in the legend.
    legend: &'static str,
    /// Corners of the polygon drawn (not the arc points between them), with the tag their
    /// labels start with; empty for curves whose corners are not labelled.
    vertices: Vec<DVec3>,
    tag: &'static str,
}

/// Points along the great-circle arc from `a` to `b` (unit vectors), `a` included.
fn arc(a: DVec3, b: DVec3, out: &mut Vec<DVec3>) {
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

fn loops_to_curves(
    loops: impl Iterator<Item = Vec<DVec3>>,
    colour: Color32,
    width: f32,
    (label, legend): (&str, &'static str),
    tag: &'static str,
    out: &mut Vec<Curve>,
) {
    for lp in loops {
        if lp.len() < 2 {
            continue;
        }
        let v: Vec<DVec3> = lp.iter().map(|p| p.normalize_or_zero()).collect();
        let mut points = Vec::new();
        for k in 0..v.len() {
            arc(v[k], v[(k + 1) % v.len()], &mut points);
        }
        out.push(Curve {
            points,
            colour,
            width,
            closed: true,
            marker: false,
            dot: false,
            label: label.into(),
            legend,
            vertices: if tag.is_empty() { Vec::new() } else { v },
            tag,
        });
    }
}

/// What the step (or everything, without a step) shows of one light record.
fn curves_of(
    rec: &LightRecord,
    step: Option<&Step>,
    layers: &Layers,
    occluder_name: &dyn Fn(usize) -> String,
    out: &mut Vec<Curve>,
) {
    // Order of the kinds within a light record, to draw everything up to the current step.
    let rank = |k: &StepKind| match k {
        StepKind::LightSilhouette => 0,
        StepKind::LightClipped => 1,
        StepKind::Culling => 2,
        StepKind::OccluderSilhouette { .. } | StepKind::OccluderClipped { .. } => 3,
        StepKind::SetDifference { .. } => 4,
        StepKind::Visible => 5,
        StepKind::LtcTransformed { .. } | StepKind::LtcClipped { .. } => 6,
        StepKind::Integral => 7,
    };
    let upto = step.map_or(7, |s| rank(&s.kind));
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
            let colour = if upto >= 5 || (who.is_none() && upto >= 3) {
                colours::CONTOUR.gamma_multiply(0.3)
            } else {
                colours::CONTOUR
            };
            for [a, b] in edges {
                let mut points = Vec::new();
                arc(*a, *b, &mut points);
                points.push(*b);
                out.push(Curve {
                    points,
                    colour,
                    width: 1.0,
                    closed: false,
                    marker: false,
                    dot: false,
                    label: label.clone(),
                    legend: "contour edge",
                    vertices: Vec::new(),
                    tag: "",
                });
            }
        }
    }
    if layers.contours {
        // Exact silhouettes of non-convex meshes: the contour pieces the ray test rejected
        // (dim red) and the apparent intersections where pieces were cut (small loops).
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
                let mut points = Vec::new();
                arc(*a, *b, &mut points);
                points.push(*b);
                out.push(Curve {
                    points,
                    colour: colours::REJECTED,
                    width: 1.5,
                    closed: false,
                    marker: false,
                    dot: false,
                    label: format!("{who}: contour piece rejected by the ray test"),
                    legend: "rejected contour piece",
                    vertices: Vec::new(),
                    tag: "",
                });
            }
            let source = if ex.from_tree {
                "from the BSP tree"
            } else {
                "on the fly"
            };
            for &p in &ex.crossings {
                // A circle of fixed size on screen: the crossings must stay visible on a small
                // sphere, and a circle on the sphere would shrink to a few pixels.
                out.push(Curve {
                    points: vec![p],
                    colour: colours::CROSSING,
                    width: 1.5,
                    closed: false,
                    marker: true,
                    dot: false,
                    label: format!("{who}: apparent intersection (Eq. 4.4), silhouette {source}"),
                    legend: "apparent intersection",
                    vertices: Vec::new(),
                    tag: "",
                });
            }
        }
    }
    for (stage, poly) in &rec.polygons {
        let (show, colour, width, name, r): (_, _, _, &'static str, _) = match stage {
            Stage::Silhouette => (
                layers.light_silhouette,
                colours::LIGHT,
                1.5,
                "light silhouette",
                0,
            ),
            Stage::HorizonClipped => (
                layers.light_clipped,
                colours::LIGHT_CLIPPED,
                2.0,
                "light, clipped",
                1,
            ),
            Stage::Visible => (layers.visible, colours::VISIBLE, 3.0, "visible polygon", 5),
            _ => continue,
        };
        // Once the visible polygon is shown, the earlier light polygons fade.
        let colour = if upto >= 5 && r < 5 {
            colour.gamma_multiply(0.35)
        } else {
            colour
        };
        if show && r <= upto {
            // The corners of the current stage's polygon are labelled (l: light, v: visible).
            let tag = match (r == upto || (step.is_none() && r == 5), r) {
                (false, _) => "",
                (true, 5) => "v",
                (true, _) => "l",
            };
            loops_to_curves(
                poly.loops().map(|l| l.to_vec()),
                colour,
                width,
                (name, name),
                tag,
                out,
            );
        }
    }
    if layers.occluders && upto >= 3 {
        for (k, (oi, _, stage, poly)) in rec.occluder_polygons.iter().enumerate() {
            // At an occluder step, only that occluder's polygons so far.
            if let Some(
                StepKind::OccluderSilhouette { k: cur } | StepKind::OccluderClipped { k: cur },
            ) = step.map(|s| s.kind)
                && k > cur
            {
                continue;
            }
            let (colour, width, legend) = match stage {
                Stage::Silhouette => (colours::OCCLUDER, 1.5, "occluder silhouette"),
                _ => (colours::OCCLUDER_CLIPPED, 2.0, "occluder, clipped"),
            };
            let colour = if upto >= 5 {
                colour.gamma_multiply(0.35)
            } else {
                colour
            };
            let tag = if (3..=4).contains(&upto) { "o" } else { "" };
            loops_to_curves(
                poly.loops().map(|l| l.to_vec()),
                colour,
                width,
                (&format!("occluder {}", occluder_name(*oi)), legend),
                tag,
                out,
            );
        }
    }
    if layers.ltc && upto >= 6 {
        for (lobe, transformed, clipped, integral) in &rec.lobes {
            let name = format!("{lobe:?} lobe, LTC space (integral {integral:.5})");
            loops_to_curves(
                transformed.loops().map(|l| l.to_vec()),
                colours::LTC.gamma_multiply(0.5),
                1.5,
                (&name, "LTC space"),
                "",
                out,
            );
            loops_to_curves(
                clipped.loops().map(|l| l.to_vec()),
                colours::LTC,
                2.5,
                (&name, "LTC space"),
                "t",
                out,
            );
        }
    }
}

/// The environment's layers at the picked point: the exact method's union terms, `rt`'s cones
/// and rays, as curves on the sphere (shading frame).
fn environment_curves(
    probe: &Probe,
    layers: &Layers,
    occluder_name: &dyn Fn(usize) -> String,
    out: &mut Vec<Curve>,
) {
    let rec = &probe.recording.environment;
    let terms = match &probe.environment {
        Some(e) if rec.terms.is_empty() => &e.exact_terms,
        _ => &rec.terms,
    };
    if layers.env_terms {
        for t in terms {
            let (colour, legend, side) = match t.side {
                EnvironmentSide::Static => {
                    (colours::STATIC_TERM, "static term S_k − S_<k", "static")
                }
                EnvironmentSide::Dynamic => (
                    colours::DYNAMIC_TERM,
                    "dynamic term D_i − S − D_<i",
                    "dynamic",
                ),
            };
            let name = format!(
                "{side} term of {}: ∫ L cos = {}",
                occluder_name(t.occluder),
                super::inspector::fmt3(t.integral)
            );
            loops_to_curves(
                t.polygon.loops().map(|l| l.to_vec()),
                colour,
                2.0,
                (&name, legend),
                "",
                out,
            );
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
        for (i, c) in rec.cones.iter().enumerate() {
            out.push(Curve {
                points: circle(c),
                colour: colours::CONE,
                width: 1.0,
                closed: true,
                marker: false,
                dot: false,
                label: format!(
                    "cone {i} (002 Eq. 4): ψ = {:.2}°, h = {:.3}",
                    c.half_angle.to_degrees(),
                    c.height
                ),
                legend: "cone (Eq. 4)",
                vertices: Vec::new(),
                tag: "",
            });
        }
        for (i, c) in rec.merged_cones.iter().enumerate() {
            out.push(Curve {
                points: circle(c),
                colour: colours::MERGED_CONE,
                width: 2.0,
                closed: true,
                marker: false,
                dot: false,
                label: format!(
                    "merged cone {i} (Alg. 1): ψ = {:.2}°, h = {:.3}",
                    c.half_angle.to_degrees(),
                    c.height
                ),
                legend: "merged cone (Alg. 1)",
                vertices: Vec::new(),
                tag: "",
            });
        }
    }
    if layers.rays {
        for r in &rec.rays {
            // Culled rays smaller: the traced ones are what the eye should find.
            let width = if r.outcome == RayOutcome::Culled {
                0.6
            } else {
                1.4
            };
            let (colour, legend) = match r.outcome {
                RayOutcome::Culled => (colours::RAY_CULLED, "ray culled"),
                RayOutcome::Escaped => (colours::RAY_ESCAPED, "ray traced, escaped"),
                RayOutcome::Static => (colours::RAY_STATIC, "ray traced, hit static"),
                RayOutcome::Dynamic => (colours::RAY_DYNAMIC, "ray traced, hit dynamic"),
            };
            out.push(Curve {
                points: vec![r.dir],
                colour,
                width,
                closed: false,
                marker: false,
                dot: true,
                label: legend.to_string(),
                legend,
                vertices: Vec::new(),
                tag: "",
            });
        }
    }
}

/// The map's radiance on the probe's coarse grid, drawn as filled cells under everything
/// else: on the 3D sphere (cells facing the eye; below the horizon dimmed) and on the flat
/// hemisphere (cells above the horizon). Tone-mapped so that the mean radiance of the grid
/// is mid-grey (Reinhard), and dimmed so the curves stay legible.
fn draw_sky(
    painter: &egui::Painter,
    env: &crate::inspect::EnvironmentProbe,
    project: &dyn Fn(DVec3) -> (Pos2, bool),
    hemisphere_only: bool,
    facing: &dyn Fn(DVec3) -> bool,
) {
    let (rows, cols) = (env.sky_rows, env.sky_cols);
    if env.sky.len() != (rows * cols) as usize || rows == 0 {
        return;
    }
    let mean = env
        .sky
        .iter()
        .map(|c| crate::environment::luminance(*c))
        .sum::<f64>()
        / env.sky.len() as f64;
    let exposure = if mean > 0.0 { -mean.log2() } else { 0.0 };
    let mut mesh = egui::Mesh::default();
    for r in 0..rows {
        for c in 0..cols {
            let (rf, cf) = (r as f64, c as f64);
            let centre = sky_grid_direction(rows, cols, rf + 0.5, cf + 0.5);
            if hemisphere_only && centre.z < 0.0 {
                continue;
            }
            if !facing(centre) {
                continue;
            }
            let corners = [
                (rf, cf),
                (rf + 1.0, cf),
                (rf + 1.0, cf + 1.0),
                (rf, cf + 1.0),
            ]
            .map(|(a, b)| project(sky_grid_direction(rows, cols, a, b)).0);
            let colour = tonemap(
                env.sky[(r * cols + c) as usize],
                exposure,
                ToneMap::Reinhard,
            )
            .gamma_multiply(if centre.z < 0.0 { 0.25 } else { 0.7 });
            // One mesh, no anti-aliasing: neighbouring cells meet without seams.
            let base = mesh.vertices.len() as u32;
            for p in corners {
                mesh.colored_vertex(p, colour);
            }
            mesh.add_triangle(base, base + 1, base + 2);
            mesh.add_triangle(base, base + 2, base + 3);
        }
    }
    painter.add(Shape::mesh(mesh));
}

/// Orthographic eye basis: (right, up, toward the eye).
fn eye_basis(yaw: f32, pitch: f32) -> (DVec3, DVec3, DVec3) {
    let (yaw, pitch) = (yaw as f64, pitch as f64);
    let e = DVec3::new(
        pitch.cos() * yaw.cos(),
        pitch.cos() * yaw.sin(),
        pitch.sin(),
    );
    let right = DVec3::Z.cross(e).try_normalize().unwrap_or(DVec3::X);
    let up = e.cross(right);
    (right, up, e)
}

impl SphereView {
    /// Draws the 3D sphere (left half of the space given) and the flat hemisphere (right half).
    /// What the step shows: the curves on the sphere and the shading-frame directions.
    fn drawing(&self, probe: &Probe, step: Option<&Step>) -> (Vec<Curve>, Vec<Arrow>) {
        let names = |i: usize| {
            probe
                .occluder_names
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("#{i}"))
        };
        let mut curves = Vec::new();
        for (r, rec) in probe.recording.lights.iter().enumerate() {
            match step {
                Some(s) if s.record != r => continue,
                _ => curves_of(rec, step, &self.layers, &names, &mut curves),
            }
        }
        // The environment's layers do not belong to a light's stages: shown at every step.
        if probe.environment.is_some() {
            environment_curves(probe, &self.layers, &names, &mut curves);
        }
        let mut arrows = Vec::new();
        if self.layers.directions {
            arrows.push((DVec3::Z, colours::NORMAL, "normal n"));
            if let Some(sp) = probe.point {
                let to_local = |w: DVec3| {
                    DVec3::new(
                        w.dot(probe.frame_x),
                        w.dot(probe.frame_y),
                        w.dot(probe.frame_z),
                    )
                };
                let v = to_local(sp.view);
                arrows.push((v, colours::VIEW, "view v"));
                arrows.push((DVec3::new(-v.x, -v.y, v.z), colours::MIRROR, "mirror r"));
            }
        }
        (curves, arrows)
    }

    /// The layer switches, as a menu (a row of checkboxes would take the sphere's room).
    pub fn layers_ui(&mut self, ui: &mut Ui, probe: &Probe) {
        ui.menu_button("layers", |ui| {
            let l = &mut self.layers;
            ui.checkbox(&mut l.contours, "contour edges");
            ui.checkbox(&mut l.light_silhouette, "light silhouette");
            ui.checkbox(&mut l.light_clipped, "clipped");
            ui.checkbox(&mut l.occluders, "occluders");
            ui.checkbox(&mut l.visible, "visible");
            ui.checkbox(&mut l.ltc, "LTC space");
            ui.checkbox(&mut l.directions, "n, v, r");
            ui.checkbox(&mut l.vertex_labels, "vertex labels");
            if probe.environment.is_some() {
                ui.checkbox(&mut l.environment, "environment map");
                ui.checkbox(&mut l.env_terms, "union terms");
                ui.checkbox(&mut l.cones, "cones");
                ui.checkbox(&mut l.rays, "rays");
            }
            ui.checkbox(&mut self.fit, "zoom the flat view to fit");
        });
    }

    /// The rotatable 3D unit sphere, as large as the space given (drag to rotate).
    pub fn sphere_ui(&mut self, ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
        let (curves, arrows) = self.drawing(probe, step);
        let sky = probe
            .environment
            .as_ref()
            .filter(|_| self.layers.environment);
        let (resp, painter) = canvas(ui, "unit sphere (drag to rotate)", Sense::drag());
        if resp.dragged() {
            let d = resp.drag_delta();
            self.yaw -= d.x * 0.01;
            self.pitch = (self.pitch + d.y * 0.01).clamp(-1.5, 1.5);
        }
        let rect = resp.rect;
        self.sphere_side = rect.width().min(rect.height());
        let c = rect.center();
        let radius = self.sphere_side * 0.45;
        let (right, up, eye) = eye_basis(self.yaw, self.pitch);
        let project = |p: DVec3| -> (Pos2, bool) {
            (
                Pos2::new(
                    c.x + (p.dot(right) as f32) * radius,
                    c.y - (p.dot(up) as f32) * radius,
                ),
                p.dot(eye) >= 0.0,
            )
        };
        let bg = ui.visuals().extreme_bg_color;
        painter.rect_filled(rect, 4.0, bg);
        if let Some(env) = sky {
            draw_sky(&painter, env, &project, false, &|d| d.dot(eye) >= 0.0);
        }
        painter.circle_stroke(c, radius, Stroke::new(1.0, ui.visuals().weak_text_color()));
        // Horizon: the great circle z = 0.
        let mut horizon = Vec::new();
        for k in 0..=128 {
            let a = k as f64 / 128.0 * std::f64::consts::TAU;
            horizon.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        let hcol = ui.visuals().text_color();
        draw_polyline(&painter, &horizon, &project, hcol, 1.0, false);
        for cv in &curves {
            draw_curve(&painter, cv, &project);
        }
        if self.layers.vertex_labels {
            draw_vertex_labels(&painter, &curves, &project, radius);
        }
        for (d, col, name) in &arrows {
            let (tip, front) = project(*d);
            let col = if front { *col } else { col.gamma_multiply(0.3) };
            painter.line_segment([c, tip], Stroke::new(2.0, col));
            painter.text(
                tip,
                egui::Align2::LEFT_BOTTOM,
                *name,
                egui::FontId::proportional(12.0),
                col,
            );
        }
        self.hovered = None;
        if let Some(pos) = resp.hover_pos() {
            self.hover(&curves, pos, &|p| project(p).0, &painter);
        }
        self.overlay(&painter, rect, &curves, ui.visuals());
    }

    /// The hemisphere seen from the normal (orthographic: areas are form factors).
    pub fn hemisphere_ui(&mut self, ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
        let (curves, arrows) = self.drawing(probe, step);
        let sky = probe
            .environment
            .as_ref()
            .filter(|_| self.layers.environment);
        let (resp, painter) = canvas(ui, "hemisphere seen from the normal", Sense::hover());
        let rect: Rect = resp.rect;
        let radius = rect.width().min(rect.height()) * 0.45;
        let bg = ui.visuals().extreme_bg_color;
        let hcol = ui.visuals().text_color();
        painter.rect_filled(rect, 4.0, bg);
        // The square of the disk shown: all of it, or the box of the points drawn above the
        // horizon (with a margin) when fitting.
        let (centre, half) = match self.fit.then(|| fit_box(&curves)).flatten() {
            Some((lo, hi)) => ((lo + hi) / 2.0, ((hi - lo).max_element() * 0.6).max(1e-4)),
            None => (glam::DVec2::ZERO, 1.0),
        };
        let scale = radius as f64 / half;
        let c2 = rect.center();
        let flat = |p: DVec3| -> (Pos2, bool) {
            (
                Pos2::new(
                    c2.x + ((p.x - centre.x) * scale) as f32,
                    c2.y - ((p.y - centre.y) * scale) as f32,
                ),
                p.z >= 0.0,
            )
        };
        if let Some(env) = sky {
            draw_sky(&painter, env, &flat, true, &|_| true);
        }
        painter.circle_stroke(flat(DVec3::ZERO).0, scale as f32, Stroke::new(1.0, hcol));
        if self.fit {
            painter.text(
                rect.right_top() + Vec2::new(-4.0, 4.0),
                egui::Align2::RIGHT_TOP,
                format!("×{:.1}", 1.0 / half),
                egui::FontId::proportional(12.0),
                hcol,
            );
        }
        for cv in &curves {
            draw_curve(&painter, cv, &flat);
        }
        if self.layers.vertex_labels {
            draw_vertex_labels(&painter, &curves, &flat, radius);
        }
        for (d, col, name) in &arrows {
            let (tip, _) = flat(*d);
            painter.circle_filled(tip, 3.0, *col);
            painter.text(
                tip,
                egui::Align2::LEFT_BOTTOM,
                *name,
                egui::FontId::proportional(12.0),
                *col,
            );
        }
        self.hovered = None;
        if let Some(pos) = resp.hover_pos() {
            self.hover(&curves, pos, &|p| flat(p).0, &painter);
        }
        self.overlay(&painter, rect, &curves, ui.visuals());
    }

    /// The legend (top left) and the hovered vertex (bottom), drawn over the canvas so that
    /// the sphere keeps the whole tile.
    fn overlay(&self, painter: &egui::Painter, rect: Rect, curves: &[Curve], v: &egui::Visuals) {
        let font = egui::FontId::proportional(12.0);
        let mut kinds: Vec<&Curve> = Vec::new();
        for cv in curves {
            if !kinds.iter().any(|k| k.legend == cv.legend) {
                kinds.push(cv);
            }
        }
        let mut y = rect.top() + 6.0;
        let widest = kinds
            .iter()
            .map(|k| k.legend.chars().count())
            .max()
            .unwrap_or(0) as f32;
        if !kinds.is_empty() {
            // A veil under the legend, so that curves behind it do not garble it.
            painter.rect_filled(
                Rect::from_min_size(
                    Pos2::new(rect.left() + 2.0, y - 2.0),
                    Vec2::new(26.0 + widest * 6.5, kinds.len() as f32 * 15.0 + 4.0),
                ),
                3.0,
                v.extreme_bg_color.gamma_multiply(0.8),
            );
        }
        for k in kinds {
            let a = Pos2::new(rect.left() + 6.0, y + 7.0);
            if k.dot {
                painter.circle_filled(a + Vec2::new(7.0, 0.0), 3.0, k.colour);
            } else if k.marker {
                painter.circle_stroke(a + Vec2::new(7.0, 0.0), 4.0, Stroke::new(k.width, k.colour));
            } else {
                painter.line_segment(
                    [a, a + Vec2::new(14.0, 0.0)],
                    Stroke::new(k.width.max(2.0), k.colour),
                );
            }
            painter.text(
                a + Vec2::new(20.0, 0.0),
                egui::Align2::LEFT_CENTER,
                k.legend,
                font.clone(),
                v.text_color(),
            );
            y += 15.0;
        }
        if let Some(h) = &self.hovered {
            let galley =
                painter.layout(h.clone(), font, v.strong_text_color(), rect.width() - 12.0);
            let pos = Pos2::new(rect.left() + 6.0, rect.bottom() - 6.0 - galley.size().y);
            painter.rect_filled(
                Rect::from_min_size(pos, galley.size()).expand(2.0),
                2.0,
                v.extreme_bg_color.gamma_multiply(0.85),
            );
            painter.galley(pos, galley, v.strong_text_color());
        }
    }

    fn hover(
        &mut self,
        curves: &[Curve],
        pos: Pos2,
        project: &dyn Fn(DVec3) -> Pos2,
        painter: &egui::Painter,
    ) {
        let mut best: Option<(f32, DVec3, &str)> = None;
        for cv in curves {
            // Vertices of the original polygon are where arcs start; show every arc point.
            for &p in &cv.points {
                let d = project(p).distance(pos);
                if d < 8.0 && best.is_none_or(|b| d < b.0) {
                    best = Some((d, p, &cv.label));
                }
            }
        }
        if let Some((_, p, label)) = best {
            painter.circle_stroke(project(p), 5.0, Stroke::new(1.5, Color32::WHITE));
            let theta = p.z.clamp(-1.0, 1.0).acos().to_degrees();
            let phi = p.y.atan2(p.x).to_degrees();
            self.hovered = Some(format!(
                "{label}: ({:.5}, {:.5}, {:.5})  θ = {theta:.2}°, φ = {phi:.2}°",
                p.x, p.y, p.z
            ));
        }
    }
}

/// How the exact silhouette of the step's mesh (if non-convex) was found, in words.
fn exact_silhouette_text(rec: &LightRecord, step: &Step) -> Option<String> {
    let occluder = match step.kind {
        StepKind::LightSilhouette => None,
        StepKind::OccluderSilhouette { k } => Some(rec.occluder_polygons.get(k)?.0),
        _ => return None,
    };
    let ex = rec.exact.iter().find(|e| e.occluder == occluder)?;
    let crossings = format!(
        "{} apparent intersection(s) (Eq. 4.4, magenta circles: contour edges crossing as \
         seen from the point)",
        ex.crossings.len()
    );
    Some(if ex.from_tree {
        format!(
            "Exact silhouette read from the BSP tree: {crossings}. A tree stores only the \
             result, so no rejected contour pieces are recorded; untick \"silhouettes from \
             BSP trees\" to see them."
        )
    } else {
        format!(
            "Exact silhouette computed at the point: {crossings}; {} contour piece(s) rejected \
             by the ray test (dim red: hidden by the mesh itself).",
            ex.rejected.len()
        )
    })
}

/// The box (in the flat view's x, y) of every curve point above the horizon; `None` if none.
fn fit_box(curves: &[Curve]) -> Option<(glam::DVec2, glam::DVec2)> {
    let mut pts = curves
        .iter()
        .flat_map(|c| &c.points)
        .filter(|p| p.z >= 0.0)
        .map(|p| p.truncate());
    let first = pts.next()?;
    Some(pts.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// A shading-frame direction drawn as an arrow: where, colour, name.
type Arrow = (DVec3, Color32, &'static str);

/// A square canvas as large as the space left (centred), named for accessibility.
fn canvas(ui: &mut Ui, name: &'static str, sense: Sense) -> (egui::Response, egui::Painter) {
    let avail = ui.available_size();
    let side = avail.x.min(avail.y).max(120.0);
    let (rect, _) = ui.allocate_exact_size(avail.max(Vec2::splat(side)), Sense::hover());
    let square = Rect::from_center_size(rect.center(), Vec2::splat(side));
    let resp = ui.interact(square, ui.scope_id().with(name), sense);
    resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, name));
    (resp, ui.painter_at(square))
}

/// Labels the corners of the current stage's polygons: the tag and the corner's index in its
/// loop (`v0`, `v1`, ... of the visible polygon), where the view is large enough to read them.
fn draw_vertex_labels(
    painter: &egui::Painter,
    curves: &[Curve],
    project: &dyn Fn(DVec3) -> (Pos2, bool),
    radius: f32,
) {
    if radius < 120.0 {
        return;
    }
    let font = egui::FontId::monospace(11.0);
    for cv in curves.iter().filter(|c| !c.tag.is_empty()) {
        for (i, &p) in cv.vertices.iter().enumerate() {
            let (q, front) = project(p);
            if !front {
                continue;
            }
            painter.circle_filled(q, 2.5, cv.colour);
            painter.text(
                q + Vec2::new(4.0, -2.0),
                egui::Align2::LEFT_BOTTOM,
                format!("{}{i}", cv.tag),
                font.clone(),
                cv.colour,
            );
        }
    }
}

/// What the current step adds in words: how an exact silhouette was found, and at the
/// integral step each lobe's value with its per-edge terms (000 Eq. 9's sum, over 2π).
pub fn step_details_ui(ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
    let Some(s) = step else {
        return;
    };
    let Some(rec) = probe.recording.lights.get(s.record) else {
        return;
    };
    if let Some(text) = exact_silhouette_text(rec, s) {
        ui.add(egui::Label::new(egui::RichText::new(text).small()).wrap());
    }
    if s.kind == StepKind::Integral {
        for ((lobe, _, _, integral), (_, terms)) in rec.lobes.iter().zip(&rec.lobe_edge_terms) {
            ui.label(format!("{lobe:?} lobe: ∫ = {integral:.6}; per edge:"));
            for (li, loop_terms) in terms.iter().enumerate() {
                let parts: Vec<String> = loop_terms.iter().map(|t| format!("{t:+.5}")).collect();
                ui.add(egui::Label::new(format!("  loop {li}: {}", parts.join(" "))).wrap());
            }
        }
    }
}

/// Draws a curve: a marker as a small circle (faint on the far side), dots as small filled
/// circles, else a polyline.
fn draw_curve(painter: &egui::Painter, cv: &Curve, project: &dyn Fn(DVec3) -> (Pos2, bool)) {
    if cv.dot {
        for &p in &cv.points {
            let (q, front) = project(p);
            let colour = if front {
                cv.colour
            } else {
                cv.colour.gamma_multiply(0.25)
            };
            painter.circle_filled(q, 1.0 + cv.width, colour);
        }
    } else if cv.marker {
        for &p in &cv.points {
            let (q, front) = project(p);
            let colour = if front {
                cv.colour
            } else {
                cv.colour.gamma_multiply(0.25)
            };
            painter.circle_stroke(q, 4.5, Stroke::new(cv.width, colour));
        }
    } else {
        draw_polyline(painter, &cv.points, project, cv.colour, cv.width, cv.closed);
    }
}

/// Draws a polyline, solid where `project` says front, faint elsewhere; an arrowhead every
/// ~third of the way shows the orientation.
fn draw_polyline(
    painter: &egui::Painter,
    pts: &[DVec3],
    project: &dyn Fn(DVec3) -> (Pos2, bool),
    colour: Color32,
    width: f32,
    closed: bool,
) {
    let n = pts.len();
    if n < 2 {
        return;
    }
    let segs = if closed { n } else { n - 1 };
    let faint = colour.gamma_multiply(0.25);
    for k in 0..segs {
        let (a, fa) = project(pts[k]);
        let (b, fb) = project(pts[(k + 1) % n]);
        let front = fa && fb;
        let stroke = if front {
            Stroke::new(width, colour)
        } else {
            Stroke::new(width * 0.6, faint)
        };
        painter.add(Shape::line_segment([a, b], stroke));
        if closed && front && k % (n / 3).max(1) == n / 6 {
            let d = (b - a).normalized();
            if d.is_finite() {
                let nrm = Vec2::new(-d.y, d.x);
                let tip = b;
                painter.add(Shape::convex_polygon(
                    vec![tip, tip - d * 8.0 + nrm * 4.0, tip - d * 8.0 - nrm * 4.0],
                    colour,
                    Stroke::NONE,
                ));
            }
        }
    }
}
