//! Phase 1: intersection vertices (Greiner–Hormann phase one, with the degenerate cases of
//! Foster, Hormann and Popa 2019).
//!
//! Every contact between the two boundaries becomes a *cluster* of nodes at one position: one
//! or more nodes of each operand, found in this order:
//!
//! 1. **V** (vertex on vertex): a subject vertex and a clip vertex closer than `EPS_POINT`.
//! 2. **T** (vertex on edge): a vertex within `EPS_LINE` of the other operand's edge line,
//!    strictly between its endpoints and coinciding with neither; a copy is inserted into the
//!    edge. A vertex on two consecutive edges is a V contact with their common vertex instead
//!    (the corner rule).
//! 3. **X** (crossing): edges without any V or T contact whose endpoints lie strictly on
//!    opposite sides of each other's lines and whose crossing point lies strictly inside both
//!    (checked on the point: for edges on one great circle the signs are noise); the crossing
//!    point is inserted into both.
//!
//! Collinear overlapping edges need no case of their own: the ends of an overlap are V or T
//! contacts, and phase 2 recognises the overlap as a fragment whose two end clusters are also
//! joined by a fragment of the other operand. Deciding contacts per vertex (not per pair of
//! edges) makes the two edges meeting at a vertex agree on it, and a pair of edges with a
//! contact never also reports a crossing, so every meeting point is found once.
//!
//! `finish_clusters` then removes detours of one operand through a cluster (sub-tolerance
//! features folded onto one point), gives the nodes of each cluster one position and gives
//! fragments whose ends were moved off their edge the normal of their chord. See
//! `docs/set-difference.md` for the reasons.

use super::predicates::{
    arc_coordinates, arc_parameter, coincident, on_line, opposite, unit_normal,
};
use super::{
    DETOUR_RADIUS, EPS_LINE, EPS_ON_EDGE, EPS_POINT, GreinerHormannSteps, IntersectionKind,
    IntersectionRecord, NONE, Node, SetDifference, Status,
};
use glam::DVec3;

/// At most this many vertices are looked at for a detour.
const MAX_DETOUR: usize = 8;

/// `contact_sc` bit: subject vertex i coincides with clip vertex j.
const VERTEX: u8 = 1;
/// `contact_sc` bit: subject vertex i lies inside clip edge j (`contact_cs`: clip vertex j
/// inside subject edge i).
const ON_EDGE: u8 = 2;

/// A point to insert into an input edge.
#[derive(Clone, Copy, Debug)]
pub(super) struct Insertion {
    /// Node starting the input edge.
    edge: u32,
    /// Parameter along the edge (sort key).
    t: f64,
    /// Unit direction of the point.
    pos: DVec3,
    /// The node or insertion (see `link_is_insertion`) the new node shares its position with.
    link: u32,
    link_is_insertion: bool,
    /// Index of the insertion in creation order.
    id: u32,
}

