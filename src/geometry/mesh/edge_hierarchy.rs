//! Contour edges (001 Eq. 4.2) through a hierarchy over the edges instead of a scan: a
//! spatialized normal-cone hierarchy (Sander, Gu, Gortler, Hoppe and Snyder 2000, "Silhouette
//! clustering"; Johnson and Cohen 2001). Each node bounds the faces adjacent to its edges by a
//! cone of their unit normals and a sphere around points of their planes; from a point that
//! sees all those faces from the front, or all from the back, none of the node's edges is a
//! contour edge and the node is skipped.
//!
//! The hierarchy only *enumerates* candidate edges. Its skip test is conservative with a
//! margin far above rounding (and above the coplanarity tolerance of the exact silhouette),
//! each candidate gets the scan's own test, and the contour edges are sorted by index: the
//! result is the scan's, bit for bit and in the same order ([`contour_edge_indices`]).
//!
//! # The skip test
//!
//! Let a node's faces have planes `s_f(x) = n_f · x − d_f` (unit `n_f`), anchors `q_f` on their
//! faces (the vertex mean) with residual `e_f = n_f · q_f − d_f` (zero but for rounding and
//! non-planarity), normals within the angle `α ≤ π/2` of the unit axis `a`, and
//! `|n_f| |q_f − c| + |e_f| ≤ r` for the node's centre `c`. With `d = x − c` and
//! `β = ∠(a, d)`:
//!
//! ```text
//!   s_f(x) = n_f · d + n_f · (c − q_f) + e_f,   so   n_f · d − r ≤ s_f(x) ≤ n_f · d + r,
//!   ∠(n_f, d) ∈ [β − α, β + α]  ⇒  |d| cos(α + β) ≤ n_f · d ≤ |d| cos(β − α)   (α ≤ π/2),
//! ```
//!
//! where `|d| cos(α ± β) = cos α (a · d) ∓ sin α |a × d|` needs no trigonometry at the query.
//! Hence (Eq. EH.1)
//!
//! ```text
//!   cos α (a · d) − sin α |a × d| >  r + m   ⇒  every face front-facing   (s_f > tol),
//!   cos α (a · d) + sin α |a × d| < −r − m   ⇒  every face back-facing    (s_f < −tol),
//! ```
//!
//! with the margin `m = tol + 1e-12 (|c| + r + ‖d‖₁)` (`tol` the exact silhouette's coplanarity
//! tolerance, the rest bounds the rounding of both sides). The first bound is positive only
//! when `α + β < π/2` and the second negative only when `β − α > π/2` (for `α ≤ π/2`), where
//! the cosine bounds hold; nodes with a wider cone are never skipped. Boundary edges (one face
//! only) are kept out of the tree and handed out by every query: such an edge bounds an open
//! mesh's image whichever way its face turns. [`EdgeHierarchy::candidates`] implements the test.

use crate::geometry::mesh::face_bvh::{ball_meets_pyramid, sphere_meets_cone};
use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::{NO_FACE, Polyhedron};
use glam::DVec3;

/// Meshes with fewer edges are scanned: measured with `examples/edge_hierarchy_bench.rs`
/// (docs/silhouettes.md, "Contour edges through a normal-cone hierarchy"; 480 edges break even).
pub(crate) const EDGE_HIERARCHY_MIN_EDGES: usize = 1024;

/// What testing one node costs, in plane tests of the scan's edges (measured: about 26 ns a
/// node against 5.6 ns an edge scanned, on the displaced icospheres and the bunny).
const NODE_COST: f64 = 4.7;

/// The hierarchy is kept when its estimated cost is below this fraction of the scan's.
const KEEP_BELOW: f64 = 0.8;

/// How a hierarchy is built (the defaults are the measured choice).
#[derive(Clone, Copy, Debug)]
pub struct BuildParams {
    /// Edges per leaf, at most.
    pub leaf_edges: usize,
    /// Weight of the unit mean normal against the midpoint (in mesh radii) in the split keys.
    pub normal_weight: f64,
}

impl Default for BuildParams {
    fn default() -> Self {
        BuildParams {
            leaf_edges: 8,
            normal_weight: 1.0,
        }
    }
}

/// Relative margin of the skip test over rounding (see the module documentation).
const ROUNDING: f64 = 1e-12;

/// How much a cone's half-angle is widened over its computed value (radians).
const ANGLE_MARGIN: f64 = 1e-9;

