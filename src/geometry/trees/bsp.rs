//! Precomputed silhouettes in a BSP tree (001 Sect. 5): space around a mesh is cut by a set of
//! planes into convex cells in each of which the silhouette has the same structure; each leaf
//! stores that structure, and shading only walks the tree and reads it.
//!
//! Convex meshes (Sect. 5.1): the planes are the face planes, because the contour changes only
//! where a face turns from front to back; a leaf stores the silhouette as an ordered loop of
//! vertex indices, already oriented (no flips, each vertex transformed once).
//!
//! The build (Sect. 5.3) runs twice. The first pass splits the cell of each node (a
//! [`ConvexCell`] inside a bounding box) by a plane that cuts it, down to cells no plane cuts,
//! and takes a representative point in each (its centroid). The final cells do not depend on
//! the order of the planes, so the second pass builds the tree actually used over those points
//! alone, each node taking the plane that splits its points most evenly: a balanced tree over
//! the same cells. Every point of a cell has the sign vector of its representative, so it
//! reaches that representative's leaf.

use crate::geometry::mesh::polyhedron::NO_FACE;
use crate::geometry::silhouettes::silhouette::is_front_facing;
use crate::geometry::trees::convex_cell::{CellSide, ConvexCell};
use crate::geometry::{Plane, Polyhedron, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;

/// A node of the tree: an inner node tests `planes[plane]` (front: `eval > 0`), a leaf holds
/// `loops[first..first + count]` of the leaf data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum BspNode {
    Inner { plane: u32, back: u32, front: u32 },
    Leaf { first: u32, count: u32 },
}

/// Where a point falls in a tree: the planes tested on the way (each with the side taken,
/// `true` for the front) and the leaf reached.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BspPath {
    pub steps: Vec<(Plane, bool)>,
    pub leaf: usize,
}

/// The leaf `x` falls in: the index of the node reached from the root (front: `eval > 0`).
#[inline]
pub fn bsp_leaf(nodes: &[BspNode], planes: &[Plane], x: DVec3) -> usize {
    // Bound: children come after their parent (`nodes_well_formed`, checked for every tree,
    // loaded ones included), so the descent ends within `nodes.len()` steps.
    let mut n = 0usize;
    loop {
        match nodes[n] {
            BspNode::Inner { plane, back, front } => {
                n = if planes[plane as usize].eval(x) > 0.0 {
                    front as usize
                } else {
                    back as usize
                };
            }
            BspNode::Leaf { .. } => return n,
        }
    }
}

/// The cell of a path: the box `[lo, hi]` cut to the side taken at every step.
pub fn bsp_cell(path: &BspPath, lo: DVec3, hi: DVec3, tol: f64) -> ConvexCell {
    let mut cell = ConvexCell::cuboid(lo, hi);
    for &(p, front) in &path.steps {
        let keep = if front { Plane { n: -p.n, d: -p.d } } else { p };
        cell = cell.clip_to_back(&keep, tol);
    }
    cell
}

/// Every child, plane and leaf range of `nodes` in range (`leaf_ok` checks a leaf's range).
pub(crate) fn nodes_well_formed(
    nodes: &[BspNode],
    planes: usize,
    leaf_ok: impl Fn(u32, u32) -> bool,
) -> bool {
    !nodes.is_empty()
        && nodes.iter().enumerate().all(|(i, n)| match *n {
            // Children after their parent: no cycles, every walk ends in a leaf.
            BspNode::Inner { plane, back, front } => {
                (plane as usize) < planes
                    && (back as usize) > i
                    && (front as usize) > i
                    && (back as usize) < nodes.len()
                    && (front as usize) < nodes.len()
            }
            BspNode::Leaf { first, count } => leaf_ok(first, count),
        })
}

