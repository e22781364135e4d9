//! BSP trees of precomputed exact silhouettes for closed non-convex meshes (001 Sect. 5.2).
//!
//! Within a cell of the face planes the contour edges stay the same; what still changes is
//! which pairs of them appear to cross. Two edges begin to appear to cross where an end of one
//! appears to lie on the other: on the plane through that edge and that end (001 Fig. 5.3).
//! So each cell of the face planes is cut further by the "three-endpoint" planes of the pairs
//! of *its* contour edges (the thesis' second reduction: pairs that are not both contour edges
//! there are irrelevant; the first, removing duplicates, is implicit since only planes that cut
//! the cell are used). A leaf stores the silhouette found at a point of its cell, as loops of
//! [`SilhouettePoint`]s (mesh vertices and apparent intersections of two edges).
//!
//! The thesis stops there. Yet the order in which two edges cross a third can still swap
//! inside such a cell (three edges appearing concurrent is not a plane event), and so can
//! visibility behind a third edge; a leaf's structure is therefore *validated* at the corners
//! of its cell (pulled 10 % toward the centroid) against the silhouette computed on the fly.
//! A cell that fails is split through its centroid across its longest side and validated
//! again, to a depth limit; what still fails is marked so that shading computes it on the fly.
//! This is a validation on samples, not a proof: `tests/bsp_nonconvex.rs` measures how often a
//! random point meets a wrong leaf.

use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::NO_FACE;
use crate::geometry::mesh::ray::Ray;
use crate::geometry::mesh::triangle::PreparedRay;
use crate::geometry::silhouettes::exact_silhouette::{
    ExactSilhouetteScratch, PointCoding, SilhouettePoint, exact_silhouette, symbolic_loops,
};
use crate::geometry::silhouettes::silhouette::is_front_facing;
use crate::geometry::trees::bsp::BspNode;
use crate::geometry::trees::convex_cell::{CellSide, ConvexCell};
use crate::geometry::{Plane, Polyhedron, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;

/// Corners of a cell at which its leaf is validated.
pub(crate) const VALIDATION_CORNERS: usize = 6;

/// Marks a leaf whose silhouette is computed on the fly (`BspNode::Leaf::count`).
pub(crate) const ON_THE_FLY: u32 = u32::MAX;

/// Precomputed exact silhouettes of a closed non-convex mesh, in the mesh's coordinates.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ExactSilhouetteBsp {
    pub planes: Vec<Plane>,
    pub nodes: Vec<BspNode>,
    /// Leaf data: loops as ranges of `points`; a leaf holds `loops[first..first + count]`.
    /// Points in 32 bits: the encoding of 001 Sect. 5.4 up to 256 vertices, edge pairs past
    /// that (`coding`).
    pub loops: Vec<[u32; 2]>,
    pub points: Vec<u32>,
    #[serde(default)]
    pub coding: PointCoding,
    pub lo: DVec3,
    pub hi: DVec3,
}

/// What a build produced (001 Table 7.4, and the validation of this implementation).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ExactBspStats {
    pub seconds: f64,
    pub nodes: usize,
    pub leaves: usize,
    pub depth: usize,
    /// Distinct planes: the face planes and the three-endpoint planes used.
    pub planes: usize,
    /// Silhouette edges over all leaves (one per loop vertex).
    pub silhouette_edges: usize,
    /// Splits made because a leaf failed validation, and leaves left to the on-the-fly path.
    pub validation_splits: usize,
    pub on_the_fly_leaves: usize,
    /// Size at 20 bytes per node and 8 per edge (two 32-bit points), as in Table 7.4.
    pub table_7_4_bytes: usize,
}

/// Limits of a build.
#[derive(Clone, Copy, Debug)]
pub struct ExactBspLimits {
    pub max_leaves: usize,
    /// Depth of the splits made for validation, below a cell of the mesh's own planes.
    pub max_validation_depth: u32,
    /// Corners of a cell at which its leaf is validated (`VALIDATION_CORNERS`; 0 builds the
    /// tree as the thesis does, without validation: for comparing build times only).
    pub validation_corners: usize,
}

impl Default for ExactBspLimits {
    fn default() -> Self {
        ExactBspLimits {
            max_leaves: 200_000,
            max_validation_depth: 6,
            validation_corners: VALIDATION_CORNERS,
        }
    }
}

