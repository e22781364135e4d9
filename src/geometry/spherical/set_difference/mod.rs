//! Set difference of planar polygons in homogeneous coordinates: `subject − clip`, the visible
//! part of a light after removing one occluder (000 Sect. 3.6, Alg. 1 line 12, Appendix).
//!
//! Greiner–Hormann clipping (1998) extended to degenerate intersections after Foster, Hormann
//! and Popa (2019), in three phases that are kept apart so that a debugger can show them one by
//! one ([`GreinerHormannSteps`]):
//!
//! 1. `find_intersections` (`intersections.rs`): every point where the boundaries meet becomes
//!    an intersection vertex in both vertex lists — proper crossings, vertices on edges (T),
//!    vertices on vertices (V); collinear overlaps are the runs between such vertices.
//! 2. `label_intersections` and `mark_entry_exit` (`labels.rs`): the side of every boundary
//!    fragment relative to the other polygon — inside, outside, or overlapping in the same or
//!    the opposite direction — from which the crossing / bouncing / delayed labels and the
//!    entry / exit flags follow; loops without intersections are classified by a
//!    winding-number test.
//! 3. `traverse` (`traversal.rs`): the result's loops, walking the subject forwards outside the
//!    clip and the clip backwards inside the subject, switching at crossings.
//!
//! Predicates are determinants of homogeneous points (`predicates.rs`), never divided by w, with
//! absolute tolerances on normalised determinants ([`EPS_LINE`], [`EPS_POINT`]) for contacts,
//! and every decision that raw signs would leave to rounding noise (a crossing of collinear
//! edges, a point on the line of an edge) made on the computed point instead. Features smaller
//! than the tolerances are folded onto points ([`COLLAPSE_RADIUS`]). The two ends of every
//! fragment are checked to agree on its side, and the traversal checks that every loop closes
//! ([`SetDifference::last_traversal_consistent`]). The algorithm, the degenerate cases and the
//! tolerances are described in `docs/set-difference.md`. All scratch storage
//! lives in [`SetDifference`] and is reused: once its vectors have grown,
//! [`SetDifference::subtract`] does not allocate (unless steps are recorded).

mod intersections;
mod labels;
mod predicates;
mod steps;
mod traversal;

pub use steps::{
    ChainKind, EdgePoint, FragmentSide, GreinerHormannSteps, IntersectionKind, IntersectionRecord,
    LabelRecord, Operand, OverlapChain, Transition, TraversalStep, TraversedLoop, UntouchedLoop,
    VertexLabel,
};

use crate::geometry::PlanarPolygon;
use glam::DVec3;
use intersections::Insertion;
use predicates::{coincident, unit_normal};

/// A point lies on a line (great circle) when the sine of its angular distance to it is below
/// this: 1e-12 rad, some ten thousand times the rounding error of a determinant of unit vectors
/// (≈ 1e-16), so that vertices snapped onto an edge, or computed twice from the same 3D data
/// in different orders, are recognised, and far below any feature the renderer can resolve.
pub const EPS_LINE: f64 = 1e-12;

/// Two points coincide when the sine of the angle between them is below this: 5e-13 rad.
/// Merging them moves a vertex, and the edges at it, by up to this much; keeping it at half of
/// [`EPS_LINE`] means that a vertex close enough to a moved edge to change sides was already
/// within the line tolerance of the original edge, i.e. a T-junction.
pub const EPS_POINT: f64 = 5e-13;

/// Features smaller than this (sine of angle), four times [`EPS_LINE`], are folded onto one
/// point: consecutive input vertices closer than this are merged on loading (edges shorter than
/// the tolerances). (Detours of one operand through an intersection point are removed within
/// a wider radius, `DETOUR_RADIUS`, and so are loops thinner than it.)
///
/// An edge shorter than a few [`EPS_LINE`] has a well-defined line, but the tolerance band
/// around that line is as wide as the edge is long, so "on the line" says nothing about the
/// edge: a vertex of the other operand near it is then on its line and also on the lines of
/// its neighbours, decided V by one test and T or X by another, and the labels of the
/// fragments around it contradict each other. Merging moves the boundary by less than this
/// radius (the area by less than half of it times the edge length).
pub const COLLAPSE_RADIUS: f64 = 4e-12;

