//! Silhouette edges stored as high in the tree as they stay valid (001 Sect. 8, "storing each
//! edge of the silhouette as far up in the tree structure as possible").
//!
//! A leaf-stored tree ([`SilhouetteBsp`], [`ExactSilhouetteBsp`]) keeps each leaf's whole
//! silhouette. Here every node keeps the directed silhouette edges that all leaves below it
//! have and its parent does not, so an edge common to a subtree is stored once at its root.
//! The edges on the path from the root to a leaf are then exactly that leaf's edges (the sets
//! of a path telescope: root ⊆ child ⊆ … ⊆ leaf), and a lookup gathers them and chains them
//! through their shared points into the same loops, with the same orientation (edges keep
//! their direction); a loop may start at another point.
//!
//! Chaining needs every point to start at most one edge of a leaf's silhouette and end at most
//! one; a tree where some leaf breaks that is refused. Leaves left to the on-the-fly path
//! (and those inside the solid) are never read, so they do not hold edges back from their
//! ancestors: for hoisting they count as having every edge.
//!
//! Lookups allocate nothing: the caller passes a buffer, reserved once with
//! [`HoistedSilhouetteBsp::scratch`] for the longest path's edges.

use crate::geometry::silhouettes::exact_silhouette::PointCoding;
use crate::geometry::trees::bsp::{BspNode, LOOP_END, SilhouetteBsp};
use crate::geometry::trees::bsp_nonconvex::{ExactSilhouetteBsp, ON_THE_FLY};
use crate::geometry::{Plane, Polyhedron, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;

/// Marks a leaf in [`HoistedNode::plane`].
pub(super) const LEAF: u32 = u32::MAX;

/// A node in preorder: an inner node's back child is the next node, its front child `front`;
/// a leaf has `plane == LEAF` and `front` 1 if it is left to the on-the-fly path. Either kind
/// holds `edges[first..first + count]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HoistedNode {
    pub plane: u32,
    pub front: u32,
    pub first: u32,
    pub count: u32,
}

/// What the points of the edges are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoistedKind {
    /// Vertex indices (a convex mesh's tree).
    Convex,
    /// Points of an exact silhouette, in the tree's 32-bit coding ([`PointCoding`]).
    Exact(PointCoding),
}

/// A tree of precomputed silhouettes with each edge stored as high as it stays valid.
#[derive(Clone, Debug)]
pub struct HoistedSilhouetteBsp {
    pub kind: HoistedKind,
    pub planes: Vec<Plane>,
    pub nodes: Vec<HoistedNode>,
    /// Directed edges (from, to).
    pub edges: Vec<[u32; 2]>,
    pub lo: DVec3,
    pub hi: DVec3,
    /// The most edges on one root-to-leaf path: the buffer a lookup needs.
    pub max_path_edges: usize,
}

/// The directed edges of loops of points, closing each loop.
fn loop_edges<'a>(loops: impl Iterator<Item = &'a [u32]>) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for lp in loops {
        for k in 0..lp.len() {
            out.push([lp[k], lp[(k + 1) % lp.len()]]);
        }
    }
    out
}

impl HoistedSilhouetteBsp {
    /// The hoisted form of a convex mesh's tree.
    pub fn from_convex(t: &SilhouetteBsp) -> crate::Result<Self> {
        let leaf = |first: u32, count: u32| {
            let d = &t.data[first as usize..(first + count) as usize];
            Some(loop_edges(
                d.split(|&v| v == LOOP_END).filter(|l| !l.is_empty()),
            ))
        };
        Self::build(HoistedKind::Convex, &t.nodes, &t.planes, t.lo, t.hi, &leaf)
    }

    /// The hoisted form of a non-convex mesh's tree of exact silhouettes.
    pub fn from_exact(t: &ExactSilhouetteBsp) -> crate::Result<Self> {
        let leaf = |first: u32, count: u32| {
            (count != ON_THE_FLY).then(|| {
                loop_edges(
                    t.loops[first as usize..(first + count) as usize]
                        .iter()
                        .map(|lp| &t.points[lp[0] as usize..lp[1] as usize]),
                )
            })
        };
        Self::build(
            HoistedKind::Exact(t.coding),
            &t.nodes,
            &t.planes,
            t.lo,
            t.hi,
            &leaf,
        )
    }