/// 001 Sect. 8's open question, measured: if each silhouette edge were stored at the highest
/// node below which every leaf has it (valid for that node's whole cell), how many edges would
/// the tree hold? `leaf_edges(first, count)` lists a leaf's edges (any encoding, sorted or
/// not). Returns (edges stored in the leaves, edges stored as high as they stay valid).
pub(crate) fn hoisted_edge_counts(
    nodes: &[BspNode],
    leaf_edges: &dyn Fn(u32, u32) -> Vec<(u64, u64)>,
) -> (usize, usize) {
    // The edges common to the subtree of `n`, and the edges stored within it below `n`.
    fn walk(
        nodes: &[BspNode],
        n: usize,
        leaf_edges: &dyn Fn(u32, u32) -> Vec<(u64, u64)>,
        in_leaves: &mut usize,
        below: &mut usize,
    ) -> Vec<(u64, u64)> {
        match nodes[n] {
            BspNode::Leaf { first, count } => {
                let mut e = leaf_edges(first, count);
                e.sort_unstable();
                e.dedup();
                *in_leaves += e.len();
                e
            }
            BspNode::Inner { back, front, .. } => {
                let a = walk(nodes, back as usize, leaf_edges, in_leaves, below);
                let b = walk(nodes, front as usize, leaf_edges, in_leaves, below);
                let common: Vec<(u64, u64)> = a
                    .iter()
                    .filter(|e| b.binary_search(e).is_ok())
                    .copied()
                    .collect();
                // What each child keeps that the parent does not is stored at the child.
                *below += a.len() + b.len() - 2 * common.len();
                common
            }
        }
    }
    if nodes.is_empty() {
        return (0, 0);
    }
    let (mut in_leaves, mut below) = (0, 0);
    let root = walk(nodes, 0, leaf_edges, &mut in_leaves, &mut below);
    (in_leaves, below + root.len())
}

/// The BSP tree of precomputed silhouettes of one convex mesh, in the mesh's coordinates.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SilhouetteBsp {
    pub planes: Vec<Plane>,
    pub nodes: Vec<BspNode>,
    /// Leaf data: silhouette loops as vertex indices, each loop ended by `LOOP_END`.
    pub data: Vec<u32>,
    /// The box the tree partitions; outside it the tree does not answer.
    pub lo: DVec3,
    pub hi: DVec3,
}

/// Ends a loop in [`SilhouetteBsp::data`].
pub const LOOP_END: u32 = u32::MAX;

/// What a build produced (001 Table 7.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BspStats {
    pub seconds: f64,
    pub nodes: usize,
    pub leaves: usize,
    pub depth: usize,
    /// Silhouette vertices over all leaves.
    pub silhouette_vertices: usize,
    /// Size of the two buffers at 20 bytes per node and 4 per vertex, as in Table 7.4.
    pub table_7_4_bytes: usize,
}

impl SilhouetteBsp {
    /// Builds the tree of a convex mesh over the box `[lo, hi]` (which should hold every point
    /// that will be shaded). Returns `None` for a mesh that is not convex.
    pub fn build_convex(poly: &Polyhedron, lo: DVec3, hi: DVec3) -> Option<(Self, BspStats)> {
        Self::build_convex_limited(poly, lo, hi, usize::MAX)
    }

    /// [`SilhouetteBsp::build_convex`] that gives up (`None`) once the face planes cut the box
    /// into more than `max_cells` cells (their number grows with the cube of the face count).
    pub fn build_convex_limited(
        poly: &Polyhedron,
        lo: DVec3,
        hi: DVec3,
        max_cells: usize,
    ) -> Option<(Self, BspStats)> {
        if !poly.diagnostics.convex {
            return None;
        }
        let start = web_time::Instant::now();
        // Pass 1: the cells and a point in each.
        let mut points = Vec::new();
        let planes = face_plane_cells(poly, lo, hi, max_cells, &mut points)?;
        // Pass 2: a balanced tree over the points.
        let mut tree = SilhouetteBsp {
            planes,
            nodes: Vec::new(),
            data: Vec::new(),
            lo,
            hi,
        };
        let mut depth = 0;
        let mut idx: Vec<u32> = (0..points.len() as u32).collect();
        tree.build_balanced(poly, &points, &mut idx, 0, &mut depth);
        let leaves = tree
            .nodes
            .iter()
            .filter(|n| matches!(n, BspNode::Leaf { .. }))
            .count();
        let silhouette_vertices = tree.data.iter().filter(|&&v| v != LOOP_END).count();
        let stats = BspStats {
            seconds: start.elapsed().as_secs_f64(),
            nodes: tree.nodes.len(),
            leaves,
            depth,
            silhouette_vertices,
            table_7_4_bytes: 20 * tree.nodes.len() + 4 * silhouette_vertices,
        };
        Some((tree, stats))
    }

