//! The exact silhouette of any closed polyhedron seen from a point (001 Sect. 4.3): the
//! contour edges (Eq. 4.2), cut at their apparent intersections (Eq. 4.4), keeping the pieces
//! whose midpoint ray meets no other part of the mesh, chained into loops.
//!
//! An open mesh (an oriented manifold with boundary edges, such as Blender's monkey) takes the
//! same path with its boundary edges added to the contour edges: the image of a surface ends
//! only where it folds (a contour edge) or where it stops (a boundary edge), so the outline of
//! its image is made of pieces of those two kinds, and a piece is on the outline exactly when
//! the ray through it meets no other face (docs/silhouettes.md, "Open meshes"). The result may have
//! several loops and holes; each loop is positively oriented around the region the mesh covers
//! (see [`SphericalPolygon`]), so holes come out negatively oriented.
//!
//! This is the on-the-fly method: quadratic in the contour edges plus one ray test per piece.
//! It is the oracle and the leaf generator of the precomputed (BSP) silhouettes.
//!
//! Degenerate configurations are detected, never nudged: a face plane through the point, an
//! apparent intersection at (or within rounding of) an edge's end, or pieces that do not close
//! into loops return [`Degenerate`]; the caller then takes the face-by-face path, which is
//! exact there.

use crate::geometry::SphericalPolygon;
use crate::geometry::mesh::edge_hierarchy::{
    ContourScratch, contour_edge_indices, coplanar_tolerance,
};
use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::{NO_FACE, Polyhedron};
use crate::geometry::mesh::ray::Ray;
use crate::geometry::mesh::triangle::{PreparedRay, is_degenerate};
use crate::geometry::silhouettes::contour_pieces::{ArcPosition, ContourArc, ContourPieces, End};
use crate::geometry::silhouettes::quantitative_invisibility::QiScratch;
use crate::geometry::silhouettes::silhouette::is_front_facing;
use crate::math::Frame;
use glam::DVec3;

/// Why no exact silhouette was produced at a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Degenerate {
    /// The point lies (within rounding) in the plane of a face.
    CoplanarFace,
    /// Two contour edges appear to meet at, or within rounding of, the end of one of them.
    CrossingAtEnd,
    /// The kept pieces do not close into loops.
    OpenChain,
    /// The windowed silhouette cannot decide the configuration inside its window (a contour
    /// vertex or crossing on the window's boundary, a window too wide, chains that do not
    /// alternate along it): the whole silhouette decides instead.
    Window,
    /// A walk took more steps than its input allows (see each walk's bound): a structure that
    /// rounding left inconsistent. The point takes a path that is exact there.
    BoundCrossed,
}

/// Reusable buffers of [`exact_silhouette`].
#[derive(Clone, Debug, Default)]
pub struct ExactSilhouetteScratch {
    /// The contour arcs and the stages shared with the windowed silhouette.
    pieces: ContourPieces,
    /// Edges gathered by a lookup in a hoisted tree (`bsp_hoisted`), reused.
    pub hoisted: Vec<[u32; 2]>,
    /// Test every pair of contour edges and every face along each piece's ray, and scan every
    /// edge for the contour: no sweep, no face or edge hierarchy (the reference all are tested
    /// against).
    pub all_pairs: bool,
    /// Find the contour edges by the scan even where the mesh has an edge hierarchy (the
    /// oracle of the hierarchy's tests; implied by `all_pairs`).
    pub scan_edges: bool,
    /// The contour edges' indices, ascending, and the buffers of their search.
    contour_ids: Vec<u32>,
    contour: ContourScratch,
    /// One ray per piece instead of quantitative invisibility (implied by `all_pairs`).
    pub per_piece_rays: bool,
    /// The propagation of quantitative invisibility (step 4).
    pub qi: QiScratch,
}

/// Buffers of [`candidate_pairs`].
#[derive(Clone, Debug, Default)]
pub(crate) struct SweepScratch {
    /// Per arc: its box in direction space.
    boxes: Vec<[DVec3; 2]>,
    order: Vec<(i64, u32)>,
    active: Vec<u32>,
    pairs: PairSortScratch,
}

