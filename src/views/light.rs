//! A light's polyhedron as a figure, with what the renderer recorded at the picked point drawn
//! on it: the contour edges its silhouette stage worked from (001 Eq. 4.2), oriented so that
//! the silhouette loop is positive, with the front faces shaded; and, when the stage looked
//! the silhouette up in a BSP tree of precomputed silhouettes (001 Sect. 5), that tree
//! (`PreparedObject::silhouette_tree`, the one shading reads) and how it carves space: the
//! planes on the recorded path, each cut to the cell of its node (`geometry::path_sections`),
//! optionally every plane of the first levels (`SilhouetteTree::level_sections`), and the
//! leaf's cell (`geometry::bsp_cell`). Nothing is looked up again: a point the renderer did
//! not take through a tree shows no path.

use super::Style;
use super::labels::LabelPlacer;
use crate::figure::font::TextStyle;
use crate::figure::{Figure, Rgb, Shape, Subpath};
use crate::geometry::silhouettes::silhouette::is_front_facing;
use crate::geometry::{BspPath, PlaneSection, TreeKind, bsp_cell, path_sections};
use crate::shading::{LightRecord, PreparedObject};
use glam::DVec3;

/// The colour of the picked point's leaf cell (and of the point).
pub(crate) const CELL: Rgb = [90, 200, 255];
/// The colour of the contour edges (the light's colour in the sphere view).
pub(crate) const CONTOUR: Rgb = super::LIGHT;

/// How the light is seen and which of its tree's planes are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LightCamera {
    /// Azimuth and elevation of the eye about the world's +y, radians.
    pub yaw: f32,
    pub pitch: f32,
    /// Magnification over the fit of the light and the picked point.
    pub zoom: f32,
    /// Draw the planes on the picked point's path, each cut to its node's cell.
    pub path_planes: bool,
    /// Also draw every plane of the tree's first `levels` levels (0: none).
    pub levels: usize,
}

impl Default for LightCamera {
    fn default() -> Self {
        LightCamera {
            yaw: 0.6,
            pitch: 0.4,
            zoom: 1.0,
            path_planes: true,
            levels: 0,
        }
    }
}

/// What the figure drew (for the text under it, and for tests).
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

/// The colour of a plane at `depth` in a tree of depth `max`: red at the root through the
/// hues to violet at the deepest level (hue 0 to 0.8 of the circle, saturation 0.75).
pub(crate) fn depth_colour(depth: usize, max: usize) -> Rgb {
    let h = 0.8 * depth as f32 / max.max(1) as f32 * 6.0;
    let (s, v) = (0.75f32, 1.0f32);
    let c = v * s;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r, g, b].map(|u| ((u + m) * 255.0).round() as u8)
}