#[derive(Clone, Copy, Debug)]
struct Node {
    /// Unit axis of the normal cone.
    axis: DVec3,
    /// cos α and sin α of the widened half-angle; `cos_a < 0` marks a node never skipped.
    cos_a: f64,
    sin_a: f64,
    centre: DVec3,
    /// r + tol + 1e-12 (|c| + r): everything of the margin but the query's ‖d‖₁ term.
    slack: f64,
    /// Radius about `centre` of a ball holding the ends of the node's edges (for the
    /// windowed queries, [`EdgeHierarchy::candidates_in_cone`]).
    reach: f64,
    /// Index of the node after this one's subtree (depth-first order).
    next: u32,
    /// Leaf: `count > 0` edges from `start` in `edges`; inner: `count == 0`, children follow.
    start: u32,
    count: u32,
}

/// The edges of one polyhedron in a binary tree of normal cones and bounding spheres, stored
/// depth first (a node's first child follows it; `next` skips its subtree).
#[derive(Clone, Debug, Default)]
pub struct EdgeHierarchy {
    nodes: Vec<Node>,
    /// Edge indices, leaf after leaf, ascending within a leaf.
    edges: Vec<u32>,
    /// The boundary edges (one face only), outside the tree: every query hands them out.
    boundary: Vec<u32>,
    /// A ball around each boundary edge (its midpoint and half length, widened by rounding).
    boundary_balls: Vec<(DVec3, f64)>,
    leaf_edges: usize,
}

/// What one query did, for the measurements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EdgeQueryStats {
    pub nodes_visited: u32,
    pub edges_tested: u32,
}

/// The coplanarity tolerance of the exact silhouette for `poly` (a face plane within it of the
/// point is degenerate there); the skip test's margin includes it.
#[inline]
pub fn coplanar_tolerance(poly: &Polyhedron) -> f64 {
    1e-9 * poly.radius.max(f64::MIN_POSITIVE)
}

impl EdgeHierarchy {
    /// The hierarchy over the edges of `poly`: top-down median splits of the edges along the
    /// widest of six coordinates, the edge midpoint (over the mesh radius) and the mean normal
    /// of its faces, so that nodes are compact both in space and in normals.
    pub fn build(poly: &Polyhedron) -> EdgeHierarchy {
        Self::build_with(poly, BuildParams::default())
    }

    /// [`EdgeHierarchy::build`] with other parameters (for the measurements).
    pub fn build_with(poly: &Polyhedron, params: BuildParams) -> EdgeHierarchy {
        let mut h = EdgeHierarchy::default();
        if poly.edges.is_empty() {
            return h;
        }
        let scale = poly.radius.max(f64::MIN_POSITIVE);
        let anchors: Vec<(DVec3, f64)> = (0..poly.face_count())
            .map(|f| {
                let idx = poly.face(f);
                let q = idx
                    .iter()
                    .fold(DVec3::ZERO, |s, &v| s + poly.vertices[v as usize])
                    / idx.len() as f64;
                (q, poly.face_planes[f].eval(q).abs())
            })
            .collect();
        let keys: Vec<[f64; 6]> = poly
            .edges
            .iter()
            .map(|e| {
                let m = (0.5 * (poly.vertices[e.v[0] as usize] + poly.vertices[e.v[1] as usize])
                    - poly.center)
                    / scale;
                let mut n = poly.face_planes[e.faces[0] as usize].n;
                if e.faces[1] != NO_FACE {
                    n += poly.face_planes[e.faces[1] as usize].n;
                }
                let n = n.normalize_or_zero() * params.normal_weight;
                [m.x, m.y, m.z, n.x, n.y, n.z]
            })
            .collect();
        // A boundary edge bounds an open mesh's image whichever way its face turns: it is a
        // candidate at every point, and kept out of the tree so that no node has to hold one
        // (a node that did could never be skipped).
        let (mut order, boundary): (Vec<u32>, Vec<u32>) =
            (0..poly.edges.len() as u32).partition(|&e| !poly.edges[e as usize].is_boundary());
        h.boundary_balls = boundary
            .iter()
            .map(|&e| {
                let e = &poly.edges[e as usize];
                let (a, b) = (
                    poly.vertices[e.v[0] as usize],
                    poly.vertices[e.v[1] as usize],
                );
                (0.5 * (a + b), 0.5 * (a - b).length() * (1.0 + ROUNDING))
            })
            .collect();
        h.boundary = boundary;
        if order.is_empty() {
            return h;
        }
        h.nodes
            .reserve(2 * poly.edges.len() / params.leaf_edges.max(1) + 1);
        h.leaf_edges = params.leaf_edges.max(1);
        let tol = coplanar_tolerance(poly);
        h.split(poly, &anchors, &keys, tol, &mut order, 0);
        h.edges = order;
        h
    }