/// Contour counts below which every pair is tested (the sweep does not pay).
pub(crate) const SWEEP_MIN_EDGES: usize = 48;

/// How much the arcs' boxes are widened: far above `END_TOLERANCE` (an angle, and so at most
/// that distance between unit vectors) and the rounding of the boxes themselves.
const SWEEP_MARGIN: f64 = 1e-8;

/// The box (in direction space) of the great-circle arc from `a` to `b` (shorter than π) with
/// unit normal `n`: its ends, and for each axis the two points of the great circle extreme
/// along it (±(e_k − n n_k), normalised) where they lie on the arc.
fn arc_box(a: DVec3, b: DVec3, n: DVec3) -> [DVec3; 2] {
    let (mut lo, mut hi) = (a.min(b), a.max(b));
    // A direction c of the circle is on the arc iff (a × c) · n ≥ 0 and (c × b) · n ≥ 0, that
    // is c · (n × a) ≥ 0 and c · (b × n) ≥ 0: signs that do not depend on c's length, so the
    // extremes are normalised only when on the arc. (Where rounding could tell the normalised
    // and the unnormalised direction apart, the extreme is within rounding of an end, which
    // the box holds already up to far less than its margin.)
    let (na, bn) = (n.cross(a), b.cross(n));
    for k in 0..3 {
        let mut axis = DVec3::ZERO;
        axis[k] = 1.0;
        let u = axis - n * n[k];
        let (sa, sb) = (u.dot(na), u.dot(bn));
        let (plus, minus) = (sa >= 0.0 && sb >= 0.0, sa <= 0.0 && sb <= 0.0);
        if !(plus || minus) {
            continue;
        }
        let Some(d) = u.try_normalize() else {
            continue; // the circle is perpendicular to the axis: constant along it
        };
        for (c, on) in [(d, plus), (-d, minus)] {
            if on {
                (lo, hi) = (lo.min(c), hi.max(c));
            }
        }
    }
    [lo - SWEEP_MARGIN, hi + SWEEP_MARGIN]
}

/// The pairs of arcs (from, to, unit normal of the great circle; each shorter than π) that
/// can cross or touch, found by a sweep instead of testing all pairs: two arcs meet only where
/// their boxes in direction space do (each box holds its arc exactly: its ends and the
/// circle's extremes on it), and the boxes are widened by [`SWEEP_MARGIN`], so that every pair
/// that comes within the tolerance of touching (which the callers report as degenerate) is
/// kept too. The sweep runs along x, testing y and z. The pairs are sorted, so that the caller
/// meets them in the order of the all-pairs loop and its result is the same, bit for bit.
/// Returns `false` without sweeping for fewer than [`SWEEP_MIN_EDGES`] arcs: test all pairs.
pub(crate) fn candidate_pairs(
    arcs: impl ExactSizeIterator<Item = (DVec3, DVec3, DVec3)>,
    sweep: &mut SweepScratch,
    out: &mut Vec<(u32, u32)>,
) -> bool {
    if arcs.len() < SWEEP_MIN_EDGES {
        return false;
    }
    sweep.boxes.clear();
    sweep.boxes.extend(arcs.map(|(a, b, n)| arc_box(a, b, n)));
    let boxes = &sweep.boxes;
    // By the boxes' low x, as `f64::total_cmp` orders them: that order is the order of these
    // integers, which compare without reading the boxes again.
    sweep.order.clear();
    sweep.order.extend(boxes.iter().enumerate().map(|(i, b)| {
        let bits = b[0].x.to_bits() as i64;
        (bits ^ (((bits >> 63) as u64) >> 1) as i64, i as u32)
    }));
    sweep.order.sort_unstable();
    out.clear();
    sweep.active.clear();
    for &(_, i) in &sweep.order {
        let [lo, hi] = boxes[i as usize];
        sweep.active.retain(|&j| boxes[j as usize][1].x >= lo.x);
        for &j in &sweep.active {
            let [lj, hj] = boxes[j as usize];
            if lj.y <= hi.y && lo.y <= hj.y && lj.z <= hi.z && lo.z <= hj.z {
                out.push((i.min(j), i.max(j)));
            }
        }
        sweep.active.push(i);
    }
    sort_pairs(out, boxes.len(), &mut sweep.pairs);
    true
}