impl SetDifference {
    /// Phase 1: finds every intersection vertex, inserts it into both vertex lists and groups
    /// the nodes at each intersection point into a cluster.
    pub(super) fn find_intersections(&mut self, mut steps: Option<&mut GreinerHormannSteps>) {
        let ns = self.subject_nodes;
        let nc = self.clip_nodes;
        self.needs_cleaning = false;
        self.insertions.clear();
        self.side_sc.clear();
        self.side_cs.clear();
        self.contact_sc.clear();
        self.contact_cs.clear();
        if nc == 0 {
            return;
        }
        self.contact_sc.resize(ns * nc, 0);
        self.contact_cs.resize(nc * ns, 0);
        // Signed distances of every vertex to every line of the other operand, remembering the
        // few pairs near enough for a contact (none in the common case): the V and T tests
        // below only visit those.
        self.near_sc.clear();
        self.near_cs.clear();
        let near = EPS_LINE.max(EPS_POINT);
        for i in 0..ns {
            let p = self.nodes[i].dir;
            for j in 0..nc {
                let side = p.dot(self.nodes[ns + j].n_out);
                if side.abs() < near {
                    self.near_sc.push((i * nc + j) as u32);
                }
                self.side_sc.push(side);
            }
        }
        for j in 0..nc {
            let p = self.nodes[ns + j].dir;
            for i in 0..ns {
                let side = p.dot(self.nodes[i].n_out);
                if side.abs() < near {
                    self.near_cs.push((j * ns + i) as u32);
                }
                self.side_cs.push(side);
            }
        }

        // A vertex near the line of an edge where either is at a straight vertex: the operands
        // are loaded again with their straight vertices folded (`fold_straight_vertices`).
        if !self.cleaned {
            let straight_at = |this: &Self, v: usize, c: usize| {
                this.node_is_straight(v)
                    || this.node_is_straight(c)
                    || this.node_is_straight(this.nodes[c].orig_next as usize)
            };
            let near_straight = self.near_sc.iter().any(|&idx| {
                let (i, j) = (idx as usize / nc, idx as usize % nc);
                straight_at(self, i, ns + j)
            }) || self.near_cs.iter().any(|&idx| {
                let (j, i) = (idx as usize / ns, idx as usize % ns);
                straight_at(self, ns + j, i)
            });
            if near_straight {
                self.needs_cleaning = true;
                return;
            }
        }

        // 1. Vertex on vertex. A vertex within EPS_POINT of clip vertex j is within EPS_POINT
        // of the line of clip edge j, which starts at j.
        for k in 0..self.near_sc.len() {
            let idx = self.near_sc[k] as usize;
            let (i, j) = (idx / nc, idx % nc);
            if self.side_sc[idx].abs() <= EPS_POINT
                && coincident(self.nodes[i].dir, self.nodes[ns + j].dir, EPS_POINT)
            {
                self.contact_sc[idx] |= VERTEX;
                self.union(i as u32, (ns + j) as u32);
                self.record_vertex_on_vertex(steps.as_deref_mut(), i, ns + j);
            }
        }

        // 2. Vertices inside edges of the other operand (flags only, insertions below).
        let mut any_on_edge = false;
        for k in 0..self.near_sc.len() {
            let idx = self.near_sc[k] as usize;
            let (i, j) = (idx / nc, idx % nc);
            let c = ns + j;
            let d = self.nodes[c].orig_next as usize;
            if on_line(self.side_sc[idx], EPS_LINE)
                && (self.contact_sc[idx] | self.contact_sc[i * nc + d - ns]) & VERTEX == 0
                && self.strictly_inside_arc(c, d, i)
            {
                self.contact_sc[idx] |= ON_EDGE;
                any_on_edge = true;
            }
        }
        for k in 0..self.near_cs.len() {
            let idx = self.near_cs[k] as usize;
            let (j, i) = (idx / ns, idx % ns);
            let c = ns + j;
            let b = self.nodes[i].orig_next as usize;
            if on_line(self.side_cs[idx], EPS_LINE)
                && (self.contact_sc[i * nc + j] | self.contact_sc[b * nc + j]) & VERTEX == 0
                && self.strictly_inside_arc(i, b, c)
            {
                self.contact_cs[idx] |= ON_EDGE;
                any_on_edge = true;
            }
        }

        if any_on_edge {
            // 2'. A vertex within the line tolerance of two consecutive edges of the other
            // operand, inside both, lies at their common vertex (farther than EPS_POINT from
            // it only because the corner is nearly straight or the point sits in the tolerance
            // band; at most DETOUR_RADIUS, since at a sharper tip the operands are loaded
            // again with the tips cut, `truncate_spikes`): a V contact. Two T contacts would put two nodes of the other
            // operand into one cluster with the corner vertex in between.
            for k in 0..self.near_sc.len() {
                let idx = self.near_sc[k] as usize;
                let (i, j) = (idx / nc, idx % nc);
                let corner = self.nodes[ns + j].orig_next as usize - ns;
                let next = i * nc + corner;
                if self.contact_sc[idx] & self.contact_sc[next] & ON_EDGE != 0 {
                    if !self.cleaned && self.node_is_spike(ns + corner) {
                        self.needs_cleaning = true;
                        return;
                    }
                    self.contact_sc[idx] &= !ON_EDGE;
                    self.contact_sc[next] &= !ON_EDGE;
                    self.contact_sc[next] |= VERTEX;
                    self.union(i as u32, (ns + corner) as u32);
                    self.record_vertex_on_vertex(steps.as_deref_mut(), i, ns + corner);
                }
            }
            for k in 0..self.near_cs.len() {
                let idx = self.near_cs[k] as usize;
                let (j, a) = (idx / ns, idx % ns);
                let corner = self.nodes[a].orig_next as usize;
                let next = j * ns + corner;
                if self.contact_cs[idx] & self.contact_cs[next] & ON_EDGE != 0 {
                    if !self.cleaned && self.node_is_spike(corner) {
                        self.needs_cleaning = true;
                        return;
                    }
                    self.contact_cs[idx] &= !ON_EDGE;
                    self.contact_cs[next] &= !ON_EDGE;
                    self.contact_sc[corner * nc + j] |= VERTEX;
                    self.union(corner as u32, (ns + j) as u32);
                    self.record_vertex_on_vertex(steps.as_deref_mut(), corner, ns + j);
                }
            }

            // 2''. Insert the T contacts: a copy of the vertex goes into the edge.
            for k in 0..self.near_sc.len() {
                let idx = self.near_sc[k] as usize;
                if self.contact_sc[idx] & ON_EDGE == 0 {
                    continue;
                }
                let (i, j) = (idx / nc, idx % nc);
                let c = ns + j;
                let d = self.nodes[c].orig_next as usize;
                let p = self.nodes[i].dir;
                let (cn, dn) = (&self.nodes[c], &self.nodes[d]);
                let t = arc_parameter(cn.dir, dn.dir, cn.n_out, p, 0.5);
                self.push_insertion(c as u32, t, p, i as u32, false);
                if let Some(s) = steps.as_deref_mut() {
                    s.intersections.push(IntersectionRecord {
                        position: self.nodes[i].pos,
                        kind: IntersectionKind::SubjectVertexOnClipEdge,
                        subject: self.edge_point(i as u32, 0.0),
                        clip: self.edge_point(c as u32, t),
                    });
                }
            }
            for k in 0..self.near_cs.len() {
                let idx = self.near_cs[k] as usize;
                if self.contact_cs[idx] & ON_EDGE == 0 {
                    continue;
                }
                let (j, i) = (idx / ns, idx % ns);
                let c = ns + j;
                let b = self.nodes[i].orig_next as usize;
                let p = self.nodes[c].dir;
                let (an, bn) = (&self.nodes[i], &self.nodes[b]);
                let t = arc_parameter(an.dir, bn.dir, an.n_out, p, 0.5);
                self.push_insertion(i as u32, t, p, c as u32, false);
                if let Some(s) = steps.as_deref_mut() {
                    s.intersections.push(IntersectionRecord {
                        position: self.nodes[c].pos,
                        kind: IntersectionKind::ClipVertexOnSubjectEdge,
                        subject: self.edge_point(i as u32, t),
                        clip: self.edge_point(c as u32, 0.0),
                    });
                }
            }
        }

        // 3. Proper crossings of edges a → b (subject) and c → d (clip) without contacts.
        //
        // The crossing point must lie strictly inside both edges, checked on the point itself.
        // Opposite signs of the endpoints' sides on both lines imply that only when the signs
        // are right, and they are rounding noise when the edges lie on one great circle. That
        // was the bug of the chair scene (tests/set_difference_regressions.rs): boxes built on a
        // common grid have edges on one 3D line (a chair's back leg and its back, 1 mm apart),
        // so a subject edge and a clip edge lay on the same great circle without overlapping.
        // All four side values were ~1e-17, both pairs of signs came out "opposite", and a
        // "crossing" was inserted at t = sa / (sa − sb), a ratio of noise: on the subject edge,
        // but beyond the end of the clip edge (t = 1.06 there). Inserted into that edge's list,
        // it made the labels contradict each other at any tolerance (the collinearity is exact)
        // and the traversal dropped the loop: the light came out fully shadowed.
        //
        // x is a positive combination of a and b, hence on the arc a → b; that it lies strictly
        // inside the arc c → d is decided by its arc coordinates there, which are accurate to
        // rounding. Collinear edges that do not overlap (their ends are not T contacts of each
        // other) are at least EPS_POINT apart along the line, so the check rejects them however
        // the noise falls. When the signs are reliable the check always passes. Raw signs (not
        // signs classified with EPS_LINE) are what decides transversal edges: with nearly
        // parallel edges whose ends both lie about EPS_LINE from the other line, classifying
        // could call one end on the line (and outside the other edge: no T contact) and the
        // other end off it (no T contact either), losing a crossing that lies far from both ends.
        for a in 0..ns {
            let b = self.nodes[a].orig_next as usize;
            for j in 0..nc {
                let c = ns + j;
                let d = self.nodes[c].orig_next as usize;
                let dj = d - ns;
                let sa = self.side_sc[a * nc + j];
                let sb = self.side_sc[b * nc + j];
                if !opposite(sa, sb) {
                    continue;
                }
                let sc = self.side_cs[j * ns + a];
                let sd = self.side_cs[dj * ns + a];
                if !opposite(sc, sd) {
                    continue;
                }
                let contact = self.contact_sc[a * nc + j]
                    | self.contact_sc[b * nc + j]
                    | (self.contact_sc[a * nc + dj] & VERTEX)
                    | (self.contact_sc[b * nc + dj] & VERTEX)
                    | self.contact_cs[j * ns + a]
                    | self.contact_cs[dj * ns + a];
                if contact != 0 {
                    continue;
                }
                let (pa, pb) = (self.nodes[a].dir, self.nodes[b].dir);
                let (pc, pd) = (self.nodes[c].dir, self.nodes[d].dir);
                // x ∝ (1 − t)·a + t·b with t = sa / (sa − sb): the positive combination of a and b
                // on the line of c → d, so the point of the arc a → b (never the antipode).
                let t = sa / (sa - sb);
                let x = (pa * (1.0 - t) + pb * t).normalize();
                // Strictly inside the arc c → d (this also rejects the antipodal point, where
                // arcs of a sphere straddling each other's great circles may meet instead).
                let (u, v) = arc_coordinates(pc, pd, self.nodes[c].n_out, x);
                if u <= 0.0 || v <= 0.0 {
                    continue;
                }
                let ts = arc_parameter(pa, pb, self.nodes[a].n_out, x, t);
                let tc = u / (u + v);
                let id = self.insertions.len() as u32;
                self.push_insertion(a as u32, ts, x, id + 1, true);
                self.push_insertion(c as u32, tc, x, NONE, false);
                if let Some(s) = steps.as_deref_mut() {
                    s.intersections.push(IntersectionRecord {
                        position: x,
                        kind: IntersectionKind::Crossing,
                        subject: self.edge_point(a as u32, ts),
                        clip: self.edge_point(c as u32, tc),
                    });
                }
            }
        }

        // Without any contact there are no clusters to finish (the common disjoint, nested
        // and covering cases).
        let any_vertex = self.contact_sc.iter().any(|&f| f & VERTEX != 0);
        if any_vertex || !self.insertions.is_empty() {
            self.insert_nodes();
            self.finish_clusters();
        }
    }