    /// Appends the node (and its subtree) of `edges`, which start at `first` in the final order.
    fn split(
        &mut self,
        poly: &Polyhedron,
        anchors: &[(DVec3, f64)],
        keys: &[[f64; 6]],
        tol: f64,
        edges: &mut [u32],
        first: usize,
    ) {
        let n = self.nodes.len();
        self.nodes.push(bounds(poly, anchors, tol, edges));
        if edges.len() <= self.leaf_edges {
            edges.sort_unstable();
            let node = &mut self.nodes[n];
            node.start = first as u32;
            node.count = edges.len() as u32;
            node.next = (n + 1) as u32;
            return;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 6], [f64::NEG_INFINITY; 6]);
        for &e in edges.iter() {
            for (k, &v) in keys[e as usize].iter().enumerate() {
                lo[k] = lo[k].min(v);
                hi[k] = hi[k].max(v);
            }
        }
        let axis = (0..6)
            .max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j])).then(j.cmp(&i)))
            .unwrap_or(0);
        let mid = edges.len() / 2;
        edges.select_nth_unstable_by(mid, |&a, &b| {
            keys[a as usize][axis]
                .total_cmp(&keys[b as usize][axis])
                .then(a.cmp(&b))
        });
        let (left, right) = edges.split_at_mut(mid);
        self.split(poly, anchors, keys, tol, left, first);
        self.split(poly, anchors, keys, tol, right, first + mid);
        self.nodes[n].next = self.nodes.len() as u32;
    }

    /// Whether the hierarchy pays for `poly` (built over it): its mean cost over fixed sample
    /// points at three radii from the centre in 26 directions, in edge tests
    /// ([`NODE_COST`] per node visited plus the edges tested), is below [`KEEP_BELOW`] of
    /// the scan's. A mesh of noisy normals (the scanned bunny) keeps the scan.
    pub fn pays(&self, poly: &Polyhedron) -> bool {
        let mut buf = Vec::new();
        let (mut cost, mut n) = (0.0, 0.0);
        for i in -1i32..=1 {
            for j in -1i32..=1 {
                for k in -1i32..=1 {
                    let Some(dir) = DVec3::new(i as f64, j as f64, k as f64).try_normalize() else {
                        continue;
                    };
                    buf.clear();
                    let st = self.candidates(poly.center + dir * (3.0 * poly.radius), &mut buf);
                    cost += NODE_COST * st.nodes_visited as f64 + st.edges_tested as f64;
                    n += 1.0;
                }
            }
        }
        cost / n < KEEP_BELOW * poly.edges.len() as f64
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Appends to `out` the edges of every leaf that the skip test (Eq. EH.1 of the module
    /// documentation) cannot skip from `x`: a superset of the contour edges, and of the edges
    /// of every face whose plane lies within the coplanarity tolerance of `x`. Leaves come in
    /// depth-first order, not in edge order.
    pub fn candidates(&self, x: DVec3, out: &mut Vec<u32>) -> EdgeQueryStats {
        let mut stats = self.tree_candidates(x, |_| true, out);
        out.extend_from_slice(&self.boundary);
        stats.edges_tested += self.boundary.len() as u32;
        stats
    }

    /// [`EdgeHierarchy::candidates`] restricted to the edges that may meet the cone of
    /// directions within the angle θ (its cosine and sine) of the unit `axis` from `x`: nodes
    /// whose edges' ball ([`sphere_meets_cone`]) misses the cone are skipped too, and so are
    /// boundary edges whose ball misses it. A superset of the contour and boundary edges
    /// with a point in the cone (what a window around a light needs,
    /// [`crate::geometry::silhouettes::windowed_silhouette`]).
    pub fn candidates_in_cone(
        &self,
        x: DVec3,
        axis: DVec3,
        cos_theta: f64,
        sin_theta: f64,
        out: &mut Vec<u32>,
    ) -> EdgeQueryStats {
        self.candidates_in_window(x, axis, cos_theta, sin_theta, &[], out)
    }

    /// [`EdgeHierarchy::candidates_in_cone`] restricted further to the pyramid from `x` of a
    /// convex window inside the cone, given by the inward unit normals `sides` of its great
    /// circles: a ball wholly on the outer side of one of them (by more than its radius, with a
    /// relative margin of 1e-9) holds no point whose direction from `x` is in the window. A
    /// superset of the contour and boundary edges with a point in the window, in the order of
    /// the cone's query (a subsequence of it).
    pub fn candidates_in_window(
        &self,
        x: DVec3,
        axis: DVec3,
        cos_theta: f64,
        sin_theta: f64,
        sides: &[DVec3],
        out: &mut Vec<u32>,
    ) -> EdgeQueryStats {
        let in_window = |c: DVec3, r: f64| {
            sphere_meets_cone(x, axis, cos_theta, sin_theta, c, r)
                && ball_meets_pyramid(x, sides, c, r)
        };
        let mut stats = self.tree_candidates(x, |n| in_window(n.centre, n.reach), out);
        for (&e, &(c, r)) in self.boundary.iter().zip(&self.boundary_balls) {
            stats.edges_tested += 1;
            if in_window(c, r) {
                out.push(e);
            }
        }
        stats
    }

    /// The tree's part of the queries: the edges of every leaf that neither the skip test
    /// nor `keep` (false: skip the node's subtree) rules out.
    #[inline]
    fn tree_candidates(
        &self,
        x: DVec3,
        keep: impl Fn(&Node) -> bool,
        out: &mut Vec<u32>,
    ) -> EdgeQueryStats {
        let mut stats = EdgeQueryStats::default();
        let mut i = 0;
        // Bound: `i` only grows (to the next node, or past a skipped subtree): `nodes.len()` steps.
        while i < self.nodes.len() {
            let node = &self.nodes[i];
            stats.nodes_visited += 1;
            if node.cos_a >= 0.0 {
                let d = x - node.centre;
                let along = node.axis.dot(d);
                let across = node.axis.cross(d).length();
                let margin = node.slack + ROUNDING * (d.x.abs() + d.y.abs() + d.z.abs());
                // Eq. EH.1: |d| cos(α + β) > r + m, all faces front-facing; |d| cos(β − α) <
                // −(r + m), all back-facing.
                let front = node.cos_a * along - node.sin_a * across > margin;
                let back = node.cos_a * along + node.sin_a * across < -margin;
                if front || back {
                    i = node.next as usize;
                    continue;
                }
            }
            if !keep(node) {
                i = node.next as usize;
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                out.extend_from_slice(&self.edges[s..s + node.count as usize]);
                stats.edges_tested += node.count;
            }
            i += 1;
        }
        stats
    }

    /// Writes into `out` every edge of `poly` (the mesh this hierarchy was built over) that
    /// can be a contour or boundary edge with a point in the window of some shading point of
    /// `region` (Eq. EH.2 of docs/silhouettes.md): each edge that the windowed silhouette at
    /// such a point makes an arc of is in `out`, in the order of that point's window query.
    /// An edge is left out when both its faces are seen from the front from the whole ball, or
    /// both from the back, beyond the coplanarity tolerance, or when its ball, grown by the
    /// region's radius, misses the region's cone or its `pyramid`.
    pub(crate) fn tile_candidates(
        &self,
        poly: &Polyhedron,
        region: &RegionCone,
        pyramid: Option<&RegionPyramid>,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let (c, rho) = (region.centre, region.radius);
        let tol = coplanar_tolerance(poly);
        // The windows of every point of the ball lie in the cone from `c`, so a ball that can
        // meet one of them, moved by at most `rho`, meets that cone (the module docs of
        // `geometry::silhouettes::tile_candidates`); `1 + 1e-6` covers the queries' own relative margins.
        let meets = |centre: DVec3, reach: f64| {
            sphere_meets_cone(
                c,
                region.axis,
                region.cos_theta,
                region.sin_theta,
                centre,
                (reach + rho) * (1.0 + 1e-6),
            ) && pyramid.is_none_or(|p| p.meets(centre, reach))
        };
        // A face seen from the same side by every point of the ball, beyond the tolerance:
        // its plane is 1-Lipschitz in the point over its normal's length.
        let side = |f: u32| {
            let plane = &poly.face_planes[f as usize];
            let s = plane.eval(c);
            let reach = rho * plane.n.length() * (1.0 + 1e-12)
                + tol
                + 1e-12 * (plane.n.length() * c.length() + plane.d.abs());
            if s > reach {
                1
            } else if s < -reach {
                -1
            } else {
                0
            }
        };
        let mut i = 0;
        // Bound: `i` only grows, as in `tree_candidates`; each edge is looked at once.
        while i < self.nodes.len() {
            let node = &self.nodes[i];
            if skips_from_ball(node, c, rho) || !meets(node.centre, node.reach) {
                i = node.next as usize;
                continue;
            }
            let s = node.start as usize;
            for &e in &self.edges[s..s + node.count as usize] {
                let edge = &poly.edges[e as usize];
                let [g0, g1] = edge.faces;
                let (s0, s1) = (side(g0), side(g1));
                if s0 != 0 && s0 == s1 {
                    continue;
                }
                let (a, b) = (
                    poly.vertices[edge.v[0] as usize],
                    poly.vertices[edge.v[1] as usize],
                );
                if meets(0.5 * (a + b), 0.5 * (a - b).length()) {
                    out.push(e);
                }
            }
            i += 1;
        }
        for (&e, &(bc, br)) in self.boundary.iter().zip(&self.boundary_balls) {
            if meets(bc, br) {
                out.push(e);
            }
        }
    }
}

/// Shading points within `radius` of `centre`, each looking at a window (the widened light,
/// [`crate::geometry::silhouettes::windowed_silhouette`]) that lies, seen from `centre`, in the cone of directions
/// within θ of the unit `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RegionCone {
    pub centre: DVec3,
    pub radius: f64,
    pub axis: DVec3,
    pub cos_theta: f64,
    pub sin_theta: f64,
}