/// A detour of one operand out of an intersection point and back whose vertices all lie within
/// this (sine of angle) of the point is removed (`finish_clusters`): it encloses less than
/// π·1e-18 sr, nothing any integral can see, while the tolerances of the clusters (a few
/// [`EPS_LINE`]) can make such a detour out of two crossings of one nearly horizontal arc with
/// the horizon, 1e-11 apart, whose labels then contradict each other. A long loop within this
/// of one great circle is a sliver of the same scale and is dropped on loading
/// (`on_one_great_circle`).
pub(crate) const DETOUR_RADIUS: f64 = 1e-9;

/// A fragment whose end points lie farther than this (sine of angle) from the line of its input
/// edge after snapping takes the normal of its own chord (see `finish_clusters`).
const EPS_ON_EDGE: f64 = 1e-15;

/// The neighbours of a vertex folded as straight (`fold_straight_vertices`) are at least this
/// far apart (sine of their angle).
const STRAIGHT_MIN_SINE: f64 = 1e-3;

/// A loop within [`DETOUR_RADIUS`] of one great circle and longer than this (sine of the
/// angle from its first node to its farthest) is a sliver (`on_one_great_circle`): along it,
/// nodes of its two sides lie within the detour radius of each other, where collapsing a
/// detour can fold it into a loop of no area whose labels contradict each other.
const SLIVER_LENGTH: f64 = 1e-8;

/// A vertex whose two edges leave it at an angle whose sine is below this is the tip of a
/// spike (`truncate_spikes`): near it, points within [`EPS_LINE`] of both edges' lines lie up
/// to `EPS_LINE / sine` from it, farther than the detour radius.
const SPIKE_MAX_SINE: f64 = 1e-3;

/// "No node".
const NONE: u32 = u32::MAX;

/// Whether a loop is a sliver with no area the tolerances can resolve: every node within
/// [`COLLAPSE_RADIUS`] (or [`DETOUR_RADIUS`], for a loop longer than [`SLIVER_LENGTH`]) of one
/// great circle (the circle through the first node and the node farthest from it, short of its
/// antipode), going along it and back. A loop that goes once around the circle (the horizon
/// itself: a hemisphere) is kept, and so is one that spans no such pair.
fn on_one_great_circle(nodes: &[Node]) -> bool {
    let a = nodes[0].dir;
    // a × (q − a), not a × q: for nodes close together, the rounding of a × q is as large as
    // the loop's width relative to its length.
    let Some(far) = nodes[1..]
        .iter()
        .map(|q| a.cross(q.dir - a))
        .max_by(|p, q| p.length_squared().total_cmp(&q.length_squared()))
    else {
        return false;
    };
    let Some(n) = far.try_normalize() else {
        return false;
    };
    // Thinner than the collapse radius; or than the detour radius and long (a small loop of
    // some width, a hole of 1e-9 rad, is a feature the tolerances resolve).
    let width = if far.length() > SLIVER_LENGTH {
        DETOUR_RADIUS
    } else {
        COLLAPSE_RADIUS
    };
    if !nodes.iter().all(|q| n.dot(q.dir).abs() < width) {
        return false;
    }
    // The angle swept about n: ±2π around the circle, 0 there and back.
    let m = nodes.len();
    let swept: f64 = (0..m)
        .map(|k| {
            let (p, q) = (nodes[k].dir, nodes[(k + 1) % m].dir);
            n.dot(p.cross(q)).atan2(p.dot(q))
        })
        .sum();
    swept.abs() < std::f64::consts::PI
}

/// Whether `v` lies within [`EPS_LINE`] of the great circle through its neighbours `a` and
/// `b` (a straight vertex, `fold_straight_vertices`). Only where the neighbours are far enough
/// apart (and from antipodal) for the circle through them to be known well below EPS_LINE: its
/// normal's rounding over |a × b| is then below 1e-13. Squared: no square root or division.
fn is_straight(a: DVec3, v: DVec3, b: DVec3) -> bool {
    let c = a.cross(b);
    let len2 = c.length_squared();
    let along = c.dot(v);
    len2 > STRAIGHT_MIN_SINE * STRAIGHT_MIN_SINE && along * along < EPS_LINE * EPS_LINE * len2
}

