//! A light's polyhedron as a wireframe, with what the renderer recorded at the picked point
//! drawn on it: the contour edges its silhouette stage worked from (001 Eq. 4.2), in the
//! orientation that makes the silhouette loop positive, with the front faces shaded; and, when
//! the stage looked the silhouette up in a BSP tree of precomputed silhouettes (001 Sect. 5),
//! that tree (`PreparedObject::silhouette_tree`, the one shading reads: hoisted, convex or
//! exact) and how it carves space: the planes on the recorded path, each cut to the cell of
//! its node (`geometry::path_sections`), optionally every plane of the first levels
//! (`SilhouetteTree::level_sections`), and the leaf's cell (`geometry::bsp_cell`). Nothing here
//! looks anything up again: a point the renderer did not take through a tree shows no path.

use crate::geometry::silhouette::is_front_facing;
use crate::geometry::{BspPath, PlaneSection, TreeKind, bsp_cell, path_sections};
use crate::shading::{LightRecord, PreparedObject};
use egui::{Color32, Pos2, Sense, Shape, Stroke, Ui, Vec2};
use glam::DVec3;

/// The colour of the picked point's leaf cell.
const CELL: Color32 = Color32::from_rgb(90, 200, 255);
/// The colour of the contour edges (the light's silhouette colour in the sphere view).
const CONTOUR: Color32 = Color32::from_rgb(240, 200, 40);

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

/// What the structure view drew in its last frame (for the text under it, and for tests).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawn {
    /// Plane sections of the picked point's path, and of the first levels.
    pub path_planes: usize,
    pub level_planes: usize,
    /// Depth of the picked point's leaf, and the faces of its cell.
    pub leaf_depth: Option<usize>,
    pub cell_faces: usize,
    /// The tree the recording says the renderer looked the light's silhouette up in.
    pub tree: Option<TreeKind>,
    /// Contour edges drawn, from the recording.
    pub contour_edges: usize,
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

/// The colour of a plane at `depth` in a tree of depth `max`: red at the root through the
/// hues to violet at the deepest level.
pub fn depth_colour(depth: usize, max: usize) -> Color32 {
    let t = depth as f32 / max.max(1) as f32;
    egui::ecolor::Hsva::new(0.8 * t, 0.75, 1.0, 1.0).into()
}

impl LightView {
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
        let contour = record
            .and_then(|r| r.contour_points.iter().find(|(o, _)| o.is_none()))
            .map(|(_, e)| e.as_slice())
            .unwrap_or_default();
        self.drawn = Drawn {
            tree: lookup.map(|t| t.kind),
            ..Drawn::default()
        };
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
        // Fit the light and the picked point: the point's cell and planes are what it is about.
        let (centre, radius) = match point {
            Some(x) => {
                let lo = (poly.center - poly.radius).min(x);
                let hi = (poly.center + poly.radius).max(x);
                ((lo + hi) / 2.0, ((hi - lo) / 2.0).length())
            }
            None => (poly.center, poly.radius),
        };
        let scale = side as f64 * 0.45 * self.zoom as f64 / radius.max(1e-12);
        let c = rect.center();
        let project = |p: DVec3| {
            let q = p - centre;
            Pos2::new(
                c.x + (q.dot(right) * scale) as f32,
                c.y - (q.dot(up) * scale) as f32,
            )
        };

        // The tree, under the mesh: planes, then the leaf's cell. An instance reads a tree
        // shared in another member's frame: look the point up there and draw back in ours.
        let tol = 1e-9 * poly.radius.max(1e-12);
        let from_tree = obj.to_tree.map(|m| m.inverse());
        let world = |p: DVec3| from_tree.map_or(p, |m| m.transform_point3(p));
        let mut depth_labels = Vec::new();
        if let Some(t) = tree {
            let (lo, hi) = t.bounds();
            let (_, _, max_depth) = t.size();
            let draw_section = |s: &PlaneSection, fill: u8, width: f32| {
                let col = depth_colour(s.depth, max_depth);
                let pts: Vec<Pos2> = s.polygon.iter().map(|&p| project(world(p))).collect();
                painter.add(Shape::convex_polygon(
                    pts.clone(),
                    col.gamma_multiply_u8(fill),
                    Stroke::NONE,
                ));
                painter.add(Shape::closed_line(pts, Stroke::new(width, col)));
            };
            if self.levels > 0 {
                let sections = t.level_sections(self.levels, tol);
                for s in &sections {
                    draw_section(s, 18, 0.8);
                }
                self.drawn.level_planes = sections.len();
            }
            // The recorded path, in the tree the recording names (the renderer's own).
            if let Some(l) = lookup.filter(|l| l.kind == t.kind()) {
                let path = BspPath {
                    steps: l.steps.clone(),
                    leaf: 0,
                };
                if self.path_planes {
                    let sections = path_sections(&path, lo, hi, tol);
                    for s in &sections {
                        draw_section(s, 30, 1.3);
                        let mid = s.polygon.iter().sum::<DVec3>() / s.polygon.len() as f64;
                        depth_labels.push((project(world(mid)), s.depth, max_depth));
                    }
                    self.drawn.path_planes = sections.len();
                }
                let cell = bsp_cell(&path, lo, hi, tol);
                for f in &cell.faces {
                    let pts: Vec<Pos2> = f.iter().map(|&p| project(world(p))).collect();
                    painter.add(Shape::convex_polygon(
                        pts.clone(),
                        CELL.gamma_multiply_u8(28),
                        Stroke::NONE,
                    ));
                    painter.add(Shape::closed_line(pts, Stroke::new(2.0, CELL)));
                }
                self.drawn.leaf_depth = Some(path.steps.len());
                self.drawn.cell_faces = cell.faces.len();
            }
        }

        // Front faces from the picked point, filled faintly.
        if let Some(x) = point {
            for f in 0..poly.face_count() {
                if is_front_facing(poly, f, x) {
                    let pts: Vec<Pos2> = poly
                        .face(f)
                        .iter()
                        .map(|&i| project(poly.vertices[i as usize]))
                        .collect();
                    painter.add(Shape::convex_polygon(
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
        if let Some(x) = point {
            for &[p, q] in contour {
                let a = project(p);
                let b = project(q);
                painter.line_segment([a, b], Stroke::new(2.5, CONTOUR));
                let d = (b - a).normalized();
                if d.is_finite() {
                    let n = Vec2::new(-d.y, d.x);
                    let m = a + (b - a) * 0.6;
                    painter.add(Shape::convex_polygon(
                        vec![m + d * 6.0, m - d * 4.0 + n * 4.0, m - d * 4.0 - n * 4.0],
                        CONTOUR,
                        Stroke::NONE,
                    ));
                }
            }
            self.drawn.contour_edges = contour.len();
            painter.circle_filled(project(x), 4.0, CELL);
            painter.circle_stroke(project(x), 4.0, Stroke::new(1.0, Color32::BLACK));
        }
        // Depth labels last, on top of everything; the root's plane is depth 0.
        for (p, depth, max) in depth_labels {
            painter.text(
                p,
                egui::Align2::CENTER_CENTER,
                depth.to_string(),
                egui::FontId::monospace(11.0),
                depth_colour(depth, max),
            );
        }

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
        if let Some(s) = &obj.stand_in {
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
