//! Phase 2: labels and entry / exit flags.
//!
//! Greiner and Hormann mark each intersection vertex *entry* or *exit* by testing one vertex
//! for containment and toggling the flag at every intersection along the loop; Foster, Hormann
//! and Popa first label each intersection vertex locally (crossing, bouncing, or the start /
//! end / inside of an overlap chain, from the turn of the polygon's neighbours P⁻, P⁺ relative
//! to the other polygon's chain Q⁻, I, Q⁺), resolve overlap chains into delayed crossings or
//! bouncings, and toggle only at crossings.
//!
//! Here the local test is applied to each *fragment* (the boundary between two consecutive
//! nodes) leaving an intersection vertex: it is an overlap when the next node's cluster is
//! joined to this cluster by an edge of the other operand (same or opposite direction), and
//! otherwise inside or outside according to whether its tangent lies in the other operand's
//! interior sector at the vertex (FHP's left / right). Between intersection vertices the side
//! cannot change, so it is copied along the loop; this *is* the toggling of the entry / exit
//! flag, read off locally instead of propagated, so a single misjudged vertex cannot flip a
//! whole loop. Only loops without any intersection vertex need a containment test.

use super::predicates::{Ray, in_sector, tangent};
use super::{
    ChainKind, EPS_LINE, GreinerHormannSteps, LabelRecord, NONE, Operand, OverlapChain,
    SetDifference, Status, Transition, UntouchedLoop, VertexLabel,
};
use glam::DVec3;

impl SetDifference {
    /// Phase 2a: the side of every fragment leaving an intersection vertex.
    pub(super) fn label_intersections(&mut self) {
        for n in 0..self.nodes.len() {
            if self.nodes[n].cluster == NONE || self.nodes[n].removed {
                continue;
            }
            let status = self
                .overlap_status(n)
                .unwrap_or_else(|| self.sector_status(n));
            self.nodes[n].status = status;
        }
    }

    /// Whether the fragment of node n lies on an edge of the other operand: the clusters of n
    /// and of its successor are joined by a fragment of the other operand (both are arcs
    /// shorter than π between the same two points, hence the same arc).
    fn overlap_status(&self, n: usize) -> Option<Status> {
        let node = &self.nodes[n];
        let target = self.nodes[node.next as usize].cluster;
        if target == NONE {
            return None;
        }
        let mut k = n;
        let mut left = self.walk_bound();
        loop {
            if !self.step(&mut left) {
                return None;
            }
            let other = &self.nodes[k];
            if other.operand != node.operand {
                if self.nodes[other.next as usize].cluster == target {
                    return Some(Status::OverlapSame);
                }
                if self.nodes[other.prev as usize].cluster == target {
                    return Some(Status::OverlapOpposite);
                }
            }
            k = other.ring as usize;
            if k == n {
                return None;
            }
        }
    }

    /// Inside or outside: whether the fragment's tangent at the intersection point lies in the
    /// interior sector of the other operand at one of its nodes there (several when the other
    /// operand passes through the point more than once).
    fn sector_status(&self, n: usize) -> Status {
        let node = &self.nodes[n];
        self.side_of_tangent(n, tangent(node.n_out, node.dir))
    }

    /// Inside or outside for a tangent `d` at the intersection point of node n, relative to the
    /// other operand's nodes in n's cluster.
    fn side_of_tangent(&self, n: usize, d: DVec3) -> Status {
        let node = &self.nodes[n];
        let x = node.dir;
        let mut k = node.ring as usize;
        let mut left = self.walk_bound();
        while k != n && self.step(&mut left) {
            let other = &self.nodes[k];
            if other.operand != node.operand {
                let from = tangent(other.n_out, x);
                let to = -tangent(other.n_in, x);
                if in_sector(x, from, to, d) {
                    return Status::Inside;
                }
            }
            k = other.ring as usize;
        }
        Status::Outside
    }