    /// `leaf_edges(first, count)`: a leaf's directed edges, `None` for a leaf never read.
    fn build(
        kind: HoistedKind,
        nodes: &[BspNode],
        planes: &[Plane],
        lo: DVec3,
        hi: DVec3,
        leaf_edges: &dyn Fn(u32, u32) -> Option<Vec<[u32; 2]>>,
    ) -> crate::Result<Self> {
        if nodes.is_empty() {
            return Err("the tree has no nodes".into());
        }
        // Pass 1, bottom-up: the edges common to every read leaf below each node (sorted;
        // `None`: no leaf below is read).
        let mut common: Vec<Option<Vec<[u32; 2]>>> = vec![None; nodes.len()];
        let mut max_path_edges = 0;
        // Children come after their parent (`nodes_well_formed`), so a reverse sweep sees
        // both children first.
        for n in (0..nodes.len()).rev() {
            common[n] = match nodes[n] {
                BspNode::Leaf { first, count } => match leaf_edges(first, count) {
                    None => None,
                    Some(mut e) => {
                        let mut starts: Vec<u32> = e.iter().map(|e| e[0]).collect();
                        let mut ends: Vec<u32> = e.iter().map(|e| e[1]).collect();
                        starts.sort_unstable();
                        ends.sort_unstable();
                        if starts.windows(2).any(|w| w[0] == w[1])
                            || ends.windows(2).any(|w| w[0] == w[1])
                        {
                            return Err(crate::Error::from(format!(
                                "leaf {n}: a point starts or ends two silhouette edges, so the \
                                 edges cannot be chained back into loops"
                            )));
                        }
                        e.sort_unstable();
                        max_path_edges = max_path_edges.max(e.len());
                        Some(e)
                    }
                },
                BspNode::Inner { back, front, .. } => {
                    match (&common[back as usize], &common[front as usize]) {
                        (None, None) => None,
                        (Some(a), None) | (None, Some(a)) => Some(a.clone()),
                        (Some(a), Some(b)) => Some(
                            a.iter()
                                .filter(|e| b.binary_search(e).is_ok())
                                .copied()
                                .collect(),
                        ),
                    }
                }
            };
        }
        // Pass 2, top-down in preorder: each node stores its common edges minus its parent's.
        let mut out = HoistedSilhouetteBsp {
            kind,
            planes: planes.to_vec(),
            nodes: Vec::with_capacity(nodes.len()),
            edges: Vec::new(),
            lo,
            hi,
            max_path_edges,
        };
        let mut stack: Vec<(usize, Option<usize>, Option<usize>)> = vec![(0, None, None)];
        // (source node, source parent, index of the hoisted parent whose `front` to set)
        // Bound: each source node is pushed once, by its parent (a tree): `nodes.len()` pops.
        while let Some((n, parent, set_front)) = stack.pop() {
            let me = out.nodes.len() as u32;
            if let Some(p) = set_front {
                out.nodes[p].front = me;
            }
            let first = out.edges.len() as u32;
            if let Some(mine) = &common[n] {
                let above = parent.and_then(|p| common[p].as_ref());
                out.edges.extend(
                    mine.iter()
                        .filter(|e| above.is_none_or(|a| a.binary_search(e).is_err()))
                        .copied(),
                );
            }
            let count = out.edges.len() as u32 - first;
            match nodes[n] {
                BspNode::Leaf { .. } => out.nodes.push(HoistedNode {
                    plane: LEAF,
                    front: common[n].is_none() as u32,
                    first,
                    count,
                }),
                BspNode::Inner { plane, back, front } => {
                    out.nodes.push(HoistedNode {
                        plane,
                        front: 0,
                        first,
                        count,
                    });
                    // Back is popped first: it is the next node in preorder.
                    stack.push((front as usize, Some(n), Some(me as usize)));
                    stack.push((back as usize, Some(n), None));
                }
            }
        }
        Ok(out)
    }

    /// A buffer with room for every lookup of this tree.
    pub fn scratch(&self) -> Vec<[u32; 2]> {
        Vec::with_capacity(self.max_path_edges)
    }

    /// Bytes of the tree's arrays in memory (planes, nodes, edges).
    pub fn stored_bytes(&self) -> usize {
        std::mem::size_of_val(&self.planes[..])
            + std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.edges[..])
    }

    /// The silhouette edges of the cell of `x` chained into loops in `buf`: each loop is a run
    /// of edges, each starting where the previous ends, the last ending at the run's first
    /// start ([`loop_runs`] splits them). `false` outside the box or in a leaf left to the
    /// on-the-fly path.
    #[inline]
    pub fn loops(&self, x: DVec3, buf: &mut Vec<[u32; 2]>) -> bool {
        buf.clear();
        if x.cmplt(self.lo).any() || x.cmpgt(self.hi).any() {
            return false;
        }
        // Bound: the back child is the next node and the front child comes later (built from a
        // well-formed tree): the index grows at every step, at most `nodes.len()` steps.
        let mut n = 0usize;
        loop {
            let node = self.nodes[n];
            buf.extend_from_slice(
                &self.edges[node.first as usize..(node.first + node.count) as usize],
            );
            if node.plane == LEAF {
                if node.front != 0 {
                    return false;
                }
                break;
            }
            n = if self.planes[node.plane as usize].eval(x) > 0.0 {
                node.front as usize
            } else {
                n + 1
            };
        }
        // Chain in place: after step i, buf[..=i] is in loop order.
        let mut start = 0;
        for i in 0..buf.len() {
            let end = buf[i][1];
            if end == buf[start][0] {
                start = i + 1; // the loop closes; the next edge starts a new one
                continue;
            }
            if let Some(j) = (i + 1..buf.len()).find(|&j| buf[j][0] == end) {
                buf.swap(i + 1, j);
            }
        }
        true
    }

    /// The silhouette from `x` (looked up at `tree_x`, `x` in the tree's frame) as loops in
    /// `frame`, its points evaluated on `poly`; the same loops as the leaf-stored tree gives.
    pub fn silhouette_at(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        tree_x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
        buf: &mut Vec<[u32; 2]>,
    ) -> bool {
        if !self.loops(tree_x, buf) {
            return false;
        }
        out.clear();
        for run in loop_runs(buf) {
            for e in run {
                let d = match self.kind {
                    HoistedKind::Convex => (poly.vertices[e[0] as usize] - x).try_normalize(),
                    HoistedKind::Exact(coding) => coding.unpack(e[0], poly).direction(poly, x),
                };
                if let Some(d) = d {
                    out.push_vertex(frame.to_local(d));
                }
            }
            out.close_loop();
        }
        true
    }
}

/// The loops of a chained buffer ([`HoistedSilhouetteBsp::loops`]).
pub fn loop_runs(buf: &[[u32; 2]]) -> impl Iterator<Item = &[[u32; 2]]> {
    let mut rest = buf;
    std::iter::from_fn(move || {
        let first = rest.first()?[0];
        let len = rest.iter().position(|e| e[1] == first)? + 1;
        let (run, tail) = rest.split_at(len);
        rest = tail;
        Some(run)
    })
}
