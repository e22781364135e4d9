//! What the three phases did, for the debugger (`GreinerHormannSteps`).
//!
//! Nothing here is computed unless the caller passes `Some(&mut steps)` to
//! [`SetDifference::subtract`](super::SetDifference::subtract).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Which input of `subject − clip` a record refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Operand {
    /// The polygon being clipped (the light, or what is left of it).
    Subject,
    /// The polygon subtracted (an occluder).
    Clip,
}

impl Operand {
    /// The other input.
    #[inline]
    pub(crate) fn other(self) -> Operand {
        match self {
            Operand::Subject => Operand::Clip,
            Operand::Clip => Operand::Subject,
        }
    }
}

/// How the boundaries meet at an intersection vertex found by phase 1 (Foster, Hormann and
/// Popa 2019 call these X-, T- and V-intersections; overlaps are pairs of them, see
/// [`FragmentSide::OverlapSame`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum IntersectionKind {
    /// The edges cross at a point interior to both (the only case of Greiner–Hormann 1998).
    Crossing,
    /// A subject vertex lies in the interior of a clip edge (T-junction).
    SubjectVertexOnClipEdge,
    /// A clip vertex lies in the interior of a subject edge (T-junction).
    ClipVertexOnSubjectEdge,
    /// A subject vertex coincides with a clip vertex.
    VertexOnVertex,
}

/// A point on an input edge: loop `loop_index` of the operand, the edge starting at vertex
/// `edge` of that loop, and the homogeneous parameter `t` ∈ [0, 1) of the point on it
/// (p ∝ (1 − t)·a + t·b for unit endpoints a, b; monotone along the arc, 0 at the start vertex).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct EdgePoint {
    pub loop_index: u32,
    pub edge: u32,
    pub t: f64,
}

/// One intersection vertex of phase 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntersectionRecord {
    /// Homogeneous position (unit length for computed crossings, the input vertex otherwise).
    pub position: DVec3,
    pub kind: IntersectionKind,
    pub subject: EdgePoint,
    pub clip: EdgePoint,
}

/// Where a piece of one operand's boundary (between two consecutive vertices after phase 1)
/// lies relative to the other operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum FragmentSide {
    /// Inside the other operand ("left" of its oriented boundary, in FHP's words).
    Inside,
    /// Outside the other operand ("right").
    Outside,
    /// On an edge of the other operand, both traversing it in the same direction: the two
    /// interiors lie on the same side.
    OverlapSame,
    /// On an edge of the other operand traversed in the opposite direction: the interiors lie
    /// on opposite sides.
    OverlapOpposite,
}

impl FragmentSide {
    #[inline]
    pub fn is_overlap(self) -> bool {
        matches!(
            self,
            FragmentSide::OverlapSame | FragmentSide::OverlapOpposite
        )
    }
}

/// The local label of an intersection vertex from the sides of the fragments before and after
/// it (Foster, Hormann and Popa 2019, Sect. 3.2; "left" = inside the other operand, "on" = an
/// overlap).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum VertexLabel {
    /// Inside → outside or outside → inside.
    Crossing,
    /// Touches the other boundary and stays on the same side.
    Bouncing,
    /// Arrives from inside, continues along an overlap.
    LeftOn,
    /// Arrives from outside, continues along an overlap.
    RightOn,
    /// Inside an overlap chain.
    OnOn,
    /// Leaves an overlap to the inside.
    OnLeft,
    /// Leaves an overlap to the outside.
    OnRight,
}

/// Entry into or exit from the other operand along the operand's own direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Transition {
    Entry,
    Exit,
}

/// Phase 2 result for one intersection vertex of one operand.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LabelRecord {
    pub operand: Operand,
    /// Loop of the operand and the edge (start vertex index) the vertex lies on.
    pub loop_index: u32,
    pub edge: u32,
    pub position: DVec3,
    /// Side of the fragment arriving at the vertex.
    pub before: FragmentSide,
    /// Side of the fragment leaving the vertex.
    pub after: FragmentSide,
    pub label: VertexLabel,
    /// For crossings: entry or exit (toggling Greiner–Hormann's flag). `None` otherwise.
    pub transition: Option<Transition>,
}

/// How an overlap chain (a maximal run of overlapping fragments) is passed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ChainKind {
    /// Arrives from one side and leaves to the other.
    DelayedCrossing,
    /// Arrives from and leaves to the same side.
    DelayedBouncing,
    /// The whole loop lies on the other operand's boundary (e.g. identical polygons).
    WholeLoop,
}

/// Phase 2 result for one overlap chain of one operand: labels `first_label..=last_label`
/// (indices into [`GreinerHormannSteps::labels`], cyclically within the loop).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OverlapChain {
    pub operand: Operand,
    pub loop_index: u32,
    pub first_label: u32,
    pub last_label: u32,
    pub kind: ChainKind,
    /// Whether the chain's first fragment runs along the other boundary in the same direction.
    pub same_direction: bool,
    /// For delayed crossings: whether the chain as a whole enters or leaves the other operand.
    pub transition: Option<Transition>,
}

/// A loop without any intersection vertex, classified by a winding-number test.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UntouchedLoop {
    pub operand: Operand,
    pub loop_index: u32,
    /// Whether the loop lies inside the other operand.
    pub inside_other: bool,
    /// Whether it is part of the result (subject loops outside the clip; clip loops inside the
    /// subject, reversed).
    pub kept: bool,
}

/// One fragment of an output loop: a piece of an input edge, walked forwards (subject) or
/// backwards (clip).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraversalStep {
    pub operand: Operand,
    pub loop_index: u32,
    /// Start vertex index (within the loop) of the input edge the fragment lies on.
    pub edge: u32,
    /// True when the fragment is walked against the edge's direction (clip fragments).
    pub reversed: bool,
    pub from: DVec3,
    pub to: DVec3,
}

/// Phase 3 result: one output loop in traversal order.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraversedLoop {
    pub steps: Vec<TraversalStep>,
    /// Number of vertices written for the loop (collinear pass-through vertices are dropped).
    pub vertex_count: u32,
}

/// The three phases of one `subject − clip`, recorded for the debugger.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct GreinerHormannSteps {
    /// Phase 1: every intersection vertex with its degeneracy kind, in discovery order
    /// (vertex-on-vertex, subject vertex on clip edge, clip vertex on subject edge, crossings).
    pub intersections: Vec<IntersectionRecord>,
    /// Phase 2: labels of the intersection vertices of the subject, then of the clip, each
    /// loop in order.
    pub labels: Vec<LabelRecord>,
    /// Phase 2: overlap chains resolved into delayed crossings / bouncings.
    pub chains: Vec<OverlapChain>,
    /// Phase 2: loops without intersections, classified by containment.
    pub untouched_loops: Vec<UntouchedLoop>,
    /// Phase 3: the output loops in the order they were written.
    pub traversal: Vec<TraversedLoop>,
    /// False when the traversal met an inconsistency and dropped a loop (not expected; the
    /// same flag is available without recording from
    /// [`SetDifference::last_traversal_consistent`](super::SetDifference::last_traversal_consistent)).
    pub consistent: bool,
}

impl GreinerHormannSteps {
    /// Empties every record, keeping the capacities.
    pub(crate) fn clear(&mut self) {
        self.intersections.clear();
        self.labels.clear();
        self.chains.clear();
        self.untouched_loops.clear();
        self.traversal.clear();
        self.consistent = true;
    }
}