struct Builder<'a> {
    poly: &'a IndexedPolyhedron,
    tree: ExactSilhouetteBsp,
    stats: ExactBspStats,
    tol: f64,
    limits: ExactBspLimits,
    scratch: ExactSilhouetteScratch,
    symbolic: Vec<Option<SilhouettePoint>>,
    sph: SphericalPolygon,
    failed: bool,
    /// Edge index by its ends (smaller first), for [`PointCoding::EdgePairs`].
    edge_ids: std::collections::HashMap<[u32; 2], u32>,
    /// The tree's planes by grid cell of (n, d), for [`Builder::push_plane`].
    plane_grid: std::collections::HashMap<[i64; 4], Vec<u32>>,
}

/// Grid spacing of plane normals in [`Builder::push_plane`]'s index: two normals with
/// n·n' > 1 − 1e-12 differ by less than 1.5e-6 in every component, so they lie in the same or
/// in adjacent cells.
const PLANE_GRID_NORMAL: f64 = 1e-5;

impl ExactSilhouetteBsp {
    /// Builds the tree of a manifold mesh, closed or open, over the box `[lo, hi]`; `None` for
    /// a mesh with non-manifold edges or when the limits are exceeded.
    ///
    /// An open mesh's outline is made of pieces of its contour edges and of its boundary
    /// edges (docs/silhouettes.md, "Open meshes"). Inside a cell of the face planes every face
    /// keeps its side, so the contour edges are fixed there, and the boundary edges always
    /// are: the endpoint planes of their pairs (stage 2) cut the cell where crossings appear
    /// or vanish, exactly as for a closed mesh. An open mesh has no inside, so no leaf is left
    /// to the on-the-fly path for that reason.
    pub fn build(
        poly: &IndexedPolyhedron,
        lo: DVec3,
        hi: DVec3,
        limits: ExactBspLimits,
    ) -> Option<(Self, ExactBspStats)> {
        if poly.diagnostics.nonmanifold_edges != 0 {
            return None;
        }
        let coding = PointCoding::for_mesh(poly)?;
        let edge_ids = match coding {
            PointCoding::Vertices8 => Default::default(),
            PointCoding::EdgePairs => (poly.edges.iter().enumerate())
                .map(|(i, e)| ([e.v[0].min(e.v[1]), e.v[0].max(e.v[1])], i as u32))
                .collect(),
        };
        let start = web_time::Instant::now();
        let tol = 1e-9 * poly.radius.max(f64::MIN_POSITIVE);
        let mut b = Builder {
            poly,
            tree: ExactSilhouetteBsp {
                lo,
                hi,
                coding,
                ..Default::default()
            },
            stats: ExactBspStats::default(),
            tol,
            limits,
            scratch: ExactSilhouetteScratch::default(),
            symbolic: Vec::new(),
            sph: SphericalPolygon::new(),
            failed: false,
            edge_ids,
            plane_grid: Default::default(),
        };
        let faces: Vec<Plane> = poly.face_planes.clone();
        b.face_cells(ConvexCell::cuboid(lo, hi), &faces, 0);
        if b.failed {
            return None;
        }
        let mut stats = b.stats;
        stats.seconds = start.elapsed().as_secs_f64();
        stats.nodes = b.tree.nodes.len();
        stats.planes = b.tree.planes.len();
        stats.silhouette_edges = b.tree.points.len();
        stats.table_7_4_bytes = 20 * stats.nodes + 8 * stats.silhouette_edges;
        Some((b.tree, stats))
    }

    /// [`crate::geometry::trees::bsp::hoisted_edge_counts`] of this tree (edges: consecutive points of the leaf
    /// loops; on-the-fly leaves hold none).
    pub fn hoisted_edge_counts(&self) -> (usize, usize) {
        let edges = |first: u32, count: u32| {
            let mut out = Vec::new();
            if count == ON_THE_FLY {
                return out;
            }
            for lp in &self.loops[first as usize..(first + count) as usize] {
                let pts = &self.points[lp[0] as usize..lp[1] as usize];
                for k in 0..pts.len() {
                    out.push((pts[k] as u64, pts[(k + 1) % pts.len()] as u64));
                }
            }
            out
        };
        crate::geometry::trees::bsp::hoisted_edge_counts(&self.nodes, &edges)
    }