    /// Phase 2b: copies the sides along each loop from its intersection vertices (the entry /
    /// exit flags), classifies loops without intersections by a winding-number test, and
    /// records the labels when asked to.
    pub(super) fn mark_entry_exit(&mut self, mut steps: Option<&mut GreinerHormannSteps>) {
        for slot in 0..self.loops.len() {
            let first = self.loops[slot].first;
            if self.nodes[first as usize].removed {
                continue;
            }
            let mut start = NONE;
            let mut n = first;
            let mut left = self.walk_bound();
            loop {
                if !self.step(&mut left) {
                    return;
                }
                if self.nodes[n as usize].cluster != NONE {
                    start = n;
                    break;
                }
                n = self.nodes[n as usize].next;
                if n == first {
                    break;
                }
            }
            if start != NONE {
                let mut side = self.nodes[start as usize].status;
                let mut n = self.nodes[start as usize].next;
                let mut left = self.walk_bound();
                while n != start {
                    if !self.step(&mut left) {
                        return;
                    }
                    let node = &mut self.nodes[n as usize];
                    if node.cluster != NONE {
                        side = node.status;
                    } else {
                        node.status = side;
                    }
                    n = node.next;
                }
            } else {
                let operand = self.nodes[first as usize].operand;
                let inside = self.loop_inside_other(slot);
                let side = if inside {
                    Status::Inside
                } else {
                    Status::Outside
                };
                let lp = self.loops[slot];
                let mut n = lp.first;
                let mut left = self.walk_bound();
                loop {
                    if !self.step(&mut left) {
                        return;
                    }
                    let node = &mut self.nodes[n as usize];
                    node.status = side;
                    n = node.next;
                    if n == lp.first {
                        break;
                    }
                }
                if let Some(s) = steps.as_deref_mut() {
                    s.untouched_loops.push(UntouchedLoop {
                        operand,
                        loop_index: lp.input_loop,
                        inside_other: inside,
                        kept: inside == (operand == Operand::Clip),
                    });
                }
            }
        }
        self.check_both_ends();
        if let Some(s) = steps {
            self.record_labels(s);
        }
    }

    /// The side of a fragment was decided at its start; the test at its end (the backward
    /// tangent against the other operand's sector there) must agree, as must the two operands
    /// at a crossing. They always do in exact arithmetic; a disagreement means that two
    /// decisions near features at the tolerance scale contradict each other (not observed since
    /// edges shorter than the tolerances are merged on loading), and is reported by
    /// [`SetDifference::last_traversal_consistent`].
    fn check_both_ends(&mut self) {
        for n in 0..self.nodes.len() {
            let node = &self.nodes[n];
            if node.cluster == NONE || node.removed {
                continue;
            }
            let before = self.nodes[node.prev as usize].status;
            if before.is_overlap() {
                continue;
            }
            let back = -tangent(node.n_in, node.dir);
            if self.side_of_tangent(n, back) != before {
                self.consistent = false;
                return;
            }
        }
    }

    /// Containment of an intersection-free loop in the other operand: the winding number of
    /// its vertex farthest from the horizon. That vertex is not within the tolerances of the
    /// other boundary (it would be an intersection), so the test is unambiguous.
    fn loop_inside_other(&self, slot: usize) -> bool {
        let lp = self.loops[slot];
        let range = lp.input_first as usize..(lp.input_first + lp.len) as usize;
        let mut p = self.nodes[range.start].dir;
        for node in &self.nodes[range] {
            if node.dir.z > p.z {
                p = node.dir;
            }
        }
        self.contains(p, self.nodes[lp.first as usize].operand.other())
    }

    /// Whether the unit direction p lies inside `operand` (nonzero winding number over its
    /// loops), for p not on its boundary. Points on or within `EPS_LINE` of the horizon are
    /// outside every region of the closed upper hemisphere that does not pass through them.
    fn contains(&self, p: DVec3, operand: Operand) -> bool {
        let Some(ray) = Ray::new(p, EPS_LINE) else {
            return false;
        };
        let mut winding = 0;
        for slot in self.loop_range(operand) {
            let lp = self.loops[slot];
            // The input edges, as loaded: phase 1 folds nodes only within the tolerances.
            for i in lp.input_first..lp.input_first + lp.len {
                let a = &self.nodes[i as usize];
                let b = &self.nodes[a.orig_next as usize];
                winding += ray.winding_contribution(a.dir, b.dir);
            }
        }
        winding != 0
    }

