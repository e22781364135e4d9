//! One interface over the three layouts of a BSP tree of precomputed silhouettes (001 Sect. 5):
//! a convex mesh's tree ([`SilhouetteBsp`], Sect. 5.1), a non-convex mesh's exact tree
//! ([`ExactSilhouetteBsp`], Sect. 5.2) and either one hoisted ([`HoistedSilhouetteBsp`],
//! Sect. 8). Shading looks silhouettes up through it, and the debugger draws the tree the
//! lookup went through with the same calls, so that neither needs to know which layout a mesh
//! has.

use crate::geometry::silhouettes::exact_silhouette::SilhouettePoint;
use crate::geometry::trees::bsp::{BspNode, BspPath, LOOP_END, SilhouetteBsp};
use crate::geometry::trees::bsp_hoisted::{HoistedKind, HoistedSilhouetteBsp, loop_runs};
use crate::geometry::trees::bsp_nonconvex::ExactSilhouetteBsp;
use crate::geometry::trees::bsp_sections::PlaneSection;
use crate::geometry::trees::convex_cell::ConvexCell;
use crate::geometry::{Plane, Polyhedron, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;

/// Which layout a tree has (what the debugger names, and what a recording keeps).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TreeKind {
    /// A convex mesh's tree: leaves store silhouette loops of vertices (001 Sect. 5.1).
    Convex,
    /// A non-convex mesh's tree of exact silhouettes (001 Sect. 5.2, 5.4).
    Exact,
    /// A convex tree with each edge stored as high as it stays valid (001 Sect. 8).
    HoistedConvex,
    /// An exact tree, hoisted likewise.
    HoistedExact,
}

impl TreeKind {
    /// What the tree is, in words, with the section of 001 that defines it.
    pub fn describe(self) -> &'static str {
        match self {
            TreeKind::Convex => "convex silhouettes, 001 Sect. 5.1",
            TreeKind::Exact => "exact silhouettes, 001 Sect. 5.2",
            TreeKind::HoistedConvex => "convex silhouettes, edges hoisted, 001 Sect. 8",
            TreeKind::HoistedExact => "exact silhouettes, edges hoisted, 001 Sect. 8",
        }
    }
}

/// A node as every layout can present it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TreeNode {
    /// Tests `planes[plane]` (front: `eval > 0`).
    Inner {
        plane: u32,
        back: u32,
        front: u32,
    },
    Leaf,
}

/// A BSP tree of precomputed silhouettes, whatever its layout.
pub trait SilhouetteTree: Send + Sync {
    fn kind(&self) -> TreeKind;
    fn planes(&self) -> &[Plane];
    fn node_count(&self) -> usize;
    /// Node `n` (`n < node_count()`); the root is node 0.
    fn node(&self, n: usize) -> TreeNode;
    /// The box the tree partitions; outside it the tree does not answer.
    fn bounds(&self) -> (DVec3, DVec3);
    /// Bytes of the tree's arrays in memory.
    fn stored_bytes(&self) -> usize;
    /// The silhouette of `poly` from `x` as loops in `frame`, looked up at `tree_x` (`x` in the
    /// tree's frame; an instance shares its group's tree). `false`, and `out` untouched or
    /// cleared, outside the box or in a leaf left to the on-the-fly path. `buf` is room for the
    /// hoisted layout (see `SilhouetteTree::scratch`).
    #[allow(clippy::too_many_arguments)]
    fn silhouette_at(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        tree_x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
        buf: &mut Vec<[u32; 2]>,
    ) -> bool;
    /// The points of the silhouette loops stored for `tree_x`, on `poly`; `None` where
    /// [`SilhouetteTree::silhouette_at`] answers `false`. Allocates: for the debugger.
    fn leaf_loops(&self, poly: &Polyhedron, tree_x: DVec3) -> Option<Vec<Vec<SilhouettePoint>>>;

    /// The planes tested on the way from the root to the leaf of `x` (each with the side
    /// taken), whether or not the leaf answers; `None` for an empty tree.
    fn path(&self, x: DVec3) -> Option<BspPath> {
        if self.node_count() == 0 {
            return None;
        }
        let mut path = BspPath::default();
        // Bound: children come after their parent (well-formed trees only): `node_count()` steps.
        let mut n = 0usize;
        loop {
            match self.node(n) {
                TreeNode::Inner { plane, back, front } => {
                    let p = self.planes()[plane as usize];
                    let f = p.eval(x) > 0.0;
                    path.steps.push((p, f));
                    n = if f { front as usize } else { back as usize };
                }
                TreeNode::Leaf => {
                    path.leaf = n;
                    return Some(path);
                }
            }
        }
    }

    /// (nodes, leaves, depth).
    fn size(&self) -> (usize, usize, usize) {
        let count = self.node_count();
        if count == 0 {
            return (0, 0, 0);
        }
        let (mut leaves, mut depth) = (0, 0);
        let mut stack = vec![(0usize, 0usize)];
        // Bound: a tree: each node is pushed once, by its parent.
        while let Some((n, d)) = stack.pop() {
            match self.node(n) {
                TreeNode::Inner { back, front, .. } => {
                    stack.push((back as usize, d + 1));
                    stack.push((front as usize, d + 1));
                }
                TreeNode::Leaf => {
                    leaves += 1;
                    depth = depth.max(d);
                }
            }
        }
        (count, leaves, depth)
    }