    /// The node of cluster `c` (at x) that ends a short detour starting after node n (see
    /// `finish_clusters`), if any. Nodes of the detour may belong to other clusters.
    fn detour_end(&self, n: usize, c: u32, x: DVec3) -> Option<usize> {
        let mut m = self.nodes[n].next as usize;
        for _ in 0..MAX_DETOUR {
            if m == n {
                return None;
            }
            let node = &self.nodes[m];
            if node.cluster != NONE && self.root(node.cluster) == c {
                return Some(m);
            }
            if node.dir.dot(x) <= 0.0
                || node.dir.cross(x).length_squared() > DETOUR_RADIUS * DETOUR_RADIUS
            {
                return None;
            }
            m = node.next as usize;
        }
        None
    }

    /// Union–find root without path compression (for read-only queries); ends within `x`
    /// steps, parents having smaller indices than their children.
    fn root(&self, mut x: u32) -> u32 {
        while self.nodes[x as usize].cluster != x {
            x = self.nodes[x as usize].cluster;
        }
        x
    }

    /// Replaces the nodes after n up to m (all of cluster `c` or close to it) by n, which then
    /// leaves along m's edge. Clusters of removed nodes are merged into `c`; returns whether
    /// that happened.
    fn collapse_detour(&mut self, n: usize, m: usize, c: u32) -> bool {
        let absorbed = self.nodes[m];
        let mut merged = false;
        let mut k = self.nodes[n].next as usize;
        let mut left = self.walk_bound();
        loop {
            if !self.step(&mut left) {
                return merged;
            }
            self.nodes[k].removed = true;
            let slot = self.nodes[k].loop_slot as usize;
            if self.loops[slot].first == k as u32 {
                self.loops[slot].first = n as u32;
            }
            let other = self.nodes[k].cluster;
            if other != NONE && self.find(other) != self.find(c) {
                self.union(other, c);
                merged = true;
            }
            if k == m {
                break;
            }
            k = self.nodes[k].next as usize;
        }
        let node = &mut self.nodes[n];
        node.next = absorbed.next;
        node.n_out = absorbed.n_out;
        node.vertex = absorbed.vertex;
        // The in- and out-fragments now lie on different input edges: a corner, not a
        // pass-through vertex.
        node.inserted = false;
        self.nodes[absorbed.next as usize].prev = n as u32;
        if absorbed.next as usize == n {
            // The whole loop shrank to a point.
            self.nodes[n].removed = true;
        }
        merged
    }