/// The light `obj` as a figure `size` pixels square; with a picked point and the recording of
/// its light (`record`, the light taken whole), the contour edges and the tree lookup recorded
/// there.
pub(crate) fn light_figure(
    obj: &PreparedObject,
    point: Option<DVec3>,
    record: Option<&LightRecord>,
    camera: &LightCamera,
    size: u32,
    style: Style,
) -> (Figure, Drawn) {
    let size = size.clamp(64, 8192);
    let side = size as f32;
    let mut fig = Figure::new(size, size, style.background());
    let poly = &obj.poly;
    let tree = obj.silhouette_tree();
    let lookup = record.and_then(|r| r.trees.iter().find(|t| t.occluder.is_none()));
    let contour = record
        .and_then(|r| r.contour_points.iter().find(|(o, _)| o.is_none()))
        .map(|(_, e)| e.as_slice())
        .unwrap_or_default();
    let mut drawn = Drawn {
        tree: lookup.map(|t| t.kind),
        ..Drawn::default()
    };
    let (yaw, pitch) = (camera.yaw as f64, camera.pitch as f64);
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
    let scale = side as f64 * 0.45 * camera.zoom as f64 / radius.max(1e-12);
    let c = (0.5 * side, 0.5 * side);
    let project = |p: DVec3| {
        let q = p - centre;
        (
            c.0 + (q.dot(right) * scale) as f32,
            c.1 - (q.dot(up) * scale) as f32,
        )
    };
    let polygon = |pts: Vec<(f32, f32)>| {
        Shape::Path(vec![Subpath {
            points: pts,
            closed: true,
        }])
    };

    // The tree, under the mesh: planes, then the leaf's cell. An instance reads a tree shared
    // in another member's frame: look the point up there and draw back in ours.
    let tol = 1e-9 * poly.radius.max(1e-12);
    let from_tree = obj.to_tree.map(|m| m.inverse());
    let world = |p: DVec3| from_tree.map_or(p, |m| m.transform_point3(p));
    let mut depth_labels = Vec::new();
    if let Some(t) = tree {
        let (lo, hi) = t.bounds();
        let (_, _, max_depth) = t.size();
        let draw_section = |fig: &mut Figure, s: &PlaneSection, fill: f32, width: f32| {
            let col = depth_colour(s.depth, max_depth);
            let pts: Vec<(f32, f32)> = s.polygon.iter().map(|&p| project(world(p))).collect();
            fig.translucent(polygon(pts.clone()), col, fill);
            fig.stroke(polygon(pts), col, width);
        };
        if camera.levels > 0 {
            let sections = t.level_sections(camera.levels, tol);
            for s in &sections {
                draw_section(&mut fig, s, 0.07, 0.8);
            }
            drawn.level_planes = sections.len();
        }
        // The recorded path, in the tree the recording names (the renderer's own).
        if let Some(l) = lookup.filter(|l| l.kind == t.kind()) {
            let path = BspPath {
                steps: l.steps.clone(),
                leaf: 0,
            };
            if camera.path_planes {
                let sections = path_sections(&path, lo, hi, tol);
                for s in &sections {
                    draw_section(&mut fig, s, 0.12, 1.3);
                    let mid = s.polygon.iter().sum::<DVec3>() / s.polygon.len() as f64;
                    depth_labels.push((project(world(mid)), s.depth, max_depth));
                }
                drawn.path_planes = sections.len();
            }
            let cell = bsp_cell(&path, lo, hi, tol);
            for f in &cell.faces {
                let pts: Vec<(f32, f32)> = f.iter().map(|&p| project(world(p))).collect();
                fig.translucent(polygon(pts.clone()), CELL, 0.11);
                fig.stroke(polygon(pts), CELL, 2.0);
            }
            drawn.leaf_depth = Some(path.steps.len());
            drawn.cell_faces = cell.faces.len();
        }
    }

    // Front faces from the picked point, filled faintly.
    if let Some(x) = point {
        for f in 0..poly.face_count() {
            if is_front_facing(poly, f, x) {
                let pts = poly
                    .face(f)
                    .iter()
                    .map(|&i| project(poly.vertices[i as usize]))
                    .collect();
                fig.translucent(polygon(pts), CONTOUR, 0.12);
            }
        }
    }
    let edges: Vec<Subpath> = poly
        .edges
        .iter()
        .map(|edge| Subpath {
            points: vec![
                project(poly.vertices[edge.v[0] as usize]),
                project(poly.vertices[edge.v[1] as usize]),
            ],
            closed: false,
        })
        .collect();
    fig.stroke(Shape::Path(edges), style.faint(), 1.0);
    if let Some(x) = point {
        let contour_colour = style.on_background(CONTOUR);
        for &[p, q] in contour {
            let (a, b) = (project(p), project(q));
            fig.stroke(Shape::segment(a, b), contour_colour, 2.5);
            // An arrowhead 60 % of the way: the orientation that makes the loop positive.
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let len = dx.hypot(dy);
            if len > 1e-6 {
                let (ux, uy) = (dx / len, dy / len);
                let m = (a.0 + 0.6 * dx, a.1 + 0.6 * dy);
                fig.fill(
                    polygon(vec![
                        (m.0 + 6.0 * ux, m.1 + 6.0 * uy),
                        (m.0 - 4.0 * ux - 4.0 * uy, m.1 - 4.0 * uy + 4.0 * ux),
                        (m.0 - 4.0 * ux + 4.0 * uy, m.1 - 4.0 * uy - 4.0 * ux),
                    ]),
                    contour_colour,
                );
            }
        }
        drawn.contour_edges = contour.len();
        let q = project(x);
        fig.fill(
            Shape::Circle {
                centre: q,
                radius: 4.0,
            },
            CELL,
        );
        fig.stroke(
            Shape::Circle {
                centre: q,
                radius: 4.0,
            },
            style.ink(),
            1.0,
        );
    }
    // Depth labels last, on top of everything, placed apart; the root's plane is depth 0.
    let size_px = (side * 0.035).clamp(11.0, 22.0);
    let mut placer = LabelPlacer::new([0.0, 0.0, side, side]);
    for (p, depth, max) in depth_labels {
        let text = depth.to_string();
        if let Some(pl) = placer.place(&text, p, size_px, 2.0) {
            let colour = style.on_background(depth_colour(depth, max));
            fig.text(&text, pl.at, TextStyle::new(size_px, colour));
        }
    }
    (fig, drawn)
}