    /// Bytes of the tree's arrays in memory (planes, nodes, loop ranges, points).
    pub fn stored_bytes(&self) -> usize {
        std::mem::size_of_val(&self.planes[..])
            + std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.loops[..])
            + std::mem::size_of_val(&self.points[..])
    }

    /// Whether every index in the tree is in range for a mesh of `vertices` vertices and
    /// `edges` edges (a tree read from a file is checked before use).
    pub fn is_well_formed(&self, vertices: usize, edges: usize) -> bool {
        let (loops, points) = (self.loops.len(), self.points.len());
        crate::geometry::trees::bsp::nodes_well_formed(
            &self.nodes,
            self.planes.len(),
            |first, count| {
                count == ON_THE_FLY
                    || (first as usize)
                        .checked_add(count as usize)
                        .is_some_and(|e| e <= loops)
            },
        ) && self
            .loops
            .iter()
            .all(|&[a, b]| a <= b && (b as usize) <= points)
            && self
                .points
                .iter()
                .all(|&p| self.coding.in_range(p, vertices, edges))
    }

    /// The loops (ranges of `points`) of the leaf of `x`; `None` outside the box or in a leaf
    /// left to the on-the-fly path.
    #[inline]
    pub(super) fn leaf_ranges(&self, x: DVec3) -> Option<&[[u32; 2]]> {
        if x.cmplt(self.lo).any() || x.cmpgt(self.hi).any() || self.nodes.is_empty() {
            return None;
        }
        match self.nodes[crate::geometry::trees::bsp::bsp_leaf(&self.nodes, &self.planes, x)] {
            BspNode::Leaf { first, count } if count != ON_THE_FLY => {
                Some(&self.loops[first as usize..(first + count) as usize])
            }
            _ => None,
        }
    }

    /// The points of the leaf of `x` (`None` outside the box or in an on-the-fly leaf) on
    /// `poly`, the tree's mesh; for an instance, `x` is the point in the tree's frame.
    pub fn leaf_points<'a>(
        &'a self,
        poly: &'a Polyhedron,
        x: DVec3,
    ) -> Option<impl Iterator<Item = SilhouettePoint> + 'a> {
        Some(
            self.leaf_ranges(x)?
                .iter()
                .flat_map(|lp| self.points[lp[0] as usize..lp[1] as usize].iter())
                .map(move |&p| self.coding.unpack(p, poly)),
        )
    }

    /// The silhouette from `x` read from the tree, as positively oriented loops in `frame`;
    /// `false` outside the box or in a leaf left to the on-the-fly path.
    pub fn silhouette(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
    ) -> bool {
        self.silhouette_at(poly, x, x, frame, out)
    }

    /// [`ExactSilhouetteBsp::silhouette`] for an instance of the tree's mesh: the leaf is
    /// looked up at `tree_x` (`x` in the tree's frame), its points (vertex indices, pairs of
    /// edges) evaluated on `poly`, the instance's own vertices, from `x` (001 Sect. 5.4).
    #[inline]
    pub fn silhouette_at(
        &self,
        poly: &Polyhedron,
        x: DVec3,
        tree_x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
    ) -> bool {
        let Some(loops) = self.leaf_ranges(tree_x) else {
            return false;
        };
        out.clear();
        for lp in loops {
            for &p in &self.points[lp[0] as usize..lp[1] as usize] {
                if let Some(d) = self.coding.unpack(p, poly).direction(poly, x) {
                    out.push_vertex(frame.to_local(d));
                }
            }
            out.close_loop();
        }
        true
    }
}