    /// Records FHP's labels, the entry / exit flags and the overlap chains.
    fn record_labels(&self, steps: &mut GreinerHormannSteps) {
        for slot in 0..self.loops.len() {
            let lp = self.loops[slot];
            if self.nodes[lp.first as usize].removed {
                continue;
            }
            let operand = self.nodes[lp.first as usize].operand;
            let begin = steps.labels.len();
            let mut n = lp.first;
            let mut left = self.walk_bound();
            loop {
                if !self.step(&mut left) {
                    return;
                }
                let node = &self.nodes[n as usize];
                if node.cluster != NONE {
                    let before = self.nodes[node.prev as usize].status;
                    let after = node.status;
                    let (label, transition) = local_label(before, after);
                    steps.labels.push(LabelRecord {
                        operand,
                        loop_index: lp.input_loop,
                        edge: node.vertex,
                        position: node.pos,
                        before: before.public(),
                        after: after.public(),
                        label,
                        transition,
                    });
                }
                n = node.next;
                if n == lp.first {
                    break;
                }
            }
            record_chains(steps, begin, operand, lp.input_loop);
        }
    }
}

/// FHP's local label from the sides of the fragments before and after a vertex.
fn local_label(before: Status, after: Status) -> (VertexLabel, Option<Transition>) {
    let entry_exit = |s: Status| {
        if s == Status::Inside {
            Transition::Entry
        } else {
            Transition::Exit
        }
    };
    match (before.is_overlap(), after.is_overlap()) {
        (false, false) if before == after => (VertexLabel::Bouncing, None),
        (false, false) => (VertexLabel::Crossing, Some(entry_exit(after))),
        (false, true) if before == Status::Inside => (VertexLabel::LeftOn, None),
        (false, true) => (VertexLabel::RightOn, None),
        (true, false) if after == Status::Inside => (VertexLabel::OnLeft, None),
        (true, false) => (VertexLabel::OnRight, None),
        (true, true) => (VertexLabel::OnOn, None),
    }
}

/// Groups the labels `begin..` of one loop into overlap chains: from a left/on or right/on
/// vertex through on/on vertices to an on/left or on/right vertex. A delayed crossing arrives
/// from one side and leaves to the other.
fn record_chains(steps: &mut GreinerHormannSteps, begin: usize, operand: Operand, loop_index: u32) {
    let count = steps.labels.len() - begin;
    if count == 0 {
        return;
    }
    let Some(rot) = (0..count).find(|&k| !steps.labels[begin + k].before.is_overlap()) else {
        steps.chains.push(OverlapChain {
            operand,
            loop_index,
            first_label: begin as u32,
            last_label: (begin + count - 1) as u32,
            kind: ChainKind::WholeLoop,
            same_direction: steps.labels[begin].after == super::FragmentSide::OverlapSame,
            transition: None,
        });
        return;
    };
    let mut open: Option<usize> = None;
    for step in 0..count {
        let idx = begin + (rot + step) % count;
        let label = &steps.labels[idx];
        match label.label {
            VertexLabel::LeftOn | VertexLabel::RightOn => open = Some(idx),
            VertexLabel::OnLeft | VertexLabel::OnRight => {
                if let Some(start) = open.take() {
                    let first = &steps.labels[start];
                    let from_inside = first.label == VertexLabel::LeftOn;
                    let to_inside = label.label == VertexLabel::OnLeft;
                    let (kind, transition) = if from_inside == to_inside {
                        (ChainKind::DelayedBouncing, None)
                    } else if to_inside {
                        (ChainKind::DelayedCrossing, Some(Transition::Entry))
                    } else {
                        (ChainKind::DelayedCrossing, Some(Transition::Exit))
                    };
                    let same_direction = first.after == super::FragmentSide::OverlapSame;
                    steps.chains.push(OverlapChain {
                        operand,
                        loop_index,
                        first_label: start as u32,
                        last_label: idx as u32,
                        kind,
                        same_direction,
                        transition,
                    });
                }
            }
            _ => {}
        }
    }
}
