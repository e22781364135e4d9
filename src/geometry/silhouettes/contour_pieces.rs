//! The stages both exact silhouettes share (001 Sect. 4.3), after each has found its contour
//! arcs: the whole silhouette ([`exact_silhouette`](crate::geometry::silhouettes::exact_silhouette)) takes every
//! contour and boundary edge from end to end; the windowed one
//! ([`exact_silhouette_in_window`](crate::geometry::exact_silhouette_in_window)) takes the parts of them
//! inside a window, whose ends may lie on the window's boundary. From there on the work is
//! one pipeline over [`ContourArc`]s:
//!
//! 1. [`ContourPieces::find_crossings`]: apparent intersections of pairs of arcs without a
//!    common vertex (Eq. 4.4), among the pairs a sweep keeps;
//! 2. [`ContourPieces::split_into_pieces`]: the pieces between consecutive crossings along
//!    each arc;
//! 3. [`ContourPieces::keep_visible`]: the pieces whose midpoint ray meets no face but the
//!    arc's own, one ray per piece or by quantitative invisibility (`quantitative_invisibility`);
//! 4. [`ContourPieces::chain_closed_loops`]: the kept pieces chained into loops through their
//!    shared ends (the windowed silhouette first takes the chains that run from the window's
//!    boundary to it, and closes them along the boundary itself).

use crate::geometry::SphericalPolygon;
use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::NO_FACE;
use crate::geometry::silhouettes::exact_silhouette::{
    Degenerate, SweepScratch, blocked_ray, candidate_pairs,
};
use crate::geometry::silhouettes::quantitative_invisibility::{QiEdge, QiEnd, QiPiece, QiScratch};
use crate::math::Frame;
use glam::DVec3;

/// How far (a sine) both ends of an arc must be on one side of another arc's circle for the
/// pair to be passed over without its crossing test: far above the crossing test's tolerance
/// (1e-10) and the rounding of unit vectors.
const APART: f64 = 1e-8;

/// Where a piece of a contour arc starts or ends: a mesh vertex, an apparent intersection (by
/// id), or a point where the arc leaves the window (by id, windowed silhouette only).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum End {
    Vertex(u32),
    Crossing(u32),
    Boundary(u32),
}

impl End {
    /// Its kind (vertex, crossing, boundary point) and its id among them.
    #[inline]
    fn kind_and_id(self) -> (usize, u32) {
        match self {
            End::Vertex(v) => (0, v),
            End::Crossing(id) => (1, id),
            End::Boundary(id) => (2, id),
        }
    }
}

/// The part of a contour (or boundary) edge's arc in play, oriented with the mesh to its left
/// on the sphere.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ContourArc {
    /// Mesh vertices of the whole edge's ends, oriented (arcs sharing one do not cross).
    pub v: [u32; 2],
    /// The edge's faces (`NO_FACE` for a missing one).
    pub faces: [u32; 2],
    /// Unit normal of the arc's great circle.
    pub n: DVec3,
    /// The ends of the part in play (unit directions, world orientation).
    pub from: DVec3,
    pub to: DVec3,
    /// For an end on the window's boundary, the side of the window it lies on.
    pub from_side: Option<u32>,
    pub to_side: Option<u32>,
}

impl ContourArc {
    /// A whole arc, from vertex to vertex.
    #[inline]
    pub(crate) fn whole(v: [u32; 2], faces: [u32; 2], from: DVec3, to: DVec3, n: DVec3) -> Self {
        ContourArc {
            v,
            faces,
            n,
            from,
            to,
            from_side: None,
            to_side: None,
        }
    }

    /// The angle from the arc's start to `p` (on its great circle), measured in the arc's
    /// plane: the order of the crossings along the arc.
    #[inline]
    fn parameter(&self, p: DVec3) -> f64 {
        self.from.cross(p).dot(self.n).atan2(self.from.dot(p))
    }
}

/// Where a direction on an arc's great circle lies relative to the arc.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ArcPosition {
    /// Strictly inside both ends, by more than the caller's tolerance.
    Inside,
    /// Within the tolerance of an end (inside or out): undecidable, degenerate.
    AtEnd,
    Outside,
}