/// The pyramid of one point's window, which bounds the windows of every point of a region
/// (the module docs of `geometry::silhouettes::tile_candidates`): from `apex`, whose window is the whole
/// light, with the inward unit normals `sides` of that window's great circles. The points of
/// the region lie within `reach` of the apex, and every direction from one of them into its
/// window is on the inner side of each great circle up to `spread` (a sine).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RegionPyramid<'a> {
    pub apex: DVec3,
    pub sides: &'a [DVec3],
    pub reach: f64,
    pub spread: f64,
}

impl RegionPyramid<'_> {
    /// Whether the ball of centre `q` and radius `r` may hold a point seen from a point of the
    /// region in its window: a point `p = x + t u` of it has `n · (p − apex) ≥ −reach − t
    /// spread` for each side `n`, with `t ≤ |q − apex| + r + reach`.
    #[inline]
    fn meets(&self, q: DVec3, r: f64) -> bool {
        let d = q - self.apex;
        let far = d.length() + r + self.reach;
        let slack = (r + self.reach) * (1.0 + 1e-6) + far * self.spread;
        self.sides.iter().all(|n| n.dot(d) >= -slack)
    }
}

/// Eq. EH.2: the skip test of Eq. EH.1 holds at every point within `rho` of `c`. Both sides of
/// Eq. EH.1 are 1-Lipschitz in `x` (the left one is `|d| cos(α ± β)`, whose gradient has unit
/// length, the margin's ‖d‖₁ term is √3-Lipschitz times 1e-12), so the test at `c` with the
/// margin raised by `rho (1 + 2e-12)` holds everywhere in the ball; the last term covers the
/// rounding of both evaluations, far above it.
#[inline]
fn skips_from_ball(node: &Node, c: DVec3, rho: f64) -> bool {
    if node.cos_a < 0.0 {
        return false;
    }
    let d = c - node.centre;
    let along = node.axis.dot(d);
    let across = node.axis.cross(d).length();
    let margin = node.slack
        + ROUNDING * (d.x.abs() + d.y.abs() + d.z.abs())
        + rho * (1.0 + 2.0 * ROUNDING)
        + 1e-10 * (d.length() + rho + node.centre.length() + node.slack);
    node.cos_a * along - node.sin_a * across > margin
        || node.cos_a * along + node.sin_a * across < -margin
}