/// Sorts pairs `(i, j)` with `i < j < n`: counted into one bucket per `i` (a prefix sum over
/// `n` counters), then each bucket's few `j` sorted in place. The order of `sort_unstable`, in
/// linear time.
fn sort_pairs(pairs: &mut Vec<(u32, u32)>, n: usize, scratch: &mut PairSortScratch) {
    let PairSortScratch { next, sorted } = scratch;
    next.clear();
    next.resize(n + 1, 0);
    for &(i, _) in pairs.iter() {
        next[i as usize + 1] += 1;
    }
    for k in 0..n {
        next[k + 1] += next[k];
    }
    sorted.clear();
    sorted.resize(pairs.len(), (0, 0));
    for &p in pairs.iter() {
        let slot = &mut next[p.0 as usize];
        sorted[*slot as usize] = p;
        *slot += 1;
    }
    // Bucket i now ends at next[i]: it began where bucket i − 1 ended. Buckets hold a few
    // pairs: insertion sort.
    let mut begin = 0;
    for &end in &next[..n] {
        let bucket = &mut sorted[begin..end as usize];
        for a in 1..bucket.len() {
            let mut b = a;
            while b > 0 && bucket[b - 1] > bucket[b] {
                bucket.swap(b - 1, b);
                b -= 1;
            }
        }
        begin = end as usize;
    }
    std::mem::swap(pairs, sorted);
}

/// Reusable buffers of [`sort_pairs`].
#[derive(Clone, Debug, Default)]
pub(crate) struct PairSortScratch {
    next: Vec<u32>,
    sorted: Vec<(u32, u32)>,
}

/// What [`exact_silhouette`] found, for statistics and the debugger.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactSilhouetteStats {
    pub contour_edges: u32,
    pub apparent_intersections: u32,
    pub pieces: u32,
    pub kept: u32,
    /// Rays cast to decide which pieces are kept.
    pub rays: u32,
}

/// Angular tolerance (radians) below which an apparent intersection is taken to be at an end.
const END_TOLERANCE: f64 = 1e-10;

/// The silhouette of the mesh `poly` seen from `x`, in `frame`, as positively oriented loops in
/// `out` (cleared first). A closed mesh must have `x` outside it; an open one must be an
/// oriented manifold (no non-manifold edges).
pub fn exact_silhouette(
    poly: &IndexedPolyhedron,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    scratch: &mut ExactSilhouetteScratch,
) -> Result<ExactSilhouetteStats, Degenerate> {
    out.clear();
    let tol = coplanar_tolerance(poly);
    let mut stats = ExactSilhouetteStats::default();

    // 0./1. No face plane through the point, and the contour edges (through the normal-cone
    //    hierarchy where the mesh has one: the scan's list, in its order), oriented so that
    //    the mesh lies to their left on the sphere.
    scratch.contour.scan = scratch.all_pairs || scratch.scan_edges;

    if contour_edge_indices(
        poly,
        x,
        Some(tol),
        &mut scratch.contour,
        &mut scratch.contour_ids,
    )
    .is_err()
    {
        return Err(Degenerate::CoplanarFace);
    }
    let pieces = &mut scratch.pieces;
    pieces.clear();
    for &ei in &scratch.contour_ids {
        let e = &poly.edges[ei as usize];
        // The orientation of `contour_edges`: the mesh to the left on the sphere (for a
        // boundary edge, its one face, front- or back-facing).
        let [i, j] = if is_front_facing(poly, e.faces[0] as usize, x) {
            [e.v[1], e.v[0]]
        } else {
            [e.v[0], e.v[1]]
        };
        let a = (poly.vertices[i as usize] - x).normalize();
        let b = (poly.vertices[j as usize] - x).normalize();
        let c = a.cross(b);
        let Some(n) = c.try_normalize() else {
            // An edge seen end-on: zero length, no area; it cannot bound anything.
            continue;
        };
        pieces
            .arcs
            .push(ContourArc::whole([i, j], e.faces, a, b, n));
    }
    stats.contour_edges = pieces.arcs.len() as u32;

    // 2.-5. The stages shared with the windowed silhouette (`contour_pieces`): apparent
    //    intersections (Eq. 4.4), pieces between them, the pieces whose midpoint ray meets no
    //    face but the edge's own two (one ray per piece, or quantitative invisibility on a
    //    manifold mesh), chained into loops through their shared ends.
    pieces.find_crossings(scratch.all_pairs, arc_position)?;
    stats.apparent_intersections = pieces.crossings.len() as u32;
    pieces.split_into_pieces();
    stats.pieces = pieces.pieces.len() as u32;
    stats.rays = pieces.keep_visible(
        poly,
        x,
        scratch.all_pairs || scratch.per_piece_rays,
        scratch.all_pairs,
        None,
        |f| f == NO_FACE,
        &mut scratch.qi,
    );
    stats.kept = pieces.kept.len() as u32;
    pieces.index_starts();
    if let Err(e) = pieces.chain_closed_loops(frame, out) {
        out.clear();
        return Err(e);
    }
    Ok(stats)
}