    /// Builds the subtree over `idx` (indices into `points`) and returns its node index.
    fn build_balanced(
        &mut self,
        poly: &Polyhedron,
        points: &[DVec3],
        idx: &mut [u32],
        depth: usize,
        max_depth: &mut usize,
    ) -> u32 {
        *max_depth = (*max_depth).max(depth);
        let me = self.nodes.len() as u32;
        self.nodes.push(BspNode::Leaf { first: 0, count: 0 });
        // The plane with the most even split of the points (ties: the lowest index).
        let mut best: Option<(usize, u32)> = None;
        if idx.len() > 1 {
            for (k, pl) in self.planes.iter().enumerate() {
                let front = idx
                    .iter()
                    .filter(|&&i| pl.eval(points[i as usize]) > 0.0)
                    .count();
                if front == 0 || front == idx.len() {
                    continue;
                }
                let imbalance = front.abs_diff(idx.len() - front);
                if best.is_none_or(|(b, _)| imbalance < b) {
                    best = Some((imbalance, k as u32));
                }
            }
        }
        match best {
            None => {
                // One cell (several points only if they lie in one cell: the same structure).
                let first = self.data.len() as u32;
                contour_loops(poly, points[idx[0] as usize], &mut self.data);
                let count = self.data.len() as u32 - first;
                self.nodes[me as usize] = BspNode::Leaf { first, count };
            }
            Some((_, k)) => {
                let pl = self.planes[k as usize];
                // Partition in place: back points first.
                let mut split = 0;
                for j in 0..idx.len() {
                    if pl.eval(points[idx[j] as usize]) <= 0.0 {
                        idx.swap(j, split);
                        split += 1;
                    }
                }
                let (back_idx, front_idx) = idx.split_at_mut(split);
                let back = self.build_balanced(poly, points, back_idx, depth + 1, max_depth);
                let front = self.build_balanced(poly, points, front_idx, depth + 1, max_depth);
                self.nodes[me as usize] = BspNode::Inner {
                    plane: k,
                    back,
                    front,
                };
            }
        }
        me
    }

    /// [`hoisted_edge_counts`] of this tree (edges: consecutive vertices of the leaf loops).
    pub fn hoisted_edge_counts(&self) -> (usize, usize) {
        let edges = |first: u32, count: u32| {
            let d = &self.data[first as usize..(first + count) as usize];
            let mut out = Vec::new();
            for lp in d.split(|&v| v == LOOP_END) {
                for k in 0..lp.len() {
                    out.push((lp[k] as u64, lp[(k + 1) % lp.len()] as u64));
                }
            }
            out
        };
        hoisted_edge_counts(&self.nodes, &edges)
    }

    /// Bytes of the tree's arrays in memory (planes, nodes, leaf data).
    pub fn stored_bytes(&self) -> usize {
        std::mem::size_of_val(&self.planes[..])
            + std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.data[..])
    }

    /// Whether every index in the tree is in range for a mesh of `vertices` vertices (a tree
    /// read from a file is checked before use).
    pub fn is_well_formed(&self, vertices: usize) -> bool {
        let data = self.data.len();
        nodes_well_formed(&self.nodes, self.planes.len(), |first, count| {
            (first as usize)
                .checked_add(count as usize)
                .is_some_and(|e| e <= data)
        }) && self
            .data
            .iter()
            .all(|&v| v == LOOP_END || (v as usize) < vertices)
    }

    /// The leaf data (loops of vertex indices, each ended by `LOOP_END`) of the cell of `x`, or
    /// `None` outside the box.
    #[inline]
    pub fn lookup(&self, x: DVec3) -> Option<&[u32]> {
        if x.cmplt(self.lo).any() || x.cmpgt(self.hi).any() || self.nodes.is_empty() {
            return None;
        }
        match self.nodes[bsp_leaf(&self.nodes, &self.planes, x)] {
            BspNode::Leaf { first, count } => {
                Some(&self.data[first as usize..(first + count) as usize])
            }
            BspNode::Inner { .. } => None,
        }
    }

    /// The silhouette of `poly` (the mesh the tree was built for) from `x` as a spherical
    /// polygon in `frame`, read from the tree: the same loops as
    /// [`crate::geometry::silhouettes::silhouette`](fn@crate::geometry::silhouettes::silhouette) computes. `false` (and `out` untouched)
    /// outside the box.
    pub fn silhouette(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
    ) -> bool {
        self.silhouette_at(poly, x, x, frame, out)
    }

    /// [`SilhouetteBsp::silhouette`] for an instance of the tree's mesh: the cell is looked up
    /// at `tree_x` (the shading point `x` in the tree's frame), the loops read off `poly`, the
    /// instance's own vertices, from `x` (`shading::prepared`, 001 Sect. 5.4).
    #[inline]
    pub fn silhouette_at(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        tree_x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
    ) -> bool {
        let Some(data) = self.lookup(tree_x) else {
            return false;
        };
        out.clear();
        crate::geometry::silhouettes::silhouette::emit_loops(poly, x, frame, data, out);
        true
    }
}