/// The normal cone and bounding sphere of the faces adjacent to `edges`.
fn bounds(poly: &Polyhedron, anchors: &[(DVec3, f64)], tol: f64, edges: &[u32]) -> Node {
    let faces = || {
        edges.iter().flat_map(|&e| {
            let e = &poly.edges[e as usize];
            e.faces.into_iter().filter(|&f| f != NO_FACE)
        })
    };
    // Cone: the mean normal, and the widest angle to it (2 atan2(|a − n|, |a + n|) is
    // accurate at small angles, where acos is not).
    let sum = faces().fold(DVec3::ZERO, |s, f| s + poly.face_planes[f as usize].n);
    let (axis, cos_a, sin_a) = match sum.try_normalize() {
        Some(a) => {
            let alpha = faces()
                .map(|f| {
                    let n = poly.face_planes[f as usize].n;
                    2.0 * (a - n).length().atan2((a + n).length())
                })
                .fold(0.0, f64::max)
                + ANGLE_MARGIN;
            if alpha < std::f64::consts::FRAC_PI_2 {
                (a, alpha.cos(), alpha.sin())
            } else {
                (a, -1.0, 0.0)
            }
        }
        None => (DVec3::Z, -1.0, 0.0),
    };
    // Sphere: the centre of the anchors' box; r bounds |n_f| |q_f − c| + |e_f|.
    let (lo, hi) = faces().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), f| {
        let q = anchors[f as usize].0;
        (lo.min(q), hi.max(q))
    });
    let centre = 0.5 * (lo + hi);
    let r = faces()
        .map(|f| {
            let (q, e) = anchors[f as usize];
            poly.face_planes[f as usize].n.length() * (q - centre).length() + e
        })
        .fold(0.0, f64::max)
        * (1.0 + ROUNDING);
    let reach = edges
        .iter()
        .flat_map(|&e| poly.edges[e as usize].v)
        .map(|v| (poly.vertices[v as usize] - centre).length())
        .fold(0.0, f64::max)
        * (1.0 + ROUNDING);
    Node {
        axis,
        cos_a,
        sin_a,
        centre,
        slack: r + tol + ROUNDING * (centre.length() + r),
        reach,
        next: 0,
        start: 0,
        count: 0,
    }
}

