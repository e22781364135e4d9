//! The unit sphere at the picked shading point, as the workbench shows it: the figures of
//! `views` (the 3-D sphere framed on the lights, and the hemisphere seen from above, where
//! areas are form factors) painted by egui, with what only a window has: orbit and zoom, and
//! the name and coordinates of the vertex under the mouse. Everything is in the shading frame
//! (z = n).

use super::figure_painter::{self, FigureRect};
use crate::inspect::Probe;
use crate::shading::LightRecord;
use crate::views::sphere::{Drawing, Layers, drawing, region_of_interest};
use crate::views::stages::{Step, StepKind};
use crate::views::{self, SphereCamera, Style};
use egui::{Pos2, Rect, Sense, Stroke, Ui, Vec2};
use glam::DVec3;

/// State of the sphere view: camera, layers, the vertex under the mouse.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SphereView {
    /// The camera once the user orbits or zooms; `None`: framed on the picked point's lights
    /// ([`SphereCamera::framed`]), which a new pick or "frame" restores.
    #[serde(default)]
    pub camera: Option<SphereCamera>,
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

/// Which of the sphere's figures a pane shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SphereFigure {
    Sphere,
    Hemisphere,
}

impl SphereView {
    /// The camera the 3-D sphere is drawn with for `probe`.
    pub fn camera_for(&self, probe: &Probe, step: Option<&Step>) -> SphereCamera {
        self.camera
            .unwrap_or_else(|| SphereCamera::framed(&region_of_interest(probe, step)))
    }

    /// The figure a pane shows (also what Export ▸ Figure writes), `side` pixels square.
    pub fn figure(
        &self,
        which: SphereFigure,
        probe: &Probe,
        step: Option<&Step>,
        side: u32,
        style: Style,
    ) -> crate::figure::Figure {
        let d = drawing(probe, step, &self.layers);
        self.figure_of(which, &d, &self.camera_for(probe, step), side, style)
    }

    fn figure_of(
        &self,
        which: SphereFigure,
        d: &Drawing,
        camera: &SphereCamera,
        side: u32,
        style: Style,
    ) -> crate::figure::Figure {
        match which {
            SphereFigure::Sphere => views::sphere_figure(d, camera, side, style),
            SphereFigure::Hemisphere => views::hemisphere_figure(d, self.fit, side, style),
        }
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

    /// The rotatable 3D unit sphere, as large as the space given (drag to rotate, scroll to
    /// zoom, double-click to frame the lights again).
    pub fn sphere_ui(&mut self, ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
        let (resp, painter) = canvas(ui, "unit sphere (drag to rotate)", Sense::click_and_drag());
        let mut camera = self.camera_for(probe, step);
        if resp.dragged() {
            let d = resp.drag_delta();
            camera.yaw -= d.x * 0.01;
            camera.pitch = (camera.pitch + d.y * 0.01).clamp(-1.5, 1.5);
            self.camera = Some(camera);
        }
        if resp.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                camera.zoom = (camera.zoom * (scroll * 0.003).exp()).clamp(0.5, 50.0);
                self.camera = Some(camera);
            }
        }
        if resp.double_clicked() {
            self.camera = None;
        }
        self.sphere_side = resp.rect.width();
        self.paint(ui, &resp, &painter, SphereFigure::Sphere, probe, step);
    }

    /// The hemisphere seen from the normal (orthographic: areas are form factors).
    pub fn hemisphere_ui(&mut self, ui: &mut Ui, probe: &Probe, step: Option<&Step>) {
        let (resp, painter) = canvas(ui, "hemisphere seen from the normal", Sense::hover());
        self.paint(ui, &resp, &painter, SphereFigure::Hemisphere, probe, step);
    }

    /// Paints the pane's figure at the canvas' size and the vertex under the mouse.
    fn paint(
        &mut self,
        ui: &Ui,
        resp: &egui::Response,
        painter: &egui::Painter,
        which: SphereFigure,
        probe: &Probe,
        step: Option<&Step>,
    ) {
        let rect = resp.rect;
        let side = rect.width().round().max(64.0) as u32;
        let style = if ui.visuals().dark_mode {
            Style::Screen
        } else {
            Style::Print
        };
        let d = drawing(probe, step, &self.layers);
        let camera = self.camera_for(probe, step);
        let fig = self.figure_of(which, &d, &camera, side, style);
        let at = FigureRect::fit(&fig, rect);
        figure_painter::paint(painter, &fig, at);
        self.hovered = None;
        if let Some(pos) = resp.hover_pos() {
            let project = match which {
                SphereFigure::Sphere => {
                    views::sphere::figure::sphere_projection(&self.camera_for(probe, step), side)
                }
                SphereFigure::Hemisphere => {
                    views::sphere::figure::hemisphere_projection(&d, self.fit, side)
                }
            };
            let to_screen = |p: DVec3| at.to_screen(project.project(p));
            self.hover(&d, pos, &to_screen, painter);
        }
        if let Some(h) = &self.hovered {
            let v = ui.visuals();
            let font = egui::FontId::proportional(12.0);
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
        d: &Drawing,
        pos: Pos2,
        to_screen: &dyn Fn(DVec3) -> Pos2,
        painter: &egui::Painter,
    ) {
        let mut best: Option<(f32, DVec3, &str)> = None;
        for cv in &d.curves {
            // Vertices of the original polygon are where arcs start; show every arc point.
            for &p in &cv.points {
                let dist = to_screen(p).distance(pos);
                if dist < 8.0 && best.is_none_or(|b| dist < b.0) {
                    best = Some((dist, p, &cv.label));
                }
            }
        }
        if let Some((_, p, label)) = best {
            painter.circle_stroke(to_screen(p), 5.0, Stroke::new(1.5, egui::Color32::WHITE));
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