/// The tangents at `v` toward `a` and `b` (unit directions), from the differences a − v and
/// b − v so that short edges keep their precision.
fn tangents(a: DVec3, v: DVec3, b: DVec3) -> (DVec3, DVec3) {
    let (da, db) = (a - v, b - v);
    (da - v * v.dot(da), db - v * v.dot(db))
}

/// Whether the corner `v` between its neighbours `a` and `b` is the tip of a spike: its edges
/// leave it at an angle θ with sin θ below [`SPIKE_MAX_SINE`] (sin θ |t_a| |t_b| = (t_a × t_b)·v
/// and cos θ |t_a| |t_b| = t_a·t_b for the tangents; squared, with no square root).
fn is_spike(a: DVec3, v: DVec3, b: DVec3) -> bool {
    let (ta, tb) = tangents(a, v, b);
    let sin = ta.cross(tb).dot(v);
    ta.dot(tb) > 0.0
        && sin * sin < SPIKE_MAX_SINE * SPIKE_MAX_SINE * ta.length_squared() * tb.length_squared()
}

/// Side of the fragment leaving a node (see [`FragmentSide`]); `Unknown` before phase 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Status {
    Unknown,
    Inside,
    Outside,
    OverlapSame,
    OverlapOpposite,
}

impl Status {
    fn public(self) -> FragmentSide {
        match self {
            Status::Inside | Status::Unknown => FragmentSide::Inside,
            Status::Outside => FragmentSide::Outside,
            Status::OverlapSame => FragmentSide::OverlapSame,
            Status::OverlapOpposite => FragmentSide::OverlapOpposite,
        }
    }

    fn is_overlap(self) -> bool {
        matches!(self, Status::OverlapSame | Status::OverlapOpposite)
    }
}

/// A vertex of either operand's doubly linked list (original vertices first, then the
/// intersection vertices inserted by phase 1). The fragment "of" a node is the piece of
/// boundary from the node to its successor.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// Homogeneous coordinates written to the output (the input vertex, bit for bit, for
    /// original vertices; the shared position for every node of an intersection cluster).
    pos: DVec3,
    /// `pos` normalised: the point of the unit hemisphere every predicate uses.
    dir: DVec3,
    /// Unit normal of the input edge containing the fragment arriving at the node.
    n_in: DVec3,
    /// Unit normal of the input edge containing the node's fragment.
    n_out: DVec3,
    next: u32,
    prev: u32,
    /// Successor in the input loop (original nodes only; phase 1 works on input edges).
    orig_next: u32,
    /// Union–find parent during phase 1, then the cluster's representative (its smallest node
    /// index); `NONE` for vertices that are not intersections.
    cluster: u32,
    /// Next node of the same cluster (a circular list).
    ring: u32,
    /// Index into `SetDifference::loops`.
    loop_slot: u32,
    /// Index (within its input loop) of the vertex starting the input edge of the fragment.
    vertex: u32,
    operand: Operand,
    /// Created by phase 1 inside an input edge.
    inserted: bool,
    status: Status,
    visited: bool,
    /// Absorbed into its predecessor by phase 1 (see `finish_clusters`): no longer in the list.
    removed: bool,
}

/// A loop of one operand: original nodes `input_first..input_first + len`, linked through
/// `orig_next` as loaded; `first` is a live node of the loop for traversal (phase 1 may fold
/// the original first node into a cluster node outside that range).
#[derive(Clone, Copy, Debug)]
struct LoopInfo {
    first: u32,
    input_first: u32,
    len: u32,
    /// Index of the loop in the input polygon.
    input_loop: u32,
}

