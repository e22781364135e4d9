//! The light structure pane's state and controls: a light's polyhedron with what the
//! renderer recorded at the picked point on it (`views::light`: the contour edges, the BSP tree
//! the stage looked the silhouette up in, the planes on the recorded path and the leaf's cell),
//! painted by egui and explained in words under it. Nothing here looks anything up again.

use super::figure_painter::{self, FigureRect};
use crate::shading::{LightRecord, PreparedObject};
use crate::views::Style;
pub(crate) use crate::views::light::Drawn;
use crate::views::light::{LightCamera, light_figure};
use egui::{Sense, Ui, Vec2};
use glam::DVec3;

/// Orientation and layers of the structure view.
#[derive(Clone, Debug)]
pub struct LightView {
    pub yaw: f32,
    pub pitch: f32,
    /// Magnification over the fit of the light and the picked point.
    pub zoom: f32,
    /// Draw the planes on the picked point's path, each cut to its node's cell.
    pub path_planes: bool,
    /// Also draw every plane of the tree's first `levels` levels (0: none).
    pub levels: usize,
    /// What the last frame drew.
    pub drawn: Drawn,
}

impl Default for LightView {
    fn default() -> Self {
        LightView {
            yaw: 0.6,
            pitch: 0.4,
            zoom: 1.0,
            path_planes: true,
            levels: 0,
            drawn: Drawn::default(),
        }
    }
}

impl LightView {
    /// The figure this view shows (also what Export ▸ Figure writes), and what it drew.
    pub(crate) fn figure(
        &self,
        obj: &PreparedObject,
        point: Option<DVec3>,
        record: Option<&LightRecord>,
        side: u32,
        style: Style,
    ) -> (crate::figure::Figure, Drawn) {
        let camera = LightCamera {
            yaw: self.yaw,
            pitch: self.pitch,
            zoom: self.zoom,
            path_planes: self.path_planes,
            levels: self.levels,
        };
        light_figure(obj, point, record, &camera, side, style)
    }

    /// Draws the mesh of `obj`; with a picked point and the recording of its light (`record`,
    /// the light taken whole), the contour edges and the tree lookup recorded there.
    pub fn ui(
        &mut self,
        ui: &mut Ui,
        obj: &PreparedObject,
        point: Option<DVec3>,
        record: Option<&LightRecord>,
    ) {
        let poly = &obj.poly;
        let tree = obj.silhouette_tree();
        let lookup = record.and_then(|r| r.trees.iter().find(|t| t.occluder.is_none()));
        if tree.is_some() {
            // One control a line: side by side they would widen the panel (and the viewport
            // beside it would shrink and render again).
            ui.checkbox(&mut self.path_planes, "planes on the path");
            ui.add(egui::Slider::new(&mut self.levels, 0..=6).text("levels of planes"));
        }
        ui.add(
            egui::Slider::new(&mut self.zoom, 0.1..=20.0)
                .logarithmic(true)
                .text("zoom"),
        );
        let side = ui.available_width().clamp(160.0, 320.0);
        let (resp, painter) = ui.allocate_painter(Vec2::splat(side), Sense::drag());
        resp.widget_info(|| {
            egui::WidgetInfo::labeled(
                egui::Role::Canvas,
                true,
                "light polyhedron (drag to rotate)",
            )
        });
        if resp.dragged() {
            let d = resp.drag_delta();
            self.yaw -= d.x * 0.01;
            self.pitch = (self.pitch + d.y * 0.01).clamp(-1.5, 1.5);
        }
        let style = if ui.visuals().dark_mode {
            Style::Screen
        } else {
            Style::Print
        };
        let (fig, drawn) = self.figure(obj, point, record, side.round() as u32, style);
        self.drawn = drawn;
        figure_painter::paint(&painter, &fig, FigureRect::fit(&fig, resp.rect));

        // What was drawn, in words.
        let d = &poly.diagnostics;
        match tree {
            None => {
                ui.small("no BSP tree (silhouettes computed at each point)");
            }
            Some(t) => {
                let (n, leaves, depth) = t.size();
                ui.small(format!(
                    "BSP tree ({}): {n} nodes, {leaves} leaves, depth {depth}, {} planes, \
                     {:.1} KiB in memory",
                    t.kind().describe(),
                    t.planes().len(),
                    t.stored_bytes() as f64 / 1024.0
                ));
                let dr = &self.drawn;
                match (dr.leaf_depth, lookup) {
                    (Some(leaf_depth), Some(l)) => {
                        ui.small(format!(
                            "the renderer looked the picked point (blue dot) up in a leaf at \
                             depth {leaf_depth}; its cell (blue) has {} faces{}",
                            dr.cell_faces,
                            if l.answered {
                                ""
                            } else {
                                "; the leaf was left to the on-the-fly path, or the point is \
                                 outside the tree's box: the silhouette was computed there"
                            }
                        ));
                        if self.path_planes {
                            ui.small(format!(
                                "{} planes on its path, each cut to its node's cell, \
                                 labelled and coloured by depth (root red … depth {depth} violet)",
                                dr.path_planes
                            ));
                        }
                    }
                    _ if point.is_some() => {
                        ui.small(
                            "the renderer did not look this light up in its tree at the picked \
                             point (below the horizon, or taken face by face)",
                        );
                    }
                    _ => {
                        ui.small("pick a point to see its cell and the planes on its path");
                    }
                }
                if self.levels > 0 {
                    ui.small(format!(
                        "{} planes of the first {} levels (faint)",
                        dr.level_planes, self.levels
                    ));
                }
            }
        }
        if let Some(s) = obj.stand_in() {
            ui.small(format!(
                "drawn and shaded: the convex hull standing in for the mesh ({} vertices, {} \
                 faces; every point of the hull within {:.2e} of it)",
                s.mesh_vertices, s.mesh_faces, s.deviation
            ));
        }
        ui.small(format!(
            "{} vertices, {} edges, {} faces; {}{}",
            poly.vertices.len(),
            poly.edges.len(),
            poly.face_count(),
            if d.planar {
                "flat"
            } else if d.convex {
                "convex"
            } else {
                "non-convex"
            },
            match point {
                Some(_) => format!(
                    ", {} contour edges (yellow) recorded at the picked point",
                    self.drawn.contour_edges
                ),
                None => ", pick a point to see its contour edges".into(),
            }
        ));
    }
}