impl ExactSilhouetteScratch {
    /// Per piece of the last call that used quantitative invisibility: the ray through its
    /// midpoint (unit, world orientation), its edge's own faces, its count `c` and whether
    /// that count came from a ray at the piece (for tests: every count equals the ray's).
    pub fn qi_counts(&self) -> impl Iterator<Item = (DVec3, [u32; 2], i32, bool)> + '_ {
        ContourPieces::qi_counts(&self.qi)
    }

    /// The apparent intersections found by the last call (unit directions from the point, in
    /// world orientation), for the debugger.
    pub(crate) fn crossings(&self) -> &[DVec3] {
        &self.pieces.crossings
    }

    /// The pieces of contour edges the last successful call rejected (their midpoint ray met
    /// the mesh), as (from, to) unit directions in world orientation, for the debugger.
    pub(crate) fn rejected_pieces(&self) -> impl Iterator<Item = [DVec3; 2]> + '_ {
        self.pieces
            .pieces
            .iter()
            .filter(|p| !p.used)
            .map(|p| [p.from, p.to])
    }
}

/// A vertex of a silhouette loop as the mesh defines it, valid wherever the structure of the
/// silhouette stays the same (a BSP cell, 001 Sect. 5.2): a mesh vertex, or the apparent
/// intersection of two mesh edges given by their end vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SilhouettePoint {
    Vertex(u32),
    Crossing([u32; 2], [u32; 2]),
}

impl SilhouettePoint {
    /// The 32-bit encoding of 001 Sect. 5.4: four 8-bit vertex indices, the ends of the two
    /// edges of a crossing, or one vertex index four times. `None` if an index exceeds 255
    /// (the encoding is for meshes of at most 256 vertices).
    pub fn pack(&self) -> Option<u32> {
        let [a, b, c, d] = match *self {
            SilhouettePoint::Vertex(v) => [v; 4],
            SilhouettePoint::Crossing([a, b], [c, d]) => [a, b, c, d],
        };
        [a, b, c, d]
            .iter()
            .all(|&i| i < 256)
            .then_some(a | b << 8 | c << 16 | d << 24)
    }

    /// The point a [`SilhouettePoint::pack`] code stands for. Two edges of a crossing share no
    /// vertex, so four equal indices can only be a vertex.
    pub fn unpack(code: u32) -> SilhouettePoint {
        let i = |k: u32| (code >> (8 * k)) & 0xff;
        let (a, b, c, d) = (i(0), i(1), i(2), i(3));
        if a == b && b == c && c == d {
            SilhouettePoint::Vertex(a)
        } else {
            SilhouettePoint::Crossing([a, b], [c, d])
        }
    }