/// Workspace of the set difference. Create it once per thread and call
/// [`SetDifference::subtract`] for every shading point and occluder: its buffers are reused.
#[derive(Clone, Debug, Default)]
pub struct SetDifference {
    nodes: Vec<Node>,
    loops: Vec<LoopInfo>,
    /// Subject nodes are `0..subject_nodes`, clip nodes `subject_nodes..subject_nodes +
    /// clip_nodes` (before phase 1 appends inserted nodes).
    subject_nodes: usize,
    clip_nodes: usize,
    /// Subject loops are `loops[..subject_loops]`.
    subject_loops: usize,
    /// `side_sc[i * nc + j]`: signed distance (sine) of subject vertex i to the line of clip
    /// edge j; `side_cs[j * ns + i]` the converse.
    side_sc: Vec<f64>,
    side_cs: Vec<f64>,
    /// Contact flags of subject vertex i with clip vertex / edge j, and of clip vertex j with
    /// subject edge i (see `intersections.rs`).
    contact_sc: Vec<u8>,
    contact_cs: Vec<u8>,
    /// Indices into `side_sc` / `side_cs` of the pairs close enough for a contact.
    near_sc: Vec<u32>,
    near_cs: Vec<u32>,
    insertions: Vec<Insertion>,
    insertion_nodes: Vec<u32>,
    /// First live node of each cluster, indexed by the union–find representative.
    cluster_rep: Vec<u32>,
    loop_scratch: Vec<DVec3>,
    /// A loop's nodes while its spikes are truncated (`truncate_spikes`).
    spike_scratch: Vec<Node>,
    /// This load folded the straight vertices and cut the spikes' tips
    /// (`fold_straight_vertices`, `truncate_spikes`).
    cleaned: bool,
    /// Phase 1 found a contact at a straight vertex or on both edges of a spike, left as they
    /// were: the operands are loaded again, cleaned.
    needs_cleaning: bool,
    consistent: bool,
    /// Set by a walk over the nodes that took more steps than [`SetDifference::walk_bound`]
    /// (a loop, ring or detour that rounding left unclosed): the difference is then not
    /// trusted, and the caller takes a path that is exact there.
    bound_crossed: std::cell::Cell<bool>,
    /// A lower bound for the walks than the node count, for tests of what a crossing does:
    /// (steps, for clips of more than this many vertices).
    walk_limit: Option<(usize, usize)>,
}

impl SetDifference {
    pub fn new() -> Self {
        Self::default()
    }

    /// `out = subject − clip`.
    ///
    /// Both inputs are sets of closed loops of homogeneous points with w ≥ 0 (filled loops
    /// counter-clockwise, holes clockwise, loops not crossing each other, every edge a
    /// great-circle arc shorter than π); points on the horizon (w = 0) and edges along it are
    /// ordinary input. Consecutive vertices closer than [`COLLAPSE_RADIUS`] are merged. The
    /// output follows the same conventions; loops may touch each other at isolated vertices but
    /// never cross. When `steps` is `Some`, the three phases are recorded into it (this
    /// allocates); otherwise nothing extra is computed.
    pub fn subtract(
        &mut self,
        subject: &PlanarPolygon,
        clip: &PlanarPolygon,
        out: &mut PlanarPolygon,
        mut steps: Option<&mut GreinerHormannSteps>,
    ) {
        if let Some(s) = steps.as_deref_mut() {
            s.clear();
        }
        out.clear();
        #[cfg(feature = "speed-guard-selftest")]
        for _ in 0..3 {
            // The speed guard's test of itself (scripts/speed_guard_selftest.sh): the loading
            // and the first phase done three more times, a slowdown the guard must report.
            self.load(subject, clip, false);
            if self.subject_nodes != 0 {
                self.find_intersections(None);
            }
        }
        self.consistent = true;
        self.bound_crossed.set(false);
        self.load(subject, clip, false);
        if self.subject_nodes == 0 {
            return;
        }
        self.find_intersections(steps.as_deref_mut());
        if self.needs_cleaning {
            // A contact at a straight vertex, or a vertex on both edges of a spike sharper than
            // the tolerances resolve: start over with the straight vertices folded and the
            // spikes' tips cut. Rare (phase 1 looks only at the few pairs within the line
            // tolerance), so the common load pays nothing for either.
            if let Some(s) = steps.as_deref_mut() {
                s.clear();
            }
            self.load(subject, clip, true);
            if self.subject_nodes == 0 {
                return;
            }
            self.find_intersections(steps.as_deref_mut());
        }
        self.label_intersections();
        self.mark_entry_exit(steps.as_deref_mut());
        self.traverse(out, steps);
        if self.bound_crossed.get() {
            out.clear();
            self.consistent = false;
        }
    }

    /// True when a walk of the last [`SetDifference::subtract`] crossed its bound: its output
    /// is empty and must not be used.
    pub fn last_bound_crossed(&self) -> bool {
        self.bound_crossed.get()
    }