    /// Whether the direction of node p projects strictly inside the arc between nodes a and b
    /// (and coincides with neither end, which the V test has excluded).
    fn strictly_inside_arc(&self, a: usize, b: usize, p: usize) -> bool {
        let an = &self.nodes[a];
        let (u, v) = arc_coordinates(an.dir, self.nodes[b].dir, an.n_out, self.nodes[p].dir);
        u > 0.0 && v > 0.0
    }

    fn record_vertex_on_vertex(
        &self,
        steps: Option<&mut GreinerHormannSteps>,
        subject: usize,
        clip: usize,
    ) {
        if let Some(s) = steps {
            s.intersections.push(IntersectionRecord {
                position: self.nodes[subject].pos,
                kind: IntersectionKind::VertexOnVertex,
                subject: self.edge_point(subject as u32, 0.0),
                clip: self.edge_point(clip as u32, 0.0),
            });
        }
    }

    fn push_insertion(
        &mut self,
        edge: u32,
        t: f64,
        pos: DVec3,
        link: u32,
        link_is_insertion: bool,
    ) {
        let id = self.insertions.len() as u32;
        self.insertions.push(Insertion {
            edge,
            t,
            pos,
            link,
            link_is_insertion,
            id,
        });
    }

    /// Links the inserted points into the vertex lists, sorted along each edge. A point equal
    /// to an endpoint or to the previous inserted point (copies of one vertex, e.g. where the
    /// other operand touches itself) becomes that node. Points that are merely close are kept
    /// apart: proximity is decided once, by the V and T tests; merging two crossings 3e-12
    /// apart would put both clip edges of a corner into one cluster without the corner.
    fn insert_nodes(&mut self) {
        let count = self.insertions.len();
        if count == 0 {
            return;
        }
        self.insertion_nodes.clear();
        self.insertion_nodes.resize(count, NONE);
        self.insertions.sort_unstable_by(|p, q| {
            p.edge
                .cmp(&q.edge)
                .then(p.t.total_cmp(&q.t))
                .then(p.id.cmp(&q.id))
        });
        let mut k = 0;
        while k < count {
            let a = self.insertions[k].edge;
            let b = self.nodes[a as usize].orig_next;
            let mut last = a;
            while k < count && self.insertions[k].edge == a {
                let rec = self.insertions[k];
                let target = if rec.pos == self.nodes[a as usize].dir {
                    a
                } else if rec.pos == self.nodes[b as usize].dir {
                    b
                } else if last != a && rec.pos == self.nodes[last as usize].dir {
                    last
                } else {
                    let n = self.nodes.len() as u32;
                    let base = self.nodes[a as usize];
                    self.nodes.push(Node {
                        pos: rec.pos,
                        dir: rec.pos,
                        n_in: base.n_out,
                        n_out: base.n_out,
                        next: b,
                        prev: last,
                        orig_next: NONE,
                        cluster: NONE,
                        ring: NONE,
                        loop_slot: base.loop_slot,
                        vertex: base.vertex,
                        operand: base.operand,
                        inserted: true,
                        status: Status::Unknown,
                        visited: false,
                        removed: false,
                    });
                    self.nodes[last as usize].next = n;
                    last = n;
                    n
                };
                self.insertion_nodes[rec.id as usize] = target;
                k += 1;
            }
            self.nodes[last as usize].next = b;
            self.nodes[b as usize].prev = last;
        }
        for k in 0..count {
            let rec = self.insertions[k];
            let node = self.insertion_nodes[rec.id as usize];
            if rec.link == NONE {
                continue;
            }
            let other = if rec.link_is_insertion {
                self.insertion_nodes[rec.link as usize]
            } else {
                rec.link
            };
            self.union(node, other);
        }
    }