impl Builder<'_> {
    /// The index of `p` among the tree's planes: the first plane that matches it (normals
    /// within 1e-12 in cosine, offsets within the tolerance), else `p` appended. The matches
    /// are looked up in a grid of (n, d) whose cells are at least as wide as the match
    /// tolerances, in the 3⁴ cells around `p`'s: the same answer as a scan of every plane,
    /// which made a tree of 10⁵ planes quadratic to build (tens of seconds for a 12-face mesh).
    fn push_plane(&mut self, p: Plane) -> u32 {
        let d_cell = if self.tol > 0.0 { self.tol } else { 1e-300 };
        let key = |q: &Plane| {
            [
                (q.n.x / PLANE_GRID_NORMAL).floor() as i64,
                (q.n.y / PLANE_GRID_NORMAL).floor() as i64,
                (q.n.z / PLANE_GRID_NORMAL).floor() as i64,
                (q.d / d_cell).floor() as i64,
            ]
        };
        let k = key(&p);
        let mut found: Option<u32> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for dd in -1..=1 {
                        let cell = [k[0] + dx, k[1] + dy, k[2] + dz, k[3] + dd];
                        let Some(ids) = self.plane_grid.get(&cell) else {
                            continue;
                        };
                        for &i in ids {
                            let q = &self.tree.planes[i as usize];
                            if found.is_none_or(|f| i < f)
                                && q.n.dot(p.n) > 1.0 - 1e-12
                                && (q.d - p.d).abs() <= self.tol
                            {
                                found = Some(i);
                            }
                        }
                    }
                }
            }
        }
        found.unwrap_or_else(|| {
            let i = self.tree.planes.len() as u32;
            self.tree.planes.push(p);
            self.plane_grid.entry(k).or_default().push(i);
            i
        })
    }

    /// Splits `cell` by `plane`, building both children with `f`; returns the node index.
    fn split(
        &mut self,
        cell: &ConvexCell,
        plane: Plane,
        depth: usize,
        mut f: impl FnMut(&mut Self, ConvexCell, usize) -> u32,
    ) -> u32 {
        let me = self.tree.nodes.len() as u32;
        self.tree.nodes.push(BspNode::Leaf { first: 0, count: 0 });
        let k = self.push_plane(plane);
        let (back, front) = cell.split(&plane, self.tol);
        let b = f(self, back, depth + 1);
        let fr = f(self, front, depth + 1);
        self.tree.nodes[me as usize] = BspNode::Inner {
            plane: k,
            back: b,
            front: fr,
        };
        me
    }

    /// Once over the limits, the rest of the build is skipped (the tree is discarded).
    fn abandoned(&mut self) -> Option<u32> {
        self.failed.then(|| {
            self.tree.nodes.push(BspNode::Leaf {
                first: 0,
                count: ON_THE_FLY,
            });
            (self.tree.nodes.len() - 1) as u32
        })
    }

    /// Stage 1: the cells of the face planes.
    fn face_cells(&mut self, cell: ConvexCell, faces: &[Plane], depth: usize) -> u32 {
        if let Some(n) = self.abandoned() {
            return n;
        }
        let cutting: Vec<Plane> = faces
            .iter()
            .copied()
            .filter(|p| cell.side(p, self.tol) == CellSide::Straddles)
            .collect();
        match cutting.split_first() {
            Some((&p, rest)) => {
                let rest = rest.to_vec();
                self.split(&cell, p, depth, |b, c, d| b.face_cells(c, &rest, d))
            }
            None => {
                // The contour is fixed in this cell: the three-endpoint planes of its pairs.
                let ev = self.endpoint_planes(cell.centroid());
                self.endpoint_cells(cell, &ev, depth)
            }
        }
    }

    /// The three-endpoint planes of the pairs of contour edges from `c` that share no vertex:
    /// `[e+g₁, e+g₂, g+e₁, g+e₂]` per pair (the plane through edge e and end g₁ of g, …). The
    /// sign of `e+g₁` at x is the side of g₁ relative to the plane of e's arc seen from x.
    fn endpoint_planes(&self, c: DVec3) -> Vec<[Option<Plane>; 4]> {
        let poly = self.poly;
        // The contour edges, and every boundary edge of an open mesh (whichever way its one
        // face turns: `exact_silhouette` takes them all).
        let contour: Vec<[u32; 2]> = poly
            .edges
            .iter()
            .filter(|e| {
                e.faces[1] == NO_FACE
                    || is_front_facing(poly, e.faces[0] as usize, c)
                        != is_front_facing(poly, e.faces[1] as usize, c)
            })
            .map(|e| e.v)
            .collect();
        let v = |i: u32| poly.vertices[i as usize];
        let plane = |edge: &[u32; 2], end: u32| {
            let (a, b, p) = (v(edge[0]), v(edge[1]), v(end));
            (b - a)
                .cross(p - a)
                .try_normalize()
                .map(|n| Plane { n, d: n.dot(a) })
        };
        let boundary = |e: &[u32; 2]| {
            poly.edges
                .iter()
                .any(|b| b.faces[1] == NO_FACE && (b.v == *e || b.v == [e[1], e[0]]))
        };
        let mut out = Vec::new();
        for (i, e) in contour.iter().enumerate() {
            for g in &contour[i + 1..] {
                if e.iter().any(|a| g.contains(a)) {
                    // Two outline edges at one vertex, one of them a boundary edge: which
                    // one's image lies on which side of the other's at the vertex (and so which
                    // one the outline follows there) changes where they look collinear, on the
                    // plane through both. On a closed mesh the faces' sides decide it.
                    if boundary(e) || boundary(g) {
                        let shared = if g.contains(&e[0]) { e[0] } else { e[1] };
                        let other =
                            |edge: &[u32; 2]| if edge[0] == shared { edge[1] } else { edge[0] };
                        let (a, b, c) = (v(shared), v(other(e)), v(other(g)));
                        let p = (b - a)
                            .cross(c - a)
                            .try_normalize()
                            .map(|n| Plane { n, d: n.dot(a) });
                        out.push([p; 4]);
                    }
                    continue;
                }
                out.push([
                    plane(e, g[0]),
                    plane(e, g[1]),
                    plane(g, e[0]),
                    plane(g, e[1]),
                ]);
            }
        }
        out
    }

    /// Stage 2: the cells of the three-endpoint planes inside a cell of the face planes. A
    /// pair's planes matter only where its arcs can cross: where each arc's great circle can
    /// separate the other's ends (the two signs of the pair of planes differ somewhere in the
    /// cell); elsewhere the pair is dropped for the whole subtree, an exact reduction.
    fn endpoint_cells(
        &mut self,
        cell: ConvexCell,
        pairs: &[[Option<Plane>; 4]],
        depth: usize,
    ) -> u32 {
        if let Some(n) = self.abandoned() {
            return n;
        }
        let c = cell.centroid();
        let tol = self.tol;
        let cuts = |p: &Option<Plane>| p.is_some_and(|p| cell.side(&p, tol) == CellSide::Straddles);
        let sign = |p: &Option<Plane>| p.is_some_and(|p| p.eval(c) > 0.0);
        let can_separate = |p: &Option<Plane>, q: &Option<Plane>| {
            p.is_none() || q.is_none() || cuts(p) || cuts(q) || sign(p) != sign(q)
        };
        let live: Vec<[Option<Plane>; 4]> = pairs
            .iter()
            .copied()
            .filter(|q| can_separate(&q[0], &q[1]) && can_separate(&q[2], &q[3]))
            .filter(|q| q.iter().any(&cuts))
            .collect();
        let first_cut = live
            .first()
            .and_then(|q| q.iter().find(|p| cuts(p)).copied().flatten());
        match first_cut {
            Some(p) => self.split(&cell, p, depth, |b, c, d| b.endpoint_cells(c, &live, d)),
            None => self.leaf(cell, depth, 0),
        }
    }

    /// A leaf for `cell`: the silhouette at its centroid, validated at its corners; split
    /// across its longest side when that fails.
    fn leaf(&mut self, cell: ConvexCell, depth: usize, validation_depth: u32) -> u32 {
        self.stats.depth = self.stats.depth.max(depth);
        if self.stats.leaves >= self.limits.max_leaves {
            self.failed = true;
        }
        if let Some(n) = self.abandoned() {
            return n;
        }
        let me = self.tree.nodes.len() as u32;
        let c = cell.centroid();
        if self.poly.diagnostics.closed_manifold && inside(self.poly, c) {
            // Inside the solid: never shaded.
            self.stats.leaves += 1;
            self.tree.nodes.push(BspNode::Leaf {
                first: 0,
                count: ON_THE_FLY,
            });
            return me;
        }
        let frame = Frame::from_z(DVec3::Z);
        let ok = exact_silhouette(self.poly, c, &frame, &mut self.sph, &mut self.scratch).is_ok();
        if ok {
            symbolic_loops(&self.scratch, &mut self.symbolic);
        }
        let valid = ok && self.validate(&cell);
        if !valid && validation_depth < self.limits.max_validation_depth && !self.failed {
            self.stats.validation_splits += 1;
            let plane = cell.longest_axis_plane(c);
            return self.split(&cell, plane, depth, |b, c, d| {
                b.leaf(c, d, validation_depth + 1)
            });
        }
        self.stats.leaves += 1;
        if !valid {
            self.stats.on_the_fly_leaves += 1;
            self.tree.nodes.push(BspNode::Leaf {
                first: 0,
                count: ON_THE_FLY,
            });
            return me;
        }
        let first = self.tree.loops.len() as u32;
        let mut start = self.tree.points.len() as u32;
        for p in &self.symbolic {
            match p {
                Some(p) => {
                    let edge_of =
                        |[a, b]: [u32; 2]| self.edge_ids.get(&[a.min(b), a.max(b)]).copied();
                    match self.tree.coding.pack(p, edge_of) {
                        Some(code) => self.tree.points.push(code),
                        None => self.failed = true, // excluded by `PointCoding::for_mesh`
                    }
                }
                None => {
                    let end = self.tree.points.len() as u32;
                    self.tree.loops.push([start, end]);
                    start = end;
                }
            }
        }
        let count = self.tree.loops.len() as u32 - first;
        self.tree.nodes.push(BspNode::Leaf { first, count });
        me
    }

    /// Does the structure in `self.symbolic` give the silhouette computed on the fly at points
    /// of `cell` (its corners pulled 10 % toward the centroid)?
    fn validate(&mut self, cell: &ConvexCell) -> bool {
        let c = cell.centroid();
        let frame = Frame::from_z(DVec3::Z);
        let mut corners: Vec<DVec3> = Vec::new();
        for p in cell.vertices() {
            if !corners.iter().any(|q| q.distance(p) <= self.tol) {
                corners.push(p);
            }
        }
        // A few corners suffice to catch a structure that changes inside the cell (the
        // validation's cost bounds the build's). An open mesh's outline also changes where
        // the images of three outline edges meet at one point (a curved surface of x that no
        // plane of the tree follows) more often, at its boundary's folds: its cells are
        // validated at every corner, and at the middle of every face and every edge of the
        // cell too.
        let open = !self.poly.diagnostics.closed_manifold;
        let count = if open {
            corners.len()
        } else {
            self.limits.validation_corners
        };
        let mut points: Vec<DVec3> = corners.into_iter().take(count).collect();
        if open {
            for f in &cell.faces {
                points.push(f.iter().sum::<DVec3>() / f.len() as f64);
                for k in 0..f.len() {
                    points.push(0.5 * (f[k] + f[(k + 1) % f.len()]));
                }
            }
        }
        let mut from_leaf = SphericalPolygon::new();
        for p in points {
            let q = c + (p - c) * 0.9;
            if exact_silhouette(self.poly, q, &frame, &mut self.sph, &mut self.scratch).is_err() {
                continue;
            }
            from_leaf.clear();
            for s in &self.symbolic {
                match s {
                    Some(s) => match s.direction(self.poly, q) {
                        Some(d) => {
                            from_leaf.push_vertex(d);
                        }
                        None => return false,
                    },
                    None => {
                        from_leaf.close_loop();
                    }
                }
            }
            let (a, b) = (area(&from_leaf), area(&self.sph));
            if (a - b).abs() > 1e-9 {
                return false;
            }
        }
        true
    }
}

/// Whether `x` lies inside the closed mesh: an odd number of crossings along a fixed ray.
fn inside(poly: &Polyhedron, x: DVec3) -> bool {
    let ray = PreparedRay::new(&Ray::new(x, DVec3::new(0.5773, 0.5774, 0.5775)));
    let crossings = poly
        .fan_triangles()
        .filter(|(_, [v0, v1, v2])| ray.intersect(*v0, *v1, *v2, 0.0, f64::INFINITY).is_some())
        .count();
    crossings % 2 == 1
}

/// Solid angle of a region of any size (fan about a fixed direction with the full-range
/// atan2 form of Van Oosterom–Strackee, modulo 4π).
fn area(p: &SphericalPolygon) -> f64 {
    let c = DVec3::new(0.267, -0.534, 0.802).normalize();
    let mut total = 0.0;
    for lp in p.loops() {
        for k in 0..lp.len() {
            let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
            total += 2.0
                * c.dot(a.cross(b))
                    .atan2(1.0 + c.dot(a) + a.dot(b) + b.dot(c));
        }
    }
    total.rem_euclid(4.0 * std::f64::consts::PI)
}
