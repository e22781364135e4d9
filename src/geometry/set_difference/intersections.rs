//! Phase 1: intersection vertices (Greiner–Hormann phase one, with the degenerate cases of
//! Foster, Hormann and Popa 2019).
//!
//! Every contact between the two boundaries becomes a *cluster* of nodes at one position: one
//! or more nodes of each operand, found in this order:
//!
//! 1. **V** (vertex on vertex): a subject vertex and a clip vertex closer than `EPS_POINT`.
//! 2. **T** (vertex on edge): a vertex within `EPS_LINE` of the other operand's edge line,
//!    strictly between its endpoints and coinciding with neither; a copy is inserted into the
//!    edge.
//! 3. **X** (crossing): edges without any V or T contact whose endpoints lie strictly on
//!    opposite sides of each other's lines; the crossing point is inserted into both.
//!
//! Collinear overlapping edges need no case of their own: the ends of an overlap are V or T
//! contacts, and phase 2 recognises the overlap as a fragment whose two end clusters are also
//! joined by an edge of the other operand. Deciding contacts per vertex (not per pair of edges)
//! makes the two edges meeting at a vertex agree on it, and a pair of edges with a contact never
//! also reports a crossing, so every meeting point is found exactly once.

use super::predicates::{arc_coordinates, arc_parameter, coincident, on_line, opposite};
use super::{
    EPS_POINT, GreinerHormannSteps, IntersectionKind, IntersectionRecord, NONE, Node,
    SetDifference, Status,
};
use glam::DVec3;

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
        for i in 0..ns {
            let p = self.nodes[i].dir;
            for j in 0..nc {
                self.side_sc.push(p.dot(self.nodes[ns + j].n_out));
            }
        }
        for j in 0..nc {
            let p = self.nodes[ns + j].dir;
            for i in 0..ns {
                self.side_cs.push(p.dot(self.nodes[i].n_out));
            }
        }

        // 1. Vertex on vertex. A vertex within EPS_POINT of clip vertex j is within EPS_POINT
        // of the line of clip edge j, which starts at j: a cheap filter.
        for i in 0..ns {
            for j in 0..nc {
                if self.side_sc[i * nc + j].abs() <= EPS_POINT
                    && coincident(self.nodes[i].dir, self.nodes[ns + j].dir)
                {
                    self.contact_sc[i * nc + j] |= VERTEX;
                    self.union(i as u32, (ns + j) as u32);
                    if let Some(s) = steps.as_deref_mut() {
                        s.intersections.push(IntersectionRecord {
                            position: self.nodes[i].pos,
                            kind: IntersectionKind::VertexOnVertex,
                            subject: self.edge_point(i as u32, 0.0),
                            clip: self.edge_point((ns + j) as u32, 0.0),
                        });
                    }
                }
            }
        }

        // 2. Subject vertex i inside clip edge j.
        for i in 0..ns {
            for j in 0..nc {
                if !on_line(self.side_sc[i * nc + j]) {
                    continue;
                }
                let c = ns + j;
                let d = self.nodes[c].orig_next as usize;
                if (self.contact_sc[i * nc + j] | self.contact_sc[i * nc + d - ns]) & VERTEX != 0 {
                    continue;
                }
                let (cn, p) = (&self.nodes[c], self.nodes[i].dir);
                let (u, v) = arc_coordinates(cn.dir, self.nodes[d].dir, cn.n_out, p);
                if u > 0.0 && v > 0.0 {
                    let t = u / (u + v);
                    self.contact_sc[i * nc + j] |= ON_EDGE;
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
            }
        }

        // 2'. Clip vertex j inside subject edge i.
        for j in 0..nc {
            let c = ns + j;
            for i in 0..ns {
                if !on_line(self.side_cs[j * ns + i]) {
                    continue;
                }
                let b = self.nodes[i].orig_next as usize;
                if (self.contact_sc[i * nc + j] | self.contact_sc[b * nc + j]) & VERTEX != 0 {
                    continue;
                }
                let (an, p) = (&self.nodes[i], self.nodes[c].dir);
                let (u, v) = arc_coordinates(an.dir, self.nodes[b].dir, an.n_out, p);
                if u > 0.0 && v > 0.0 {
                    let t = u / (u + v);
                    self.contact_cs[j * ns + i] |= ON_EDGE;
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
        }

        // 3. Proper crossings of edges a → b (subject) and c → d (clip) without contacts.
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
                // Arcs of a sphere can straddle each other's great circles yet meet only at
                // antipodal points; impossible for inputs in w ≥ 0 but checked for safety.
                let u = sc / (sc - sd);
                if x.dot(pc * (1.0 - u) + pd * u) <= 0.0 {
                    continue;
                }
                let ts = arc_parameter(pa, pb, self.nodes[a].n_out, x, t);
                let tc = arc_parameter(pc, pd, self.nodes[c].n_out, x, u);
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

        self.insert_nodes();
        self.finish_clusters();
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

    /// Links the inserted points into the vertex lists, sorted along each edge. A point within
    /// `EPS_POINT` of the edge's endpoints or of the previous inserted point is merged with it
    /// (it joins that node's cluster) so that no fragment is shorter than the tolerance.
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
                let target = if coincident(rec.pos, self.nodes[a as usize].dir) {
                    a
                } else if coincident(rec.pos, self.nodes[b as usize].dir) {
                    b
                } else if last != a && coincident(rec.pos, self.nodes[last as usize].dir) {
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

    /// Flattens the union–find forest, gives every node of a cluster the representative's
    /// position (the smallest node index: a subject input vertex if there is one) and threads
    /// the clusters into rings.
    fn finish_clusters(&mut self) {
        for n in 0..self.nodes.len() as u32 {
            if self.nodes[n as usize].cluster != NONE {
                let r = self.find(n);
                self.nodes[n as usize].cluster = r;
                self.nodes[n as usize].ring = n;
            }
        }
        for n in 0..self.nodes.len() {
            let r = self.nodes[n].cluster;
            if r != NONE && r as usize != n {
                let root = self.nodes[r as usize];
                self.nodes[n].ring = root.ring;
                self.nodes[r as usize].ring = n as u32;
                self.nodes[n].pos = root.pos;
                self.nodes[n].dir = root.dir;
            }
        }
    }
}