    /// The bound of every walk over the nodes: along a loop (`next`), around a cluster's ring
    /// (`ring`), or over a detour, each node is visited at most once, so no walk takes more
    /// than one step per node.
    #[inline]
    fn walk_bound(&self) -> usize {
        match self.walk_limit {
            Some((steps, clip_vertices)) if self.clip_nodes > clip_vertices => {
                steps.min(self.nodes.len())
            }
            _ => self.nodes.len(),
        }
    }

    /// Caps every walk at `steps` where the clip has more than `clip_vertices` vertices
    /// (tests only: a walk of a correct structure then crosses its bound, which shows what a
    /// crossing does to the callers).
    #[doc(hidden)]
    pub fn limit_walks(&mut self, cap: Option<(usize, usize)>) {
        self.walk_limit = cap;
    }

    /// One step of a walk with `left` steps of its bound left: false (and the crossing
    /// recorded) when none is left.
    #[inline]
    fn step(&self, left: &mut usize) -> bool {
        if *left == 0 {
            self.bound_crossed.set(true);
            return false;
        }
        *left -= 1;
        true
    }

    /// False when the last [`SetDifference::subtract`] found its labelling inconsistent (the
    /// two ends of a fragment disagreeing on its side, or a dead end in the traversal) and
    /// dropped a loop. Not observed for inputs that satisfy the preconditions (every test checks
    /// it); possible for self-intersecting input.
    pub fn last_traversal_consistent(&self) -> bool {
        self.consistent
    }

    /// Original node `c`'s direction between those of its neighbours in its loop.
    fn corner(&self, c: usize) -> (DVec3, DVec3, DVec3) {
        let node = &self.nodes[c];
        (
            self.nodes[node.prev as usize].dir,
            node.dir,
            self.nodes[node.orig_next as usize].dir,
        )
    }

    /// Whether original node `c` is the tip of a spike of its loop (see [`is_spike`]).
    fn node_is_spike(&self, c: usize) -> bool {
        let (a, b, d) = self.corner(c);
        is_spike(a, b, d)
    }

    /// Whether original node `c` is a straight vertex of its loop (see [`is_straight`]).
    fn node_is_straight(&self, c: usize) -> bool {
        let (a, b, d) = self.corner(c);
        is_straight(a, b, d)
    }

    /// Total capacity of the scratch buffers, in elements (for allocation tests and tuning).
    pub fn scratch_capacity(&self) -> usize {
        self.nodes.capacity()
            + self.loops.capacity()
            + self.side_sc.capacity()
            + self.side_cs.capacity()
            + self.contact_sc.capacity()
            + self.contact_cs.capacity()
            + self.near_sc.capacity()
            + self.near_cs.capacity()
            + self.insertions.capacity()
            + self.insertion_nodes.capacity()
            + self.cluster_rep.capacity()
            + self.loop_scratch.capacity()
            + self.spike_scratch.capacity()
    }

    /// Builds the vertex lists of both operands; `clean`: with their straight vertices folded
    /// and the tips of their spikes cut (`fold_straight_vertices`, `truncate_spikes`).
    fn load(&mut self, subject: &PlanarPolygon, clip: &PlanarPolygon, clean: bool) {
        self.cleaned = clean;
        self.nodes.clear();
        self.loops.clear();
        self.push_operand(subject, Operand::Subject);
        self.subject_nodes = self.nodes.len();
        self.subject_loops = self.loops.len();
        self.push_operand(clip, Operand::Clip);
        self.clip_nodes = self.nodes.len() - self.subject_nodes;
    }