    /// Flattens the union–find forest, collapses detours of one operand through a cluster,
    /// gives every node of a cluster the representative's position (the smallest node index: a
    /// subject input vertex if there is one) and threads the clusters into rings.
    ///
    /// Clusters are transitive, and tolerance decisions near features at the tolerance scale
    /// can put two nodes of one operand into a cluster that the operand joins by a detour of a
    /// few 1e-12 rad: consecutive nodes (a fragment of zero length and meaningless direction),
    /// or nodes separated by vertices that all lie within [`DETOUR_RADIUS`] of the cluster
    /// (a clip vertex on two edges near a subject corner, three clip vertices around one
    /// subject vertex). The detour is removed: one node arrives along the first node's edge
    /// and leaves along the last one's, a corner. Detours reaching farther are genuine loops
    /// through a point where the operand touches itself, and are kept.
    fn finish_clusters(&mut self) {
        // A round repeats only after a merge of two clusters: at most one round per node. A
        // detour collapsed removes at least one node: at most one per node in all.
        let mut rounds = self.walk_bound();
        let mut collapses = self.walk_bound();
        loop {
            if !self.step(&mut rounds) {
                return;
            }
            for n in 0..self.nodes.len() as u32 {
                if self.nodes[n as usize].cluster != NONE {
                    let r = self.find(n);
                    self.nodes[n as usize].cluster = r;
                }
            }
            let mut merged = false;
            for n in 0..self.nodes.len() {
                let c = self.nodes[n].cluster;
                if c == NONE || self.nodes[n].removed {
                    continue;
                }
                let x = self.nodes[c as usize].dir;
                while let Some(m) = self.detour_end(n, c, x) {
                    if !self.step(&mut collapses) {
                        return;
                    }
                    merged |= self.collapse_detour(n, m, c);
                    if self.nodes[n].removed {
                        break;
                    }
                }
            }
            // A detour through another cluster merged it into this one: its other nodes may now
            // form detours of their own.
            if !merged {
                break;
            }
        }
        // Rings, positions, and the first live node as the cluster's id (the representative
        // may have been absorbed; its position is still the cluster's).
        self.cluster_rep.clear();
        self.cluster_rep.resize(self.nodes.len(), NONE);
        for n in 0..self.nodes.len() {
            let c = self.nodes[n].cluster;
            if c == NONE || self.nodes[n].removed {
                continue;
            }
            let rep = self.cluster_rep[c as usize];
            if rep == NONE {
                self.cluster_rep[c as usize] = n as u32;
                self.nodes[n].ring = n as u32;
            } else {
                self.nodes[n].ring = self.nodes[rep as usize].ring;
                self.nodes[rep as usize].ring = n as u32;
            }
            let root = self.nodes[c as usize];
            let node = &mut self.nodes[n];
            node.pos = root.pos;
            node.dir = root.dir;
            node.cluster = self.cluster_rep[c as usize];
        }
        self.snap_fragment_normals();
    }

    /// After snapping, the boundary is the polyline through the cluster positions. A fragment
    /// whose end points left the line of its input edge (a vertex moved onto another operand's
    /// vertex, or copied onto its edge) is the chord between them, and every direction test of
    /// phase 2 and 3 must see that chord, not the original edge: two edges leaving a snapped
    /// vertex 1e-12 apart would otherwise be ordered by geometry that no longer exists. Fragments
    /// still on their edge keep its normal, which is more accurate than a short chord's.
    fn snap_fragment_normals(&mut self) {
        for n in 0..self.nodes.len() {
            let node = self.nodes[n];
            if node.removed {
                continue;
            }
            let next = node.next as usize;
            let (a, b) = (node.dir, self.nodes[next].dir);
            let normal =
                if node.n_out.dot(a).abs() > EPS_ON_EDGE || node.n_out.dot(b).abs() > EPS_ON_EDGE {
                    unit_normal(a, b)
                } else {
                    node.n_out
                };
            self.nodes[n].n_out = normal;
            self.nodes[next].n_in = normal;
        }
    }
}