/// The face planes without repeats (split faces share a plane).
fn distinct_planes(planes: &[Plane], tol: f64) -> Vec<Plane> {
    let mut out: Vec<Plane> = Vec::with_capacity(planes.len());
    for p in planes {
        if !out
            .iter()
            .any(|q| q.n.dot(p.n) > 1.0 - 1e-12 && (q.d - p.d).abs() <= tol)
        {
            out.push(*p);
        }
    }
    out
}

/// Whether the planes of `poly`'s faces cut the box `[lo, hi]` into more than `max_cells`
/// cells: pass 1 of the convex build alone, a quick trial for the tree of a non-convex mesh,
/// whose face-plane cells its leaves refine (so it has at least as many leaves as there are
/// cells). Costs a few microseconds per cell, against about a hundred per leaf of that tree.
pub(crate) fn face_planes_exceed(
    poly: &Polyhedron,
    lo: DVec3,
    hi: DVec3,
    max_cells: usize,
) -> bool {
    face_plane_cells(poly, lo, hi, max_cells, &mut Vec::new()).is_none()
}

/// The distinct face planes of `poly`, with a point of every cell they cut the box
/// `[lo, hi]` into pushed onto `points` (pass 1); `None` once there are more than `max_cells`.
fn face_plane_cells(
    poly: &Polyhedron,
    lo: DVec3,
    hi: DVec3,
    max_cells: usize,
    points: &mut Vec<DVec3>,
) -> Option<Vec<Plane>> {
    let tol = 1e-9 * poly.radius.max(f64::MIN_POSITIVE);
    let planes = distinct_planes(&poly.face_planes, tol);
    let all: Vec<u32> = (0..planes.len() as u32).collect();
    enumerate_cells(
        ConvexCell::cuboid(lo, hi),
        &planes,
        &all,
        tol,
        max_cells,
        points,
    )
    .then_some(planes)
}

/// Pass 1: splits `cell` by the first of `candidates` that cuts it, recursively, and pushes
/// the centroid of every final cell; `false` once there are more than `max_cells`.
fn enumerate_cells(
    cell: ConvexCell,
    planes: &[Plane],
    candidates: &[u32],
    tol: f64,
    max_cells: usize,
    points: &mut Vec<DVec3>,
) -> bool {
    // Planes that miss this cell miss all its sub-cells: drop them for the subtree.
    let cutting: Vec<u32> = candidates
        .iter()
        .copied()
        .filter(|&k| cell.side(&planes[k as usize], tol) == CellSide::Straddles)
        .collect();
    let Some((&k, rest)) = cutting.split_first() else {
        points.push(cell.centroid());
        return points.len() <= max_cells;
    };
    let (back, front) = cell.split(&planes[k as usize], tol);
    for part in [back, front] {
        if !part.is_empty() && !enumerate_cells(part, planes, rest, tol, max_cells, points) {
            return false;
        }
    }
    true
}

/// The silhouette loops of a convex mesh from `x` as vertex indices (the contour edges of 001
/// Eq. 4.2 chained through shared vertices, oriented as `contour_edges`), each loop followed
/// by `LOOP_END`.
fn contour_loops(poly: &Polyhedron, x: DVec3, out: &mut Vec<u32>) {
    let mut next = vec![NO_FACE; poly.vertices.len()];
    let mut starts = Vec::new();
    for e in &poly.edges {
        let f0 = is_front_facing(poly, e.faces[0] as usize, x);
        let f1 = e.faces[1] != NO_FACE && is_front_facing(poly, e.faces[1] as usize, x);
        let (a, b) = match (f0, f1) {
            (true, false) => (e.v[1], e.v[0]),
            (false, true) => (e.v[0], e.v[1]),
            _ => continue,
        };
        next[a as usize] = b;
        starts.push(a);
    }
    let mut used = vec![false; poly.vertices.len()];
    for s in starts {
        if used[s as usize] {
            continue;
        }
        let mut v = s;
        // Bound: every step marks a vertex used: at most one step per vertex over all starts.
        while !used[v as usize] && next[v as usize] != NO_FACE {
            used[v as usize] = true;
            out.push(v);
            v = next[v as usize];
        }
        out.push(LOOP_END);
    }
}
