//! The view state the sphere and hemisphere panes share, kept between sessions: the camera,
//! the layers, the flat view's zoom; the figures of `views::sphere` it paints with egui, and
//! the name and coordinates of the vertex under the mouse. Everything is in the shading frame
//! (z = n).

use crate::app::figure_painter::{self, FigureRect};
use crate::app::inspector::Inspector;
use crate::inspect::Probe;
use crate::views::sphere::{Drawing, Layers, drawing, region_of_interest};
use crate::views::stages::Step;
use crate::views::{self, SphereCamera, Style};
use egui::{Pos2, Rect, RichText, Sense, Stroke, Ui, Vec2};
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
    pub(crate) fn camera_for(&self, probe: &Probe, step: Option<&Step>) -> SphereCamera {
        self.camera
            .unwrap_or_else(|| SphereCamera::framed(&region_of_interest(probe, step)))
    }

    /// The figure a pane shows (also what Export ▸ Figure writes), `side` pixels square.
    pub(crate) fn figure(
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
    pub(crate) fn layers_ui(&mut self, ui: &mut Ui, probe: &Probe) {
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

    /// The header of a pane: the layer menu and the current stage's label.
    pub(crate) fn header_ui(&mut self, ui: &mut Ui, ins: &Inspector) {
        ui.horizontal(|ui| {
            self.layers_ui(ui, &ins.probe);
            let label = match ins.current() {
                Some(s) => s.label.clone(),
                None => format!("all {} stages", ins.steps.len()),
            };
            ui.add(egui::Label::new(RichText::new(label).strong()).truncate());
        });
    }

    /// Paints a pane's figure at the canvas' size and the vertex under the mouse.
    pub(super) fn paint(
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

/// What both sphere panes start with: the picked point (or, without one, the hint to pick
/// one), the pane's area as the app's subject (what a screenshot or a lesson frame crops to),
/// and the shared header of layers and stage.
pub(super) fn picked<'a>(
    ui: &mut Ui,
    app: &'a mut crate::app::AppState,
) -> Option<(&'a Inspector, &'a mut SphereView)> {
    let Some(ins) = &app.inspector else {
        ui.label(crate::app::ui::PICK_FIRST);
        return None;
    };
    app.subject_rect = Some(ui.max_rect());
    let view = &mut app.settings.sphere;
    view.header_ui(ui, ins);
    Some((ins, view))
}

/// A square canvas as large as the space left (centred), named for accessibility.
pub(super) fn canvas(
    ui: &mut Ui,
    name: &'static str,
    sense: Sense,
) -> (egui::Response, egui::Painter) {
    let avail = ui.available_size();
    let side = avail.x.min(avail.y).max(120.0);
    let (rect, _) = ui.allocate_exact_size(avail.max(Vec2::splat(side)), Sense::hover());
    let square = Rect::from_center_size(rect.center(), Vec2::splat(side));
    let resp = ui.interact(square, ui.scope_id().with(name), sense);
    resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, name));
    (resp, ui.painter_at(square))
}