/// Reusable buffers of [`contour_edge_indices`].
#[derive(Clone, Debug, Default)]
pub struct ContourScratch {
    candidates: Vec<u32>,
    /// Use the scan even where the mesh has a hierarchy (the oracle of the tests).
    pub scan: bool,
    /// What the last query through the hierarchy did.
    pub stats: EdgeQueryStats,
}

/// The face plane of `poly` lies within `tol` of the point (the exact silhouette is
/// degenerate there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoplanarFace;

/// The indices of the contour edges of `poly` from `x` (001 Eq. 4.2: exactly one adjacent face
/// front-facing, `is_front_facing`) and of its boundary edges (an open mesh's image ends
/// there too; docs/silhouettes.md, "Open meshes"), ascending, into `out` (cleared first): through the
/// mesh's [`EdgeHierarchy`] where it has one, else by the scan; the same list either way.
/// With `tol = Some(t)`, first `Err(CoplanarFace)` if any face plane lies within `t` of `x`
/// (`t` at most [`coplanar_tolerance`] when the hierarchy is used).
pub fn contour_edge_indices(
    poly: &IndexedPolyhedron,
    x: DVec3,
    tol: Option<f64>,
    scratch: &mut ContourScratch,
    out: &mut Vec<u32>,
) -> Result<(), CoplanarFace> {
    out.clear();
    let front = |f: u32| poly.face_planes[f as usize].eval(x) > 0.0;
    // A boundary edge bounds the image of an open mesh whichever way its one face turns.
    let is_contour = |e: &crate::geometry::mesh::polyhedron::Edge| {
        e.faces[1] == NO_FACE || front(e.faces[0]) != front(e.faces[1])
    };
    match poly.index.edge_hierarchy.as_deref() {
        Some(h) if !scratch.scan && poly.index.edge_hierarchy_per_point => {
            scratch.candidates.clear();
            scratch.stats = h.candidates(x, &mut scratch.candidates);
            if let Some(t) = tol {
                debug_assert!(t <= coplanar_tolerance(poly));
                let near = |f: u32| f != NO_FACE && poly.face_planes[f as usize].eval(x).abs() <= t;
                if scratch.candidates.iter().any(|&e| {
                    let e = &poly.edges[e as usize];
                    near(e.faces[0]) || near(e.faces[1])
                }) {
                    return Err(CoplanarFace);
                }
            }
            out.extend(
                scratch
                    .candidates
                    .iter()
                    .copied()
                    .filter(|&e| is_contour(&poly.edges[e as usize])),
            );
            out.sort_unstable();
        }
        _ => {
            if let Some(t) = tol
                && poly.face_planes.iter().any(|p| p.eval(x).abs() <= t)
            {
                return Err(CoplanarFace);
            }
            out.extend(
                poly.edges
                    .iter()
                    .enumerate()
                    .filter(|(_, e)| is_contour(e))
                    .map(|(i, _)| i as u32),
            );
        }
    }
    Ok(())
}