    fn push_operand(&mut self, poly: &PlanarPolygon, operand: Operand) {
        for (input_loop, lp) in poly.loops().enumerate() {
            let first = self.nodes.len();
            let slot = self.loops.len() as u32;
            for (k, &v) in lp.iter().enumerate() {
                // The pipeline's points are unit vectors; a length within 1e-14 of one changes
                // the tolerances by a relative 1e-14 and needs no normalisation.
                let len2 = v.length_squared();
                let dir = if (len2 - 1.0).abs() < 1e-14 {
                    v
                } else {
                    v.normalize_or_zero()
                };
                if !dir.is_finite() || dir == DVec3::ZERO {
                    continue;
                }
                // Edges shorter than the tolerances are folded (see COLLAPSE_RADIUS).
                if self.nodes.len() > first
                    && coincident(self.nodes[self.nodes.len() - 1].dir, dir, COLLAPSE_RADIUS)
                {
                    continue;
                }
                self.nodes.push(Node {
                    pos: v,
                    dir,
                    n_in: DVec3::ZERO,
                    n_out: DVec3::ZERO,
                    next: NONE,
                    prev: NONE,
                    orig_next: NONE,
                    cluster: NONE,
                    ring: NONE,
                    loop_slot: slot,
                    vertex: k as u32,
                    operand,
                    inserted: false,
                    status: Status::Unknown,
                    visited: false,
                    removed: false,
                });
            }
            while self.nodes.len() > first + 1
                && coincident(
                    self.nodes[self.nodes.len() - 1].dir,
                    self.nodes[first].dir,
                    COLLAPSE_RADIUS,
                )
            {
                self.nodes.pop();
            }
            if self.cleaned {
                self.fold_straight_vertices(first);
                self.truncate_spikes(first);
            }
            let len = self.nodes.len() - first;
            if len < 3 || on_one_great_circle(&self.nodes[first..]) {
                // No area: a sliver thinner than the tolerances (a face seen edge-on, a loop
                // folded onto the horizon) is folded away like a short edge.
                self.nodes.truncate(first);
                continue;
            }
            self.link_loop(first, len, input_loop);
        }
    }

    /// Removes the vertices of the loop from `first` to the end of `nodes` that lie within
    /// [`EPS_LINE`] of the great circle through their neighbours: a straight angle, or a spike
    /// of no width. Such a vertex adds nothing to the region, but it is on the line of both its
    /// edges, so a vertex of the other operand near it would be decided on one edge by one test
    /// and on the other by the next, and the labels around it would contradict each other (a
    /// clip whose horizon-clipped outline runs through one of its own vertices). Each test
    /// removes a vertex or keeps one for good: at most two passes over the loop.
    fn fold_straight_vertices(&mut self, first: usize) {
        // Most loops have none: find that out without moving a node.
        let end = self.nodes.len();
        let n = end - first;
        let dir = |k: usize| self.nodes[first + k % n].dir;
        if n < 3 || !(0..n).any(|k| is_straight(dir(k + n - 1), dir(k), dir(k + 1))) {
            return;
        }
        // A stack over the loop: the kept vertices are `first..top`.
        let mut top = first;
        for i in first..self.nodes.len() {
            let v = self.nodes[i];
            // Bound: each pop removes one kept vertex.
            while top >= first + 2
                && is_straight(self.nodes[top - 2].dir, self.nodes[top - 1].dir, v.dir)
            {
                top -= 1;
            }
            if top != i {
                self.nodes[top] = v;
            }
            top += 1;
        }
        // Around the closing point: the last vertices against the first, and the first against
        // the last.
        let mut start = first;
        // Bound: each step removes a vertex; at most the loop's length.
        loop {
            if top - start < 3 {
                break;
            }
            if is_straight(
                self.nodes[top - 2].dir,
                self.nodes[top - 1].dir,
                self.nodes[start].dir,
            ) {
                top -= 1;
            } else if is_straight(
                self.nodes[top - 1].dir,
                self.nodes[start].dir,
                self.nodes[start + 1].dir,
            ) {
                start += 1;
            } else {
                break;
            }
        }
        if start > first {
            self.nodes.copy_within(start..top, first);
            top -= start - first;
        }
        self.nodes.truncate(top);
    }

