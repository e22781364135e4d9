//! Phase 3: traversal (Greiner–Hormann phase three for `subject − clip`).
//!
//! The boundary of the difference consists of the subject's fragments outside the clip or on
//! it in the opposite direction (the interiors lie on opposite sides, so the edge stays a
//! boundary), walked forwards, and the clip's fragments inside the subject, walked backwards.
//! Overlaps in the same direction bound neither side and are dropped. Starting from any unused
//! kept fragment, the walk follows its operand through ordinary vertices; at an intersection
//! point it takes the kept fragment leaving the point — on the same operand at a bouncing
//! vertex, on the other one at a crossing, or at the right end of an overlap chain (the end of
//! a delayed crossing where the chain's other operand turns away).
//!
//! When several kept fragments leave one point (the polygons touch there, e.g. a clip vertex
//! touching a subject edge from inside), the walk takes the first one clockwise from the
//! direction it arrived from: the region lies to the left of the boundary, so this keeps each
//! passage through the point around a single interior sector and the loops touch without
//! crossing.

use super::predicates::{clockwise_before, tangent};
use super::{
    GreinerHormannSteps, NONE, Operand, SetDifference, Status, TraversalStep, TraversedLoop,
};
use crate::geometry::PlanarPolygon;
use glam::DVec3;

impl SetDifference {
    /// Whether the fragment of node f belongs to the boundary of `subject − clip`.
    #[inline]
    fn kept(&self, f: u32) -> bool {
        let node = &self.nodes[f as usize];
        match node.operand {
            Operand::Subject => matches!(node.status, Status::Outside | Status::OverlapOpposite),
            Operand::Clip => node.status == Status::Inside,
        }
    }

    /// Node where the walk along fragment f starts and ends (clip fragments run backwards).
    #[inline]
    fn ends(&self, f: u32) -> (u32, u32) {
        let node = &self.nodes[f as usize];
        match node.operand {
            Operand::Subject => (f, node.next),
            Operand::Clip => (node.next, f),
        }
    }

    /// Unit normal of fragment f's line in the direction of the walk.
    #[inline]
    fn walk_normal(&self, f: u32) -> DVec3 {
        let node = &self.nodes[f as usize];
        match node.operand {
            Operand::Subject => node.n_out,
            Operand::Clip => -node.n_out,
        }
    }

    /// The fragment the walk continues with after arriving at node `end` along fragment f, or
    /// `NONE` when no kept fragment leaves the point.
    fn successor(&self, f: u32, end: u32) -> u32 {
        let node = &self.nodes[end as usize];
        if node.cluster == NONE {
            // An ordinary vertex: the side cannot change, the walk stays on its operand.
            return match node.operand {
                Operand::Subject => end,
                Operand::Clip => node.prev,
            };
        }
        // Kept fragments leaving the intersection point: forward subject fragments of the
        // cluster's subject nodes, backward clip fragments of its clip nodes.
        let x = node.dir;
        let back = -tangent(self.walk_normal(f), x);
        let mut best = NONE;
        let mut best_tangent = DVec3::ZERO;
        let mut k = end;
        let mut left = self.walk_bound();
        loop {
            if !self.step(&mut left) {
                return NONE;
            }
            let q = &self.nodes[k as usize];
            let g = match q.operand {
                Operand::Subject => k,
                Operand::Clip => q.prev,
            };
            if self.kept(g) {
                let u = tangent(self.walk_normal(g), x);
                if best == NONE || clockwise_before(x, back, u, best_tangent) {
                    best = g;
                    best_tangent = u;
                }
            }
            k = q.ring;
            if k == end {
                break;
            }
        }
        best
    }

    /// Phase 3: writes the loops of `subject − clip` into `out`.
    pub(super) fn traverse(
        &mut self,
        out: &mut PlanarPolygon,
        mut steps: Option<&mut GreinerHormannSteps>,
    ) {
        for node in &mut self.nodes {
            node.visited = false;
        }
        for f0 in 0..self.nodes.len() as u32 {
            let node = &self.nodes[f0 as usize];
            if node.visited || node.removed || !self.kept(f0) {
                continue;
            }
            let mut record = steps.as_ref().map(|_| TraversedLoop::default());
            self.loop_scratch.clear();
            let mut f = f0;
            // Each step marks an unvisited fragment and stops at a visited one: at most one
            // step per node.
            let closed = loop {
                self.nodes[f as usize].visited = true;
                let (start, end) = self.ends(f);
                let g = self.successor(f, end);
                if let Some(r) = record.as_mut() {
                    let node = &self.nodes[f as usize];
                    r.steps.push(TraversalStep {
                        operand: node.operand,
                        loop_index: self.loops[node.loop_slot as usize].input_loop,
                        edge: node.vertex,
                        reversed: node.operand == Operand::Clip,
                        from: self.nodes[start as usize].pos,
                        to: self.nodes[end as usize].pos,
                    });
                }
                if g == NONE {
                    break false;
                }
                // The vertex between f and g, unless the walk just passes an inserted vertex
                // along the same input edge.
                let junction = self.ends(g).0;
                let node = &self.nodes[junction as usize];
                if !(junction == end && node.inserted)
                    && self.loop_scratch.last() != Some(&node.pos)
                {
                    self.loop_scratch.push(node.pos);
                }
                if g == f0 {
                    break true;
                }
                if self.nodes[g as usize].visited {
                    break false;
                }
                f = g;
            };
            if !closed {
                self.consistent = false;
                continue;
            }
            while self.loop_scratch.len() > 1
                && self.loop_scratch.last() == self.loop_scratch.first()
            {
                self.loop_scratch.pop();
            }
            // The last vertex written is the start of f0: write it first, so that a loop
            // without intersections comes out exactly as it went in.
            if let Some((&last, rest)) = self.loop_scratch.split_last() {
                out.push_vertex(last);
                for &v in rest {
                    out.push_vertex(v);
                }
            }
            let written = if out.close_loop() {
                self.loop_scratch.len() as u32
            } else {
                0
            };
            if let (Some(s), Some(mut r)) = (steps.as_deref_mut(), record) {
                r.vertex_count = written;
                s.traversal.push(r);
            }
        }
        if let Some(s) = steps {
            s.consistent = self.consistent;
        }
    }
}