/// A piece of an arc between consecutive ends.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Piece {
    pub arc: u32,
    pub start: End,
    pub end: End,
    pub from: DVec3,
    pub to: DVec3,
    /// Chained into a loop (after [`ContourPieces::chain_closed_loops`], the kept pieces are
    /// exactly the used ones).
    pub used: bool,
}

/// The arcs of one silhouette call and everything the shared stages derive from them; reused
/// from call to call.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContourPieces {
    pub arcs: Vec<ContourArc>,
    /// (arc, parameter along it, crossing id) of every apparent intersection, twice each.
    cuts: Vec<(u32, f64, u32)>,
    pub crossings: Vec<DVec3>,
    /// The two arcs (indices into `arcs`) of each crossing.
    pub crossing_arcs: Vec<(u32, u32)>,
    pub pieces: Vec<Piece>,
    /// Boundary points: (side, position along the window's boundary, direction).
    pub boundary: Vec<(u32, f64, DVec3)>,
    /// Pieces kept, as indices into `pieces`.
    pub kept: Vec<u32>,
    /// The pieces of the closed loops in loop order, with whether the piece closes its loop.
    pub chain: Vec<(u32, bool)>,
    /// Kept pieces by the end they start at: per kind of end and id, the call's stamp and
    /// the first position in `kept` of a piece starting there; per position, the next one
    /// starting at the same end (`u32::MAX`: none). Lists run in `kept` order.
    start_heads: [Vec<(u32, u32)>; 3],
    start_next: Vec<u32>,
    start_stamp: u32,
    /// The sweep's boxes and active list ([`candidate_pairs`]), and the pairs it keeps.
    sweep: SweepScratch,
    pairs: Vec<(u32, u32)>,
}

impl ContourPieces {
    /// Clears everything of the last call.
    pub fn clear(&mut self) {
        self.arcs.clear();
        self.cuts.clear();
        self.crossings.clear();
        self.crossing_arcs.clear();
        self.pieces.clear();
        self.boundary.clear();
        self.kept.clear();
        self.chain.clear();
    }

    /// Stage 1: the apparent intersections of pairs of arcs without a common vertex (Eq. 4.4:
    /// the line through the point shared by the two arcs' planes), strictly inside both arcs
    /// as `position` judges; a crossing within its tolerance of an end is degenerate. All
    /// pairs with `all_pairs` or few arcs, else the pairs whose boxes meet, in the all-pairs
    /// order (the same result, bit for bit).
    pub(crate) fn find_crossings(
        &mut self,
        all_pairs: bool,
        position: impl Fn(&ContourArc, DVec3) -> ArcPosition,
    ) -> Result<(), Degenerate> {
        self.cuts.clear();
        self.crossings.clear();
        self.crossing_arcs.clear();
        let swept = !all_pairs
            && candidate_pairs(
                self.arcs.iter().map(|a| (a.from, a.to, a.n)),
                &mut self.sweep,
                &mut self.pairs,
            );
        let (arcs, cuts, crossings, crossing_arcs) = (
            &self.arcs,
            &mut self.cuts,
            &mut self.crossings,
            &mut self.crossing_arcs,
        );
        let mut test = |i: usize, j: usize| -> Result<(), Degenerate> {
            let (e, g) = (&arcs[i], &arcs[j]);
            if e.v.iter().any(|v| g.v.contains(v)) {
                return Ok(());
            }
            // An arc (shorter than π) whose ends lie on one side of the other's circle, both by
            // more than `APART`, stays on that side by more than `APART` (its height over the
            // circle is a sinusoid with no sign change on it): the circles' common points are
            // then that far outside it, which `position` (tolerance 1e-10) calls outside. No
            // square root for the pairs that cannot meet.
            let apart = |n: DVec3, a: &ContourArc| {
                let (s0, s1) = (n.dot(a.from), n.dot(a.to));
                (s0 > APART && s1 > APART) || (s0 < -APART && s1 < -APART)
            };
            if apart(e.n, g) || apart(g.n, e) {
                return Ok(());
            }
            let Some(mut p) = e.n.cross(g.n).try_normalize() else {
                return Ok(()); // arcs on one great circle: they overlap or miss, never cross
            };
            if p.dot(e.from + e.to) < 0.0 {
                p = -p;
            }
            match (position(e, p), position(g, p)) {
                (ArcPosition::Inside, ArcPosition::Inside) => {
                    let id = crossings.len() as u32;
                    crossings.push(p);
                    crossing_arcs.push((i as u32, j as u32));
                    cuts.push((i as u32, e.parameter(p), id));
                    cuts.push((j as u32, g.parameter(p), id));
                    Ok(())
                }
                (ArcPosition::Outside, _) | (_, ArcPosition::Outside) => Ok(()),
                _ => Err(Degenerate::CrossingAtEnd),
            }
        };
        if swept {
            for &(i, j) in &self.pairs {
                test(i as usize, j as usize)?;
            }
        } else {
            for i in 0..arcs.len() {
                for j in i + 1..arcs.len() {
                    test(i, j)?;
                }
            }
        }
        Ok(())
    }