    /// The unit direction of the point seen from `x` (Eq. 4.4 for a crossing: the line shared
    /// by the planes of the two arcs, on the side of the first arc).
    #[inline]
    pub fn direction(&self, poly: &Polyhedron, x: DVec3) -> Option<DVec3> {
        let dir = |v: u32| (poly.vertices[v as usize] - x).try_normalize();
        match *self {
            SilhouettePoint::Vertex(v) => dir(v),
            SilhouettePoint::Crossing([a1, a2], [b1, b2]) => {
                let (a1, a2) = (dir(a1)?, dir(a2)?);
                let (b1, b2) = (dir(b1)?, dir(b2)?);
                let p = a1.cross(a2).cross(b1.cross(b2)).try_normalize()?;
                Some(if p.dot(a1 + a2) < 0.0 { -p } else { p })
            }
        }
    }
}

/// How a tree of precomputed silhouettes codes a [`SilhouettePoint`] in 32 bits.
///
/// 001 Sect. 5.4 packs four 8-bit vertex indices, which limits trees to meshes of 256
/// vertices. Past that, a crossing is coded by its two *edges* (15 bits each) and a vertex by
/// its index with the top bit set: trees for meshes of up to 32,768 edges, in the same 32
/// bits, so that nothing else about the trees changes. A crossing read back from its edges has
/// each edge's ends in the mesh's order rather than the contour's; [`SilhouettePoint::direction`]
/// gives the same bits either way (swapping the ends negates a cross product exactly, and the
/// side is chosen by the sum of the ends).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PointCoding {
    /// 001 Sect. 5.4: four 8-bit vertex indices.
    #[default]
    Vertices8,
    /// A vertex as `VERTEX_BIT | v`, a crossing as `e1 << 15 | e2` (edge indices).
    EdgePairs,
}

/// The top bit: an [`PointCoding::EdgePairs`] code of a vertex.
const VERTEX_BIT: u32 = 1 << 31;

/// Edges at most for [`PointCoding::EdgePairs`] (15 bits per edge index).
pub const EDGE_PAIRS_MAX_EDGES: usize = 1 << 15;

impl PointCoding {
    /// The coding a tree of `poly` uses: the thesis' for up to 256 vertices, edge pairs up to
    /// [`EDGE_PAIRS_MAX_EDGES`] edges; `None` past that (no tree).
    pub fn for_mesh(poly: &Polyhedron) -> Option<PointCoding> {
        if poly.vertices.len() <= 256 {
            Some(PointCoding::Vertices8)
        } else if poly.edges.len() <= EDGE_PAIRS_MAX_EDGES
            && poly.vertices.len() < VERTEX_BIT as usize
        {
            Some(PointCoding::EdgePairs)
        } else {
            None
        }
    }

    /// The code of `p`; `edge_of` finds the edge with the given ends (in either order).
    /// `None` when an index does not fit.
    pub fn pack(
        self,
        p: &SilhouettePoint,
        edge_of: impl Fn([u32; 2]) -> Option<u32>,
    ) -> Option<u32> {
        match self {
            PointCoding::Vertices8 => p.pack(),
            PointCoding::EdgePairs => match *p {
                SilhouettePoint::Vertex(v) => (v < VERTEX_BIT).then_some(VERTEX_BIT | v),
                SilhouettePoint::Crossing(a, b) => {
                    let (ea, eb) = (edge_of(a)?, edge_of(b)?);
                    let fits = |e: u32| (e as usize) < EDGE_PAIRS_MAX_EDGES;
                    (fits(ea) && fits(eb)).then_some(ea << 15 | eb)
                }
            },
        }
    }

    /// The point a code stands for on `poly` (whose indices [`PointCoding::in_range`] checked).
    #[inline]
    pub fn unpack(self, code: u32, poly: &Polyhedron) -> SilhouettePoint {
        match self {
            PointCoding::Vertices8 => SilhouettePoint::unpack(code),
            PointCoding::EdgePairs if code & VERTEX_BIT != 0 => {
                SilhouettePoint::Vertex(code & !VERTEX_BIT)
            }
            PointCoding::EdgePairs => SilhouettePoint::Crossing(
                poly.edges[(code >> 15) as usize].v,
                poly.edges[(code & 0x7fff) as usize].v,
            ),
        }
    }

