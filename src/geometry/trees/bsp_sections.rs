//! The partition planes of a BSP tree as the polygons a viewer can draw: each plane cut to the
//! cell of its node (the tree's box cut by the ancestors' planes), which is the part of the
//! plane that actually splits space. An infinite plane drawn whole would say nothing about
//! where the cut happens.

use crate::geometry::Plane;
use crate::geometry::trees::bsp::BspPath;
use crate::geometry::trees::convex_cell::ConvexCell;
use glam::DVec3;

/// The part of a node's plane inside the node's cell.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneSection {
    /// Depth of the node (the root is 0).
    pub depth: usize,
    /// The section polygon, counter-clockwise around the plane's normal.
    pub polygon: Vec<DVec3>,
}

/// The planes tested on `path`, each cut to the cell of its node: how the leaf's cell was
/// carved out of the box `[lo, hi]`, from the root down. A plane that does not cut its node's
/// cell (possible only through rounding) is left out.
pub fn path_sections(path: &BspPath, lo: DVec3, hi: DVec3, tol: f64) -> Vec<PlaneSection> {
    let mut cell = ConvexCell::cuboid(lo, hi);
    let mut out = Vec::with_capacity(path.steps.len());
    for (depth, &(plane, front)) in path.steps.iter().enumerate() {
        if let Some(polygon) = cell.plane_section(&plane, tol) {
            out.push(PlaneSection { depth, polygon });
        }
        cell = cell.clip_to_back(&kept_side(plane, front), tol);
    }
    out
}

/// The plane whose back side is the side `front` names of `plane`.
fn kept_side(plane: Plane, front: bool) -> Plane {
    if front {
        Plane {
            n: -plane.n,
            d: -plane.d,
        }
    } else {
        plane
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SilhouetteBsp;
    use crate::geometry::bsp_cell;
    use crate::geometry::trees::bsp::BspNode;
    use crate::geometry::trees::silhouette_tree::SilhouetteTree;

    /// A hand-made tree over the box [0, 4]³: the root splits at x = 2, its front child at
    /// y = 1, and that node's back child at z = 3.
    fn tree() -> SilhouetteBsp {
        let planes = vec![
            Plane {
                n: DVec3::X,
                d: 2.0,
            },
            Plane {
                n: DVec3::Y,
                d: 1.0,
            },
            Plane {
                n: DVec3::Z,
                d: 3.0,
            },
        ];
        let leaf = BspNode::Leaf { first: 0, count: 0 };
        let nodes = vec![
            BspNode::Inner {
                plane: 0,
                back: 1,
                front: 2,
            },
            leaf,
            BspNode::Inner {
                plane: 1,
                back: 3,
                front: 6,
            },
            BspNode::Inner {
                plane: 2,
                back: 4,
                front: 5,
            },
            leaf,
            leaf,
            leaf,
        ];
        SilhouetteBsp {
            planes,
            nodes,
            data: Vec::new(),
            lo: DVec3::ZERO,
            hi: DVec3::splat(4.0),
        }
    }

    fn area(poly: &[DVec3]) -> f64 {
        (0..poly.len())
            .map(|k| poly[k].cross(poly[(k + 1) % poly.len()]))
            .sum::<DVec3>()
            .length()
            / 2.0
    }

    #[test]
    fn each_plane_is_cut_to_its_nodes_cell() {
        let t = tree();
        let (lo, hi) = (t.lo, t.hi);
        let x = DVec3::new(3.0, 0.5, 3.5);
        let path = t.path(x).unwrap();
        assert_eq!(path.leaf, 5);
        let s = path_sections(&path, lo, hi, 1e-12);
        assert_eq!(s.iter().map(|s| s.depth).collect::<Vec<_>>(), [0, 1, 2]);
        // x = 2 across the whole box; y = 1 across the half x ≥ 2; z = 3 across the quarter
        // x ≥ 2, y ≤ 1.
        let areas: Vec<f64> = s.iter().map(|s| area(&s.polygon)).collect();
        for (a, want) in areas.iter().zip([16.0, 8.0, 2.0]) {
            assert!((a - want).abs() < 1e-12, "{areas:?}");
        }
        for sec in &s {
            let p = path.steps[sec.depth].0;
            assert!(sec.polygon.iter().all(|&q| p.eval(q).abs() < 1e-12));
        }
        // The deepest section is the face z = 3 of the leaf's cell x ≥ 2, y ≤ 1, z ≥ 3.
        let cell = bsp_cell(&path, lo, hi, 1e-12);
        assert!((cell.volume() - 2.0).abs() < 1e-12);
        assert!(
            cell.faces.iter().any(|f| (area(f) - areas[2]).abs() < 1e-12
                && f.iter().all(|q| (q.z - 3.0).abs() < 1e-12))
        );
    }

    #[test]
    fn levels_take_every_node_above_the_depth() {
        let t = tree();
        assert_eq!(t.size(), (7, 4, 3));
        let depths = |k| {
            let mut d: Vec<usize> = t.level_sections(k, 1e-12).iter().map(|s| s.depth).collect();
            d.sort();
            d
        };
        assert!(depths(0).is_empty());
        assert_eq!(depths(1), [0]);
        assert_eq!(depths(2), [0, 1]);
        assert_eq!(depths(9), [0, 1, 2]);
    }
}