    /// The planes of every inner node above depth `levels`, each cut to its node's cell: the
    /// first `levels` levels of the partition of the tree's box (up to 2^levels − 1 planes).
    fn level_sections(&self, levels: usize, tol: f64) -> Vec<PlaneSection> {
        let mut out = Vec::new();
        if self.node_count() == 0 {
            return out;
        }
        let (lo, hi) = self.bounds();
        // Depth first with an explicit stack: (node, its cell, its depth).
        let mut stack = vec![(0usize, ConvexCell::cuboid(lo, hi), 0usize)];
        // Bound: a tree: each node is pushed once, by its parent.
        while let Some((n, cell, depth)) = stack.pop() {
            let TreeNode::Inner { plane, back, front } = self.node(n) else {
                continue;
            };
            if depth >= levels || cell.is_empty() {
                continue;
            }
            let p = self.planes()[plane as usize];
            if let Some(polygon) = cell.plane_section(&p, tol) {
                out.push(PlaneSection { depth, polygon });
            }
            let (b, f) = cell.split(&p, tol);
            stack.push((front as usize, f, depth + 1));
            stack.push((back as usize, b, depth + 1));
        }
        out
    }
}

fn leaf_node(node: BspNode) -> TreeNode {
    match node {
        BspNode::Inner { plane, back, front } => TreeNode::Inner { plane, back, front },
        BspNode::Leaf { .. } => TreeNode::Leaf,
    }
}

/// The trait for a layout whose leaves store their loops (`BspNode`s, inherent
/// `stored_bytes`, `silhouette_at` and `point_loops`).
macro_rules! leaf_stored_tree {
    ($layout:ty, $kind:expr) => {
        impl SilhouetteTree for $layout {
            fn kind(&self) -> TreeKind {
                $kind
            }
            fn planes(&self) -> &[Plane] {
                &self.planes
            }
            fn node_count(&self) -> usize {
                self.nodes.len()
            }
            fn node(&self, n: usize) -> TreeNode {
                leaf_node(self.nodes[n])
            }
            fn bounds(&self) -> (DVec3, DVec3) {
                (self.lo, self.hi)
            }
            fn stored_bytes(&self) -> usize {
                <$layout>::stored_bytes(self)
            }
            #[inline]
            fn silhouette_at(
                &self,
                poly: &Polyhedron,
                x: DVec3,
                tree_x: DVec3,
                frame: &Frame,
                out: &mut SphericalPolygon,
                _buf: &mut Vec<[u32; 2]>,
            ) -> bool {
                <$layout>::silhouette_at(self, poly, x, tree_x, frame, out)
            }
            fn leaf_loops(
                &self,
                poly: &Polyhedron,
                tree_x: DVec3,
            ) -> Option<Vec<Vec<SilhouettePoint>>> {
                self.point_loops(poly, tree_x)
            }
        }
    };
}

leaf_stored_tree!(SilhouetteBsp, TreeKind::Convex);
leaf_stored_tree!(ExactSilhouetteBsp, TreeKind::Exact);

impl SilhouetteBsp {
    /// The loops of the leaf of `tree_x`, as points (vertices).
    fn point_loops(&self, _poly: &Polyhedron, tree_x: DVec3) -> Option<Vec<Vec<SilhouettePoint>>> {
        let data = self.lookup(tree_x)?;
        Some(
            data.split(|&v| v == LOOP_END)
                .filter(|lp| !lp.is_empty())
                .map(|lp| lp.iter().map(|&v| SilhouettePoint::Vertex(v)).collect())
                .collect(),
        )
    }
}

impl ExactSilhouetteBsp {
    /// The loops of the leaf of `tree_x` (`None` outside the box or in an on-the-fly leaf).
    fn point_loops(&self, poly: &Polyhedron, tree_x: DVec3) -> Option<Vec<Vec<SilhouettePoint>>> {
        Some(
            self.leaf_ranges(tree_x)?
                .iter()
                .map(|lp| {
                    self.points[lp[0] as usize..lp[1] as usize]
                        .iter()
                        .map(|&p| self.coding.unpack(p, poly))
                        .collect()
                })
                .collect(),
        )
    }
}

impl SilhouetteTree for HoistedSilhouetteBsp {
    fn kind(&self) -> TreeKind {
        match self.kind {
            HoistedKind::Convex => TreeKind::HoistedConvex,
            HoistedKind::Exact(_) => TreeKind::HoistedExact,
        }
    }
    fn planes(&self) -> &[Plane] {
        &self.planes
    }
    fn node_count(&self) -> usize {
        self.nodes.len()
    }
    fn node(&self, n: usize) -> TreeNode {
        let node = self.nodes[n];
        // Preorder: the back child follows its parent.
        if node.plane == crate::geometry::trees::bsp_hoisted::LEAF {
            TreeNode::Leaf
        } else {
            TreeNode::Inner {
                plane: node.plane,
                back: n as u32 + 1,
                front: node.front,
            }
        }
    }
    fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }
    fn stored_bytes(&self) -> usize {
        HoistedSilhouetteBsp::stored_bytes(self)
    }
    #[inline]
    fn silhouette_at(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        tree_x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
        buf: &mut Vec<[u32; 2]>,
    ) -> bool {
        HoistedSilhouetteBsp::silhouette_at(self, poly, x, tree_x, frame, out, buf)
    }
    fn leaf_loops(&self, poly: &Polyhedron, tree_x: DVec3) -> Option<Vec<Vec<SilhouettePoint>>> {
        let mut buf = self.scratch();
        if !self.loops(tree_x, &mut buf) {
            return None;
        }
        let point = |p: u32| match self.kind {
            HoistedKind::Convex => SilhouettePoint::Vertex(p),
            HoistedKind::Exact(coding) => coding.unpack(p, poly),
        };
        Some(
            loop_runs(&buf)
                .map(|run| run.iter().map(|e| point(e[0])).collect())
                .collect(),
        )
    }
}