    /// Whether every index of `code` is in range for a mesh of `vertices` vertices and `edges`
    /// edges (a tree read from a file is checked before use).
    pub(crate) fn in_range(self, code: u32, vertices: usize, edges: usize) -> bool {
        match self {
            PointCoding::Vertices8 => match SilhouettePoint::unpack(code) {
                SilhouettePoint::Vertex(v) => (v as usize) < vertices,
                SilhouettePoint::Crossing(a, b) => {
                    a.iter().chain(&b).all(|&v| (v as usize) < vertices)
                }
            },
            PointCoding::EdgePairs if code & VERTEX_BIT != 0 => {
                ((code & !VERTEX_BIT) as usize) < vertices
            }
            PointCoding::EdgePairs => {
                ((code >> 15) as usize) < edges && ((code & 0x7fff) as usize) < edges
            }
        }
    }
}

/// The loops of the last successful [`exact_silhouette`] call made with `scratch`, as
/// [`SilhouettePoint`]s; each loop is followed by `None`.
pub fn symbolic_loops(scratch: &ExactSilhouetteScratch, out: &mut Vec<Option<SilhouettePoint>>) {
    out.clear();
    let pieces = &scratch.pieces;
    for &(piece, closes) in &pieces.chain {
        let p = &pieces.pieces[piece as usize];
        out.push(Some(match p.start {
            End::Vertex(v) => SilhouettePoint::Vertex(v),
            End::Crossing(id) => {
                let (i, j) = pieces.crossing_arcs[id as usize];
                SilhouettePoint::Crossing(pieces.arcs[i as usize].v, pieces.arcs[j as usize].v)
            }
            End::Boundary(_) => unreachable!("a whole silhouette has no window boundary"),
        }));
        if closes {
            out.push(None);
        }
    }
}

/// The position of `p` (on the arc's great circle, on the side of the arc's midpoint) on the
/// arc: the signed angles θ from the start and len − θ to the end are read from their sines,
/// which equal the angles to first order where the tolerance applies; an angle past π/2 (cosine
/// negative) is far from that end whatever its sine.
#[inline]
fn arc_position(e: &ContourArc, p: DVec3) -> ArcPosition {
    let from_start = (e.from.cross(p).dot(e.n), e.from.dot(p));
    let to_end = (p.cross(e.to).dot(e.n), p.dot(e.to));
    let side = |(sin, cos): (f64, f64)| {
        if sin > END_TOLERANCE || (sin > 0.0 && cos < 0.0) {
            ArcPosition::Inside
        } else if sin > -END_TOLERANCE && cos > 0.0 {
            ArcPosition::AtEnd
        } else {
            ArcPosition::Outside
        }
    };
    match (side(from_start), side(to_end)) {
        (ArcPosition::Inside, ArcPosition::Inside) => ArcPosition::Inside,
        (ArcPosition::Outside, _) | (_, ArcPosition::Outside) => ArcPosition::Outside,
        _ => ArcPosition::AtEnd,
    }
}

/// [`blocked`] through the face hierarchy where the mesh has one (the windowed silhouette).
#[inline]
/// With `edge_on = Some(tol)`, the faces whose plane passes within `tol` of `x` are left out
/// (seen edge-on from a point on the mesh: `windowed_silhouette`).
pub(crate) fn blocked_ray(
    poly: &IndexedPolyhedron,
    x: DVec3,
    dir: DVec3,
    skip: [u32; 2],
    scan: bool,
    edge_on: Option<f64>,
) -> bool {
    let Some(tol) = edge_on else {
        return blocked(poly, x, dir, skip, scan);
    };
    let ray = PreparedRay::new(&Ray::new(x, dir));
    let hit_face =
        |f: usize| poly.face_planes[f].eval(x).abs() > tol && face_hit(poly, x, dir, &ray, skip, f);
    match &poly.index.face_bvh {
        Some(bvh) => bvh.any(x, dir, |f| hit_face(f as usize)),
        None => (0..poly.face_count()).any(hit_face),
    }
}