    /// Stage 2: the pieces between consecutive crossings along each arc; an end on the
    /// window's boundary gets a boundary point of its own (its position along the boundary is
    /// the windowed silhouette's to fill in).
    pub(crate) fn split_into_pieces(&mut self) {
        self.cuts
            .sort_unstable_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
        self.pieces.clear();
        self.boundary.clear();
        let mut k = 0;
        for (i, e) in self.arcs.iter().enumerate() {
            let mut start = match e.from_side {
                Some(s) => {
                    let id = self.boundary.len() as u32;
                    self.boundary.push((s, 0.0, e.from));
                    End::Boundary(id)
                }
                None => End::Vertex(e.v[0]),
            };
            let mut from = e.from;
            // Bound: `k` only grows, up to `cuts.len()` over all arcs.
            while k < self.cuts.len() && self.cuts[k].0 == i as u32 {
                let id = self.cuts[k].2;
                let to = self.crossings[id as usize];
                self.pieces.push(Piece {
                    arc: i as u32,
                    start,
                    end: End::Crossing(id),
                    from,
                    to,
                    used: false,
                });
                start = End::Crossing(id);
                from = to;
                k += 1;
            }
            let end = match e.to_side {
                Some(s) => {
                    let id = self.boundary.len() as u32;
                    self.boundary.push((s, 0.0, e.to));
                    End::Boundary(id)
                }
                None => End::Vertex(e.v[1]),
            };
            self.pieces.push(Piece {
                arc: i as u32,
                start,
                end,
                from,
                to: e.to,
                used: false,
            });
        }
    }

