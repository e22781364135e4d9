//! The unit sphere at the picked shading point, drawing what the renderer recorded: a
//! rotatable 3D sphere (back hemisphere dimmed, horizon, normal, view and mirror directions)
//! and the flat hemisphere seen from above (orthographic: the area a polygon covers there is
//! its diffuse form factor, Nusselt's analogue). Everything is in the shading frame (z = n).

use super::stages::{Step, StepKind};
use super::tonemap::{ToneMap, tonemap};
use crate::inspect::{Probe, sky_grid_direction};
use crate::ltc::edge_integral;
use crate::shading::{EnvironmentSide, LightRecord, RayOutcome, Stage};
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
    /// Width available to the two views (points): the panel's, set by the caller.
    #[serde(skip)]
    pub width: f32,
}

impl Default for SphereView {
    fn default() -> Self {
        SphereView {
            yaw: -1.2,
            pitch: 0.45,
            layers: Layers::default(),
            fit: false,
            hovered: None,
            width: 480.0,
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
            loops_to_curves(
                poly.loops().map(|l| l.to_vec()),
                colour,
                width,
                (name, name),
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
            loops_to_curves(
                poly.loops().map(|l| l.to_vec()),
                colour,
                width,
                (&format!("occluder {}", occluder_name(*oi)), legend),
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
                out,
            );
            loops_to_curves(
                clipped.loops().map(|l| l.to_vec()),
                colours::LTC,
                2.5,
                (&name, "LTC space"),
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
    pub fn ui(&mut self, ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
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
        let sky = probe
            .environment
            .as_ref()
            .filter(|_| self.layers.environment);
        // Shading-frame directions.
        let mut arrows: Vec<(DVec3, Color32, &str)> = Vec::new();
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

        let side = ((self.width - 12.0) / 2.0).clamp(120.0, 420.0);
        self.hovered = None;
        ui.horizontal(|ui| {
            // 3D sphere.
            let (resp, painter) = ui.allocate_painter(Vec2::splat(side), Sense::drag());
            resp.widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::Canvas, true, "unit sphere (drag to rotate)")
            });
            if resp.dragged() {
                let d = resp.drag_delta();
                self.yaw -= d.x * 0.01;
                self.pitch = (self.pitch + d.y * 0.01).clamp(-1.5, 1.5);
            }
            let rect = resp.rect;
            let c = rect.center();
            let radius = side * 0.45;
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
            for (d, col, name) in &arrows {
                let (tip, front) = project(*d);
                let col = if front { *col } else { col.gamma_multiply(0.3) };
                painter.line_segment([c, tip], Stroke::new(2.0, col));
                painter.text(
                    tip,
                    egui::Align2::LEFT_BOTTOM,
                    *name,
                    egui::FontId::proportional(11.0),
                    col,
                );
            }
            if let Some(pos) = resp.hover_pos() {
                self.hover(&curves, pos, &|p| project(p).0, &painter);
            }

            // Flat hemisphere, seen from above the normal.
            let (resp2, painter2) = ui.allocate_painter(Vec2::splat(side), Sense::hover());
            resp2.widget_info(|| {
                egui::WidgetInfo::labeled(
                    egui::Role::Canvas,
                    true,
                    "hemisphere seen from the normal",
                )
            });
            let rect2: Rect = resp2.rect;
            painter2.rect_filled(rect2, 4.0, bg);
            // The square of the disk shown: all of it, or the box of the points drawn above
            // the horizon (with a margin) when fitting.
            let (centre, half) = match self.fit.then(|| fit_box(&curves)).flatten() {
                Some((lo, hi)) => ((lo + hi) / 2.0, ((hi - lo).max_element() * 0.6).max(1e-4)),
                None => (glam::DVec2::ZERO, 1.0),
            };
            let scale = radius as f64 / half;
            let c2 = rect2.center();
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
                draw_sky(&painter2, env, &flat, true, &|_| true);
            }
            painter2.circle_stroke(flat(DVec3::ZERO).0, scale as f32, Stroke::new(1.0, hcol));
            if self.fit {
                painter2.text(
                    rect2.left_top() + Vec2::splat(4.0),
                    egui::Align2::LEFT_TOP,
                    format!("×{:.1}", 1.0 / half),
                    egui::FontId::proportional(11.0),
                    hcol,
                );
            }
            for cv in &curves {
                draw_curve(&painter2, cv, &flat);
            }
            for (d, col, name) in &arrows {
                let (tip, _) = flat(*d);
                painter2.circle_filled(tip, 3.0, *col);
                painter2.text(
                    tip,
                    egui::Align2::LEFT_BOTTOM,
                    *name,
                    egui::FontId::proportional(11.0),
                    *col,
                );
            }
            if let Some(pos) = resp2.hover_pos() {
                self.hover(&curves, pos, &|p| flat(p).0, &painter2);
            }
        });
        // Wrapped at the visible edge of the panel (which scrolls sideways).
        let visible = ui.clip_rect().max.x - ui.cursor().min.x;
        ui.scope(|ui| {
            ui.set_max_width(visible);
            legend_ui(ui, &curves);
            if let Some(s) = step
                && let Some(rec) = probe.recording.lights.get(s.record)
                && let Some(text) = exact_silhouette_text(rec, s)
            {
                ui.add(egui::Label::new(egui::RichText::new(text).small()).wrap());
            }
        });
        if let Some(h) = &self.hovered {
            ui.label(h);
        }
        if let Some(s) = step
            && let Some(rec) = probe.recording.lights.get(s.record)
            && s.kind == StepKind::Integral
        {
            for (lobe, _, clipped, integral) in &rec.lobes {
                ui.label(format!("{lobe:?} lobe: ∫ = {integral:.6}; per edge:"));
                for (li, lp) in clipped.loops().enumerate() {
                    let parts: Vec<String> = (0..lp.len())
                        .map(|k| {
                            format!(
                                "{:+.5}",
                                edge_integral(lp[k], lp[(k + 1) % lp.len()])
                                    / std::f64::consts::TAU
                            )
                        })
                        .collect();
                    ui.label(format!("  loop {li}: {}", parts.join(" ")));
                }
            }
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

/// One swatch per kind of curve drawn, in drawing order, in the colour it was drawn with.
fn legend_ui(ui: &mut Ui, curves: &[Curve]) {
    let mut kinds: Vec<&Curve> = Vec::new();
    for cv in curves {
        if !kinds.iter().any(|k| k.legend == cv.legend) {
            kinds.push(cv);
        }
    }
    ui.horizontal_wrapped(|ui| {
        for k in kinds {
            let (rect, _) = ui.allocate_exact_size(Vec2::new(16.0, 10.0), Sense::hover());
            let p = ui.painter();
            if k.dot {
                p.circle_filled(rect.center(), 3.0, k.colour);
            } else if k.marker {
                p.circle_stroke(rect.center(), 4.0, Stroke::new(k.width, k.colour));
            } else {
                p.line_segment(
                    [rect.left_center(), rect.right_center()],
                    Stroke::new(k.width.max(2.0), k.colour),
                );
            }
            ui.small(k.legend);
        }
    });
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