/// Does the ray from `x` along `dir` meet a face of `poly` other than `skip`, the two faces of
/// the piece's edge? Hits before and beyond the edge both count: a piece with part of the mesh
/// in front of it or directly behind it separates nothing from the background.
fn blocked(poly: &IndexedPolyhedron, x: DVec3, dir: DVec3, skip: [u32; 2], scan: bool) -> bool {
    let ray = PreparedRay::new(&Ray::new(x, dir));
    let hit_face = |f: usize| face_hit(poly, x, dir, &ray, skip, f);
    // The face hierarchy hands out the faces whose box the ray meets; the test of each is the
    // same as the scan's, so the answer is too.
    match &poly.index.face_bvh {
        Some(bvh) if !scan => bvh.any(x, dir, |f| hit_face(f as usize)),
        _ => (0..poly.face_count()).any(hit_face),
    }
}

/// How many faces of `poly` other than `skip` the ray from `x` along `dir` meets: the count
/// `c` of quantitative invisibility, by the very test of `blocked` (which is `c > 0`).
pub fn count_ray_hits(
    poly: &IndexedPolyhedron,
    x: DVec3,
    dir: DVec3,
    skip: [u32; 2],
    scan: bool,
) -> u32 {
    let ray = PreparedRay::new(&Ray::new(x, dir));
    count_faces(poly, x, dir, scan, |f| {
        face_hit(poly, x, dir, &ray, skip, f)
    })
}

/// [`count_ray_hits`] through the face hierarchy; with `edge_on = Some(tol)` the faces whose
/// plane passes within `tol` of `x` are left out, as [`blocked_ray`] leaves them.
pub(crate) fn count_ray_hits_edge_on(
    poly: &IndexedPolyhedron,
    x: DVec3,
    dir: DVec3,
    skip: [u32; 2],
    edge_on: Option<f64>,
) -> u32 {
    let Some(tol) = edge_on else {
        return count_ray_hits(poly, x, dir, skip, false);
    };
    let ray = PreparedRay::new(&Ray::new(x, dir));
    count_faces(poly, x, dir, false, |f| {
        poly.face_planes[f].eval(x).abs() > tol && face_hit(poly, x, dir, &ray, skip, f)
    })
}

/// How many faces `hit` accepts among those the ray from `x` along `dir` may meet: through the
/// face hierarchy (whose leaves partition the faces: every face once, never stopping early)
/// unless `scan`, else every face.
fn count_faces(
    poly: &IndexedPolyhedron,
    x: DVec3,
    dir: DVec3,
    scan: bool,
    hit: impl Fn(usize) -> bool,
) -> u32 {
    match &poly.index.face_bvh {
        Some(bvh) if !scan => {
            let mut c = 0;
            bvh.any(x, dir, |f| {
                c += u32::from(hit(f as usize));
                false
            });
            c
        }
        _ => (0..poly.face_count()).filter(|&f| hit(f)).count() as u32,
    }
}

/// The face test of [`blocked`] and [`count_ray_hits`]: does `ray` (from `x` along `dir`) meet
/// face `f`, unless it is one of `skip`?
#[inline]
fn face_hit(
    poly: &Polyhedron,
    x: DVec3,
    dir: DVec3,
    ray: &PreparedRay,
    skip: [u32; 2],
    f: usize,
) -> bool {
    if skip.contains(&(f as u32)) {
        return false;
    }
    let t_min = 1e-9 * poly.radius.max(f64::MIN_POSITIVE);
    // The ray meets the face's plane ahead of x only when it heads toward that plane (x
    // is never in a face plane here: the caller returned `CoplanarFace`).
    let plane = &poly.face_planes[f];
    if plane.eval(x) * plane.n.dot(dir) >= 0.0 {
        return false;
    }
    let idx = poly.face(f);
    let v0 = poly.vertices[idx[0] as usize];
    (1..idx.len() - 1).any(|k| {
        let (v1, v2) = (
            poly.vertices[idx[k] as usize],
            poly.vertices[idx[k + 1] as usize],
        );
        !is_degenerate(v0, v1, v2) && ray.intersect(v0, v1, v2, t_min, f64::INFINITY).is_some()
    })
}
