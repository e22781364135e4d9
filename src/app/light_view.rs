//! A light's polyhedron as a wireframe, with the contour edges seen from the picked point
//! (001 Eq. 4.2, `geometry::contour_edges`, the function the silhouette stage uses) drawn in
//! the orientation that makes the silhouette loop positive, and front faces shaded; and, for a
//! mesh with a BSP tree of precomputed silhouettes (001 Sect. 5), the cell of the picked point
//! (the tree's box cut by the planes on its path) with the tree's size and the path's depth.

use crate::geometry::silhouette::is_front_facing;
use crate::geometry::{bsp_cell, bsp_path, bsp_size, contour_edges};
use crate::shading::PreparedObject;
use egui::{Color32, Pos2, Sense, Stroke, Ui, Vec2};
use glam::DVec3;

/// Orientation of the structure view.
#[derive(Clone, Copy, Debug)]
pub struct LightView {
    pub yaw: f32,
    pub pitch: f32,
}

impl Default for LightView {
    fn default() -> Self {
        LightView {
            yaw: 0.6,
            pitch: 0.4,
        }
    }
}

impl LightView {
    /// Draws the mesh of `obj`; with a picked point, its contour edges and front faces from
    /// there, and the BSP cell of the point.
    pub fn ui(&mut self, ui: &mut Ui, obj: &PreparedObject, point: Option<DVec3>) {
        let poly = &obj.poly;
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
        let rect = resp.rect;
        painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
        let (yaw, pitch) = (self.yaw as f64, self.pitch as f64);
        // Eye direction about +y (world up), orthographic.
        let e = DVec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
        let right = DVec3::Y.cross(e).try_normalize().unwrap_or(DVec3::X);
        let up = e.cross(right);
        let scale = side as f64 * 0.42 / poly.radius.max(1e-12);
        let c = rect.center();
        let project = |p: DVec3| {
            let q = p - poly.center;
            Pos2::new(
                c.x + (q.dot(right) * scale) as f32,
                c.y - (q.dot(up) * scale) as f32,
            )
        };
        // Front faces from the picked point, filled faintly.
        if let Some(x) = point {
            for f in 0..poly.face_count() {
                if is_front_facing(poly, f, x) {
                    let pts: Vec<Pos2> = poly
                        .face(f)
                        .iter()
                        .map(|&i| project(poly.vertices[i as usize]))
                        .collect();
                    painter.add(egui::Shape::convex_polygon(
                        pts,
                        Color32::from_rgba_unmultiplied(240, 200, 40, 30),
                        Stroke::NONE,
                    ));
                }
            }
        }
        let weak = ui.visuals().weak_text_color();
        for edge in &poly.edges {
            let a = project(poly.vertices[edge.v[0] as usize]);
            let b = project(poly.vertices[edge.v[1] as usize]);
            painter.line_segment([a, b], Stroke::new(1.0, weak));
        }
        let mut n_contour = 0;
        if let Some(x) = point {
            for [i, j] in contour_edges(poly, x) {
                let a = project(poly.vertices[i as usize]);
                let b = project(poly.vertices[j as usize]);
                painter.line_segment([a, b], Stroke::new(2.5, Color32::from_rgb(240, 200, 40)));
                let d = (b - a).normalized();
                if d.is_finite() {
                    let n = Vec2::new(-d.y, d.x);
                    let m = a + (b - a) * 0.6;
                    painter.add(egui::Shape::convex_polygon(
                        vec![m + d * 6.0, m - d * 4.0 + n * 4.0, m - d * 4.0 - n * 4.0],
                        Color32::from_rgb(240, 200, 40),
                        Stroke::NONE,
                    ));
                }
                n_contour += 1;
            }
        }
        // The tree: the cell of the picked point.
        let tree = match (&obj.bsp, &obj.exact_bsp) {
            (Some(t), _) => Some((&t.nodes, &t.planes, t.lo, t.hi)),
            (None, Some(t)) => Some((&t.nodes, &t.planes, t.lo, t.hi)),
            _ => None,
        };
        let mut tree_line = "no BSP tree (silhouettes computed at each point)".to_string();
        if let Some((nodes, planes, lo, hi)) = tree {
            let (n, leaves, depth) = bsp_size(nodes);
            tree_line = format!("BSP tree: {n} nodes, {leaves} leaves, depth {depth}");
            if let Some(x) = point
                && let Some(path) = bsp_path(nodes, planes, x)
            {
                let cell = bsp_cell(&path, lo, hi, 1e-9 * poly.radius.max(1e-12));
                let cell_colour = Color32::from_rgb(90, 200, 255);
                for f in &cell.faces {
                    for k in 0..f.len() {
                        let (a, b) = (project(f[k]), project(f[(k + 1) % f.len()]));
                        painter.line_segment([a, b], Stroke::new(1.5, cell_colour));
                    }
                }
                painter.circle_filled(project(x), 3.5, cell_colour);
                tree_line += &format!(
                    "; the picked point's cell (blue): leaf {} at depth {}, {} faces",
                    path.leaf,
                    path.steps.len(),
                    cell.faces.len()
                );
            }
        }
        let d = &poly.diagnostics;
        ui.small(tree_line);
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
                Some(_) => format!(", {n_contour} contour edges from the picked point"),
                None => ", pick a point to see its contour edges".into(),
            }
        ));
    }
}