    /// Stage 3: keeps the pieces whose midpoint ray meets no face but their arc's own. One ray
    /// per piece (`per_piece`, or a mesh without vertex-face lists), else quantitative
    /// invisibility: one ray per connected set of pieces, the count carried along. With
    /// `edge_on = Some(tol)` the faces whose plane passes within `tol` of `x` are left out
    /// (seen edge-on from a point on the mesh); `absent` names them, so that their edges count
    /// as boundary edges. `scan`: test every face along a ray (no hierarchy; the reference).
    /// Returns the rays cast.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn keep_visible(
        &mut self,
        poly: &IndexedPolyhedron,
        x: DVec3,
        per_piece: bool,
        scan: bool,
        edge_on: Option<f64>,
        absent: impl Fn(u32) -> bool,
        qi: &mut QiScratch,
    ) -> u32 {
        self.kept.clear();
        if per_piece || poly.index.vertex_stars.is_none() {
            for (pi, p) in self.pieces.iter().enumerate() {
                let mid = (p.from + p.to).normalize();
                let faces = self.arcs[p.arc as usize].faces;
                if !blocked_ray(poly, x, mid, faces, scan, edge_on) {
                    self.kept.push(pi as u32);
                }
            }
            return self.pieces.len() as u32;
        }
        qi.edges.clear();
        // A face left out is no face of its edge: the edge counts as a boundary edge.
        qi.edges.extend(self.arcs.iter().map(|a| QiEdge {
            v: a.v,
            faces: a.faces.map(|f| if absent(f) { NO_FACE } else { f }),
            n: a.n,
        }));
        let end = |e: End| match e {
            End::Vertex(v) => QiEnd::Vertex(v),
            End::Crossing(id) => QiEnd::Crossing(id),
            End::Boundary(_) => QiEnd::Other,
        };
        qi.pieces.clear();
        qi.pieces.extend(self.pieces.iter().map(|p| QiPiece {
            edge: p.arc,
            start: end(p.start),
            end: end(p.end),
            from: p.from,
            to: p.to,
        }));
        qi.solve_kept(poly, x, &self.crossings, edge_on, &mut self.kept)
    }

    /// Indexes the kept pieces by the end they start at, for [`ContourPieces::next_piece`].
    pub(crate) fn index_starts(&mut self) {
        // A new stamp marks every head of an earlier call stale, without clearing.
        self.start_stamp = self.start_stamp.wrapping_add(1);
        if self.start_stamp == 0 {
            self.start_heads.iter_mut().for_each(Vec::clear);
            self.start_stamp = 1;
        }
        let stamp = self.start_stamp;
        self.start_next.clear();
        self.start_next.resize(self.kept.len(), u32::MAX);
        // From the last kept piece to the first, each put at the head of its end's list.
        for pos in (0..self.kept.len()).rev() {
            let (kind, id) = self.pieces[self.kept[pos] as usize].start.kind_and_id();
            let heads = &mut self.start_heads[kind];
            if heads.len() <= id as usize {
                heads.resize(id as usize + 1, (0, u32::MAX));
            }
            let head = &mut heads[id as usize];
            self.start_next[pos] = if head.0 == stamp { head.1 } else { u32::MAX };
            *head = (stamp, pos as u32);
        }
    }

    /// The kept piece that follows one ending at `end`: the first unused kept piece (in
    /// `kept` order) that starts there.
    #[inline]
    pub(crate) fn next_piece(&self, end: End) -> Option<usize> {
        let (kind, id) = end.kind_and_id();
        let mut pos = match self.start_heads[kind].get(id as usize) {
            Some(&(stamp, first)) if stamp == self.start_stamp => first,
            _ => return None,
        };
        // Bound: a list holds each kept piece at most once.
        while pos != u32::MAX {
            let q = self.kept[pos as usize] as usize;
            if !self.pieces[q].used {
                return Some(q);
            }
            pos = self.start_next[pos as usize];
        }
        None
    }

    /// Stage 4: chains the unused kept pieces into closed loops through their shared ends
    /// ([`ContourPieces::next_piece`]), written into `out` in `frame`, and their pieces into
    /// `chain`. Call [`ContourPieces::index_starts`] first. A piece that starts or ends on the
    /// window's boundary here, or a chain that does not close, is degenerate (`out` is then
    /// left for the caller to clear).
    pub(crate) fn chain_closed_loops(
        &mut self,
        frame: &Frame,
        out: &mut SphericalPolygon,
    ) -> Result<(), Degenerate> {
        self.chain.clear();
        for s in 0..self.kept.len() {
            let first = self.kept[s] as usize;
            if self.pieces[first].used {
                continue;
            }
            let start = self.pieces[first].start;
            if matches!(start, End::Boundary(_)) {
                return Err(Degenerate::OpenChain);
            }
            // Bound: each step marks an unused kept piece used, and `next_piece` returns unused ones
            // only: at most `kept.len()` steps over all loops.
            let mut cur = first;
            loop {
                self.pieces[cur].used = true;
                out.push_vertex(frame.to_local(self.pieces[cur].from));
                let end = self.pieces[cur].end;
                self.chain.push((cur as u32, end == start));
                if end == start {
                    break;
                }
                if matches!(end, End::Boundary(_)) {
                    return Err(Degenerate::OpenChain);
                }
                cur = self.next_piece(end).ok_or(Degenerate::OpenChain)?;
            }
            out.close_loop();
        }
        Ok(())
    }

    /// Per piece of the last call that used quantitative invisibility: the ray through its
    /// midpoint (unit, world orientation), its edge's own faces, its count `c` and whether
    /// that count came from a ray at the piece (for tests: every count equals the ray's).
    pub fn qi_counts<'a>(
        qi: &'a QiScratch,
    ) -> impl Iterator<Item = (DVec3, [u32; 2], i32, bool)> + 'a {
        qi.pieces.iter().enumerate().map(|(q, p)| {
            (
                (p.from + p.to).normalize(),
                qi.edges[p.edge as usize].faces,
                qi.count[q],
                qi.from_ray[q],
            )
        })
    }
}