    /// Cuts the tip off every spike of the loop from `first` to the end of `nodes`: a vertex
    /// whose edges leave it at an angle θ with sin θ below [`SPIKE_MAX_SINE`] is replaced by
    /// the two points of its edges at the distance r = 2 [`COLLAPSE_RADIUS`] / sin θ from it,
    /// where the spike is as wide as twice the collapse radius.
    ///
    /// Within r of the tip the spike is narrower than that, and within `EPS_LINE / sin θ` a
    /// point lies within the line tolerance of both edges: a vertex of the other operand
    /// there would be taken for the tip itself (the corner rule of `intersections.rs`) and
    /// moved by up to that distance, far more than any tolerance (an occluder's face seen
    /// nearly edge-on, with a corner of 1e-6 rad, moved a light's vertex 1e-6 rad and put its
    /// far corners into the visible polygon). The tip cut off has an area of about
    /// r² sin θ / 2 = 2 [`COLLAPSE_RADIUS`]² / sin θ, a spike no wider than twice the collapse
    /// radius. A spike whose r would reach past half of one of its edges is left alone (it is
    /// a sliver, or the loop is).
    fn truncate_spikes(&mut self, first: usize) {
        let n = self.nodes.len() - first;
        if n < 3 {
            return;
        }
        let dir = |k: usize| self.nodes[first + k % n].dir;
        if !(0..n).any(|k| is_spike(dir(k + n - 1), dir(k), dir(k + 1))) {
            return;
        }
        self.spike_scratch.clear();
        self.spike_scratch.extend_from_slice(&self.nodes[first..]);
        self.nodes.truncate(first);
        for k in 0..n {
            let node = self.spike_scratch[k];
            let (a, v, b) = (
                self.spike_scratch[(k + n - 1) % n].dir,
                node.dir,
                self.spike_scratch[(k + 1) % n].dir,
            );
            if !is_spike(a, v, b) {
                self.nodes.push(node);
                continue;
            }
            let (ta, tb) = tangents(a, v, b);
            let (la, lb) = (ta.length(), tb.length());
            let sin = (ta.cross(tb).dot(v) / (la * lb))
                .abs()
                .max(f64::MIN_POSITIVE);
            let r = 2.0 * COLLAPSE_RADIUS / sin;
            // The edges' angles: |t| is the sine of each for unit vectors.
            if r >= 0.5 * la.atan2(v.dot(a)) || r >= 0.5 * lb.atan2(v.dot(b)) {
                self.nodes.push(node);
                continue;
            }
            let (sr, cr) = r.sin_cos();
            for t in [ta / la, tb / lb] {
                let p = v * cr + t * sr;
                self.nodes.push(Node {
                    pos: p,
                    dir: p,
                    ..node
                });
            }
        }
    }

    /// Links the `n` nodes from `first` into one loop (doubly linked, with the unit normals of
    /// its edges) and records it.
    fn link_loop(&mut self, first: usize, n: usize, input_loop: usize) {
        let slot = self.loops.len() as u32;
        for k in 0..n {
            let i = first + k;
            let j = first + (k + 1) % n;
            let m = unit_normal(self.nodes[i].dir, self.nodes[j].dir);
            self.nodes[i].n_out = m;
            self.nodes[i].next = j as u32;
            self.nodes[i].orig_next = j as u32;
            self.nodes[i].loop_slot = slot;
            self.nodes[j].n_in = m;
            self.nodes[j].prev = i as u32;
        }
        self.loops.push(LoopInfo {
            first: first as u32,
            input_first: first as u32,
            len: n as u32,
            input_loop: input_loop as u32,
        });
    }

    /// Loops of one operand, as a range of `self.loops`.
    fn loop_range(&self, operand: Operand) -> std::ops::Range<usize> {
        match operand {
            Operand::Subject => 0..self.subject_loops,
            Operand::Clip => self.subject_loops..self.loops.len(),
        }
    }

    /// Union–find root of a node, making the node a cluster of its own on first use. A parent
    /// always has a smaller index than its child ([`SetDifference::union`]), so the walk to the
    /// root ends within `x` steps.
    fn find(&mut self, mut x: u32) -> u32 {
        if self.nodes[x as usize].cluster == NONE {
            self.nodes[x as usize].cluster = x;
            return x;
        }
        while self.nodes[x as usize].cluster != x {
            let p = self.nodes[x as usize].cluster;
            let gp = self.nodes[p as usize].cluster;
            self.nodes[x as usize].cluster = gp;
            x = gp;
        }
        x
    }

    /// Puts two nodes into the same intersection cluster; the smallest index represents it.
    fn union(&mut self, a: u32, b: u32) {
        let ra = self.find(a);
        let rb = self.find(b);
        if ra < rb {
            self.nodes[rb as usize].cluster = ra;
        } else if rb < ra {
            self.nodes[ra as usize].cluster = rb;
        }
    }

    /// The loop and edge of a node, as reported in [`GreinerHormannSteps`].
    fn edge_point(&self, node: u32, t: f64) -> EdgePoint {
        let n = &self.nodes[node as usize];
        EdgePoint {
            loop_index: self.loops[n.loop_slot as usize].input_loop,
            edge: n.vertex,
            t,
        }
    }
}
