//! Quantitative invisibility (Appel 1967; Markosian et al. 1997) for the exact silhouettes
//! ([`exact_silhouette`](crate::geometry::silhouettes::exact_silhouette) and the windowed one): instead of one ray per
//! piece of contour edge, one ray per connected set of pieces, and the count of faces the ray
//! meets carried from piece to piece by exact local rules (docs/silhouettes.md, "Quantitative
//! invisibility").
//!
//! For a piece of the contour edge `e`, `c` is the number of faces other than `e`'s own two
//! that the ray from `x` through the piece's midpoint meets (before or beyond the edge): the
//! piece is kept iff `c = 0`. Along the pieces and between them, `c` changes only by:
//!
//! * **crossings** ([`crossing_step`]): passing the apparent intersection `p` of `e` with
//!   another contour edge `g`, `c` changes by `+2` if the travel direction `e.n × p` leads to
//!   the mesh side of `g` (`g.n · (e.n × p) > 0`, where the ray meets both of `g`'s faces next
//!   to `g`) and by `−2` otherwise; and across the crossing from the piece of `e` after `p` to
//!   the piece of `g` after `p` by `−2` or `+2` for the same sign ([`crossing_transfer`]);
//! * **vertices** ([`vertex_step`]): from a piece of `e1` ending at a contour vertex `v` to a
//!   piece of `e2` at `v`, `c` changes by the faces of `v`'s star (other than each edge's own)
//!   that cover the direction of `e2` near `v` minus those that cover the direction of `e1`,
//!   decided by the signs of determinants of the directions from `x` to `v` and its
//!   neighbours (the wedge of each fan triangle at `v`).
//!
//! Whatever is not decided exactly (edges sharing a face, a sign within rounding of zero, a
//! piece shorter than [`TINY`] next to a link) leaves the link unused, and a piece no used link
//! reaches gets its own ray: the counts are those of the per-piece rays, never guesses. A count
//! that comes out negative, or two routes that give one piece two counts, send the whole call
//! back to one ray per piece.

use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::{NO_FACE, Polyhedron};
use crate::geometry::mesh::triangle::is_degenerate;
use glam::DVec3;

/// The star of each vertex, for the vertex rule: per vertex, the wedges at it of its faces'
/// fan triangles (those the ray test uses), grouped by face.
#[derive(Clone, Debug, Default)]
pub struct VertexStars {
    start: Vec<u32>,
    wedges: Vec<Wedge>,
}

/// The corner at a vertex `v` of one fan triangle `(v, p, q)` (in the face's order) of
/// `face`. Degenerate triangles are left out, as the ray test skips them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Wedge {
    pub face: u32,
    pub p: u32,
    pub q: u32,
}

impl VertexStars {
    /// The stars of every vertex of `poly`. Built from its geometry as well as its topology
    /// (which fan triangles are degenerate): a moved mesh builds its own.
    pub fn build(poly: &Polyhedron) -> Self {
        // Each fan triangle, in face order, with whether it is degenerate.
        let fans = || {
            (0..poly.face_count()).flat_map(move |f| {
                let idx = poly.face(f);
                (1..idx.len().saturating_sub(1))
                    .map(move |k| (f as u32, [idx[0], idx[k], idx[k + 1]]))
            })
        };
        let degenerate: Vec<bool> = fans()
            .map(|(_, tri)| {
                let [a, b, c] = tri.map(|i| poly.vertices[i as usize]);
                is_degenerate(a, b, c)
            })
            .collect();
        // Three wedges per fan triangle that is not degenerate, placed by a counting sort on
        // their vertex: each vertex's wedges stay in face order, grouped by face.
        let mut start = vec![0u32; poly.vertices.len() + 1];
        for ((_, tri), &skip) in fans().zip(&degenerate) {
            if !skip {
                for v in tri {
                    start[v as usize + 1] += 1;
                }
            }
        }
        for i in 0..poly.vertices.len() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let empty = Wedge {
            face: 0,
            p: 0,
            q: 0,
        };
        let mut wedges = vec![empty; start[poly.vertices.len()] as usize];
        for ((face, tri), &skip) in fans().zip(&degenerate) {
            if skip {
                continue; // the ray test skips it too
            }
            for at in 0..3 {
                let v = tri[at] as usize;
                wedges[fill[v] as usize] = Wedge {
                    face,
                    p: tri[(at + 1) % 3],
                    q: tri[(at + 2) % 3],
                };
                fill[v] += 1;
            }
        }
        VertexStars { start, wedges }
    }

    /// The wedges at `v`, grouped by face.
    #[inline]
    pub(crate) fn wedges(&self, v: u32) -> &[Wedge] {
        &self.wedges[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }
}

/// Pieces whose angle (its sine) is below this take part in no link: the order of two cuts so
/// close together, or of a cut and an end, is not trusted.
pub(crate) const TINY: f64 = 1e-8;

/// Relative size below which a sign (of a determinant of directions, or of the sine of a
/// crossing angle) is not trusted.
const SIGN_TOL: f64 = 1e-10;

/// A contour edge as the propagation sees it: oriented ends (mesh vertices), own faces, unit
/// normal of its great circle (the mesh to its left: the side where `n · d > 0`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct QiEdge {
    pub v: [u32; 2],
    pub faces: [u32; 2],
    pub n: DVec3,
}

/// Where a piece starts or ends, for the propagation: a mesh vertex, a crossing (its id), or
/// anything else (the window's boundary), which links nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum QiEnd {
    Vertex(u32),
    Crossing(u32),
    Other,
}

/// A piece: its edge (index into the edges), ends, and unit end directions. The pieces of one
/// edge are consecutive and in order along it, joined at crossings.
#[derive(Clone, Copy, Debug)]
pub(crate) struct QiPiece {
    pub edge: u32,
    pub start: QiEnd,
    pub end: QiEnd,
    pub from: DVec3,
    pub to: DVec3,
}

/// What the propagation did at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QiStats {
    /// Rays cast (one per piece in the per-piece mode).
    pub rays: u32,
    /// Links between pieces left unused because they could not be decided exactly.
    pub undecided_links: u32,
    /// Connected sets of pieces through all links, decided or not (computed only when
    /// [`QiScratch::measure`] is set): `rays − components` rays were cast because of undecided
    /// links (the fallback).
    pub components: u32,
    /// The call went back to one ray per piece (a negative or contradictory count).
    pub whole_fallback: bool,
}

const UNKNOWN: i32 = i32::MIN;

/// Buffers of the propagation.
#[derive(Clone, Debug, Default)]
pub struct QiScratch {
    pub(crate) edges: Vec<QiEdge>,
    pub(crate) pieces: Vec<QiPiece>,
    /// The count `c` of each piece, after [`QiScratch::solve`].
    pub(crate) count: Vec<i32>,
    /// Whether the count came from a ray at the piece.
    pub(crate) from_ray: Vec<bool>,
    /// Per piece whose count came across a mesh vertex: the piece it came from and the
    /// vertex. The step back across that vertex is the same step negated, so it is not
    /// evaluated again.
    via_vertex: Vec<(u32, u32)>,
    tiny: Vec<bool>,
    /// Per crossing: the pieces that start at it (one on each edge).
    after: Vec<[u32; 2]>,
    /// (vertex, piece) for every piece end at a mesh vertex, and the next entry of the same
    /// vertex (`u32::MAX`: none): each vertex's entries form a list in increasing piece order.
    at_vertex: Vec<(u32, u32)>,
    next_at_vertex: Vec<u32>,
    /// Per mesh vertex: the first entry of its list while the lists are built (`u32::MAX`
    /// otherwise: every entry set is reset before the lists are used).
    vertex_head: Vec<u32>,
    /// Per piece end (2 q for its start, 2 q + 1 for its end) at a mesh vertex: the first
    /// entry of that vertex's list in `at_vertex`.
    vertex_group: Vec<u32>,
    stack: Vec<u32>,
    parent: Vec<u32>,
    /// Count the connected sets of pieces too ([`QiStats::components`]), for tests and the
    /// benchmark.
    pub measure: bool,
    pub stats: QiStats,
}

/// How many faces an edge has in the count: two for a contour edge, one for a boundary edge
/// (of an open mesh, or next to a face left out; its other face is [`NO_FACE`]).
#[inline]
fn face_count(e: &QiEdge) -> i32 {
    e.faces.iter().filter(|&&f| f != NO_FACE).count() as i32
}

/// `g.n · (e.n × p)`: positive when the travel direction along `e` past `p` leads to `g`'s
/// mesh side; `None` within rounding of zero, or when `e` and `g` share a face (the faces met
/// next to `p` are then not the same for both).
#[inline]
fn crossing_side(e: &QiEdge, g: &QiEdge, p: DVec3) -> Option<f64> {
    if e.faces
        .iter()
        .any(|&f| f != NO_FACE && g.faces.contains(&f))
    {
        return None;
    }
    let s = g.n.dot(e.n.cross(p));
    (s.abs() > SIGN_TOL).then_some(s)
}

/// The change of `c` along the edge `e` passing its crossing `p` with the edge `g`, or `None`
/// when it is not decided: the ray meets `g`'s faces (two, or one for a boundary edge) next to
/// `g` on `g`'s mesh side, none on the other.
#[inline]
pub(crate) fn crossing_step(e: &QiEdge, g: &QiEdge, p: DVec3) -> Option<i32> {
    let s = crossing_side(e, g, p)?;
    Some(if s > 0.0 {
        face_count(g)
    } else {
        -face_count(g)
    })
}

/// `c` of the piece of `g` after the crossing `p` minus `c` of the piece of `e` after it: the
/// faces other than `e`'s and `g`'s are met alike next to `p`; after `p` along `e` the ray meets
/// `g`'s faces iff `g.n · (e.n × p) > 0`, and after `p` along `g` it meets `e`'s iff
/// `e.n · (g.n × p) > 0`, the opposite sign.
#[inline]
pub(crate) fn crossing_transfer(e: &QiEdge, g: &QiEdge, p: DVec3) -> Option<i32> {
    let s = crossing_side(e, g, p)?;
    Some(if s > 0.0 {
        -face_count(g)
    } else {
        face_count(e)
    })
}

/// A direction from `x` and its squared length.
#[derive(Clone, Copy)]
struct Toward {
    d: DVec3,
    len2: f64,
}

impl Toward {
    fn new(d: DVec3) -> Self {
        Toward {
            d,
            len2: d.length_squared(),
        }
    }
}

/// Whether a face covers the directions from `x` just off the mesh vertex `v` (direction
/// `vd = v − x`) toward `t` (`t − x`, any point but `v` on the arc's great circle), for each
/// of the two `t` asked (`None`: not asked, answered `false`): is `t`'s direction strictly
/// inside one of the face's `wedges` at `v` (the corners at `v` of its fan triangles)? `None`
/// within rounding of a wedge's side. With `v × p` and `q × v` formed once per wedge, the
/// three determinants of its test are dot products (`det(v, p, t) = (v × p) · t`,
/// `det(v, t, q) = (q × v) · t`); the sign tests compare squares, so no square root is taken.
fn covers(
    poly: &Polyhedron,
    x: DVec3,
    vd: Toward,
    wedges: &[Wedge],
    toward: [Option<Toward>; 2],
) -> Option<[bool; 2]> {
    // |det| ≤ SIGN_TOL |a| |b| |c|, squared.
    let tol2 = SIGN_TOL * SIGN_TOL;
    let near = |s: f64, l2: f64| s * s <= tol2 * l2;
    let mut hit = [false; 2];
    for w in wedges {
        let pd = poly.vertices[w.p as usize] - x;
        let qd = poly.vertices[w.q as usize] - x;
        let (lp2, lq2) = (pd.length_squared(), qd.length_squared());
        let vp = vd.d.cross(pd);
        let s = vp.dot(qd);
        if near(s, vd.len2 * lp2 * lq2) {
            return None;
        }
        let qv = qd.cross(vd.d);
        for (t, hit) in toward.iter().zip(&mut hit) {
            let Some(t) = t else {
                continue;
            };
            let sp = vp.dot(t.d);
            let sq = qv.dot(t.d);
            if near(sp, vd.len2 * lp2 * t.len2) || near(sq, vd.len2 * t.len2 * lq2) {
                return None;
            }
            if sp * s > 0.0 && sq * s > 0.0 {
                *hit = true;
            }
        }
    }
    Some(hit)
}

/// `c` next to the mesh vertex `v` along an edge toward `b` (own faces `fb`) minus `c` next to
/// `v` along an edge toward `a` (own faces `fa`): only the faces at `v` differ there (every
/// other face is met alike by all rays close to `v`'s direction, the configurations where it is
/// not being degenerate for the caller). Faces `absent` are left out, as the rays leave them.
pub(crate) fn vertex_step(
    poly: &Polyhedron,
    star: &VertexStars,
    x: DVec3,
    v: u32,
    (a, fa): (u32, [u32; 2]),
    (b, fb): (u32, [u32; 2]),
    absent: &impl Fn(u32) -> bool,
) -> Option<i32> {
    let vd = Toward::new(poly.vertices[v as usize] - x);
    let ad = Toward::new(poly.vertices[a as usize] - x);
    let bd = Toward::new(poly.vertices[b as usize] - x);
    let mut delta = 0;
    let mut rest = star.wedges(v);
    // Bound: each pass takes at least one wedge off `rest`.
    while let Some(first) = rest.first() {
        let f = first.face;
        let n = rest.iter().take_while(|w| w.face == f).count();
        let (wedges, tail) = rest.split_at(n);
        rest = tail;
        if absent(f) {
            continue; // never met by the rays (seen edge-on)
        }
        let asked = [
            (!fa.contains(&f)).then_some(ad),
            (!fb.contains(&f)).then_some(bd),
        ];
        if asked.iter().all(Option::is_none) {
            continue;
        }
        let [by_a, by_b] = covers(poly, x, vd, wedges, asked)?;
        delta += by_b as i32 - by_a as i32;
    }
    Some(delta)
}

/// The other end of an edge at its end `v`.
#[inline]
fn other_end(e: &QiEdge, v: u32) -> u32 {
    if e.v[0] == v { e.v[1] } else { e.v[0] }
}

/// Union-find root. Bound: links only ever join two roots (`components`), so the parents form a
/// forest and the walk ends within `parent.len()` steps.
fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        parent[i as usize] = parent[parent[i as usize] as usize];
        i = parent[i as usize];
    }
    i
}

impl QiScratch {
    /// [`QiScratch::solve`] with the exact counting ray of the exact silhouette (001 Sect.
    /// 4.3), then the pieces counted 0 (seen against the background) appended to `kept`, in
    /// piece order; returns the rays cast. The one step 4 of both silhouette computations.
    pub(crate) fn solve_kept(
        &mut self,
        poly: &IndexedPolyhedron,
        x: DVec3,
        crossings: &[DVec3],
        edge_on: Option<f64>,
        kept: &mut Vec<u32>,
    ) -> u32 {
        let absent =
            |f: u32| edge_on.is_some_and(|t| poly.face_planes[f as usize].eval(x).abs() <= t);
        self.solve(
            poly,
            poly.index.vertex_stars.as_deref(),
            x,
            crossings,
            absent,
            |dir, faces| {
                crate::geometry::silhouettes::exact_silhouette::count_ray_hits_edge_on(
                    poly, x, dir, faces, edge_on,
                )
            },
        );
        let count = &self.count;
        kept.extend((0..self.pieces.len() as u32).filter(|&q| count[q as usize] == 0));
        self.stats.rays
    }

    /// The counts of [`QiScratch::pieces`] (crossing directions `crossings`, by id): one ray
    /// (`ray(direction, own faces)`, the count of faces met) for each piece the links from
    /// pieces already counted do not reach. Afterwards `count[q] == 0` iff piece `q` is kept.
    /// `star` is `None` for meshes without vertex adjacency: no vertex links then. The faces
    /// `absent` (those `ray` leaves out, seen edge-on from a point on the mesh) are left out
    /// of the vertex rule too; an edge's own faces name [`NO_FACE`] in their place.
    pub(crate) fn solve(
        &mut self,
        poly: &IndexedPolyhedron,
        star: Option<&VertexStars>,
        x: DVec3,
        crossings: &[DVec3],
        absent: impl Fn(u32) -> bool,
        mut ray: impl FnMut(DVec3, [u32; 2]) -> u32,
    ) {
        let n = self.pieces.len();
        self.stats = QiStats::default();
        self.count.clear();
        self.count.resize(n, UNKNOWN);
        self.from_ray.clear();
        self.from_ray.resize(n, false);
        self.via_vertex.clear();
        self.via_vertex.resize(n, (u32::MAX, u32::MAX));
        self.tiny.clear();
        self.tiny.extend(
            self.pieces
                .iter()
                // Arcs may be longer than π/2 (seen from near a vertex): short means a small
                // sine and a positive cosine.
                .map(|p| p.from.cross(p.to).length() <= TINY && p.from.dot(p.to) > 0.0),
        );
        self.after.clear();
        self.after.resize(crossings.len(), [u32::MAX; 2]);
        for (q, p) in self.pieces.iter().enumerate() {
            if let QiEnd::Crossing(id) = p.start {
                let slot = &mut self.after[id as usize];
                if slot[0] == u32::MAX {
                    slot[0] = q as u32;
                } else {
                    slot[1] = q as u32;
                }
            }
        }
        self.link_vertex_ends(star.is_some().then_some(poly.vertices.len()));

        let mut conflict = false;
        for q0 in 0..n {
            if self.count[q0] != UNKNOWN {
                continue;
            }
            let p = self.pieces[q0];
            let mid = (p.from + p.to).normalize();
            self.count[q0] = ray(mid, self.edges[p.edge as usize].faces) as i32;
            self.from_ray[q0] = true;
            self.stats.rays += 1;
            self.stack.clear();
            self.stack.push(q0 as u32);
            // Bound: a piece is pushed when its count goes from unknown to known: once per piece.
            while let Some(q) = self.stack.pop() {
                let q = q as usize;
                if self.tiny[q] {
                    continue;
                }
                let c = self.count[q];
                let p = self.pieces[q];
                let e = self.edges[p.edge as usize];
                // Assigns `c + delta` to piece r (or checks it against its count).
                let mut link = |r: usize, delta: Option<i32>, this: &mut Self| {
                    if this.tiny[r] {
                        this.stats.undecided_links += 1;
                        return;
                    }
                    let Some(d) = delta else {
                        this.stats.undecided_links += 1;
                        return;
                    };
                    let value = c + d;
                    if this.count[r] == UNKNOWN {
                        if value < 0 {
                            conflict = true;
                            return;
                        }
                        this.count[r] = value;
                        this.stack.push(r as u32);
                    } else if this.count[r] != value {
                        conflict = true;
                    }
                };
                // Along the edge, across the crossings at the piece's ends.
                if let QiEnd::Crossing(id) = p.end {
                    let g = self.crossing_partner(id, p.edge);
                    let d =
                        g.and_then(|g| crossing_step(&e, &self.edges[g], crossings[id as usize]));
                    link(q + 1, d, self);
                }
                if let QiEnd::Crossing(id) = p.start {
                    let g = self.crossing_partner(id, p.edge);
                    let d =
                        g.and_then(|g| crossing_step(&e, &self.edges[g], crossings[id as usize]));
                    link(q - 1, d.map(|d| -d), self);
                    // To the other edge's piece after the crossing, when both pieces before it
                    // are long enough too (nothing else near the crossing).
                    let [a, b] = self.after[id as usize];
                    let r = if a as usize == q { b } else { a } as usize;
                    if !self.tiny[q - 1] && !self.tiny[r - 1] {
                        let g = self.pieces[r].edge as usize;
                        let d = crossing_transfer(&e, &self.edges[g], crossings[id as usize]);
                        link(r, d, self);
                    } else {
                        self.stats.undecided_links += 1;
                    }
                }
                // Around the mesh vertices at its ends.
                if let Some(star) = star {
                    for (i, end) in [p.start, p.end].into_iter().enumerate() {
                        let QiEnd::Vertex(v) = end else { continue };
                        let mut k = self.vertex_group[2 * q + i];
                        // Bound: a list holds each piece end at `v` once.
                        while k != u32::MAX {
                            let r = self.at_vertex[k as usize].1 as usize;
                            k = self.next_at_vertex[k as usize];
                            // The step q took its count by, back: `vertex_step` with its two
                            // edges swapped is the negated step (each face's test is the same
                            // pair of tests, and a tie in either is a tie in both), so the
                            // check below could only agree.
                            if r == q || self.via_vertex[q] == (r as u32, v) {
                                continue;
                            }
                            let g = self.edges[self.pieces[r].edge as usize];
                            let d = vertex_step(
                                poly,
                                star,
                                x,
                                v,
                                (other_end(&e, v), e.faces),
                                (other_end(&g, v), g.faces),
                                &absent,
                            );
                            let unknown = self.count[r] == UNKNOWN;
                            link(r, d, self);
                            if unknown && self.count[r] != UNKNOWN {
                                self.via_vertex[r] = (q as u32, v);
                            }
                        }
                    }
                }
            }
            if conflict {
                break;
            }
        }
        if conflict {
            // Back to one ray per piece.
            self.stats.whole_fallback = true;
            self.stats.rays = 0;
            for q in 0..n {
                let p = self.pieces[q];
                let mid = (p.from + p.to).normalize();
                self.count[q] = ray(mid, self.edges[p.edge as usize].faces) as i32;
                self.from_ray[q] = true;
                self.stats.rays += 1;
            }
        }
        if self.measure {
            self.stats.components = self.components();
        }
    }

    /// Lists, per mesh vertex, the piece ends at it in increasing piece order (the order a
    /// sort of (vertex, piece) pairs gives, without the sort), for a mesh of `vertices`
    /// vertices; none without vertex adjacency (`None`).
    fn link_vertex_ends(&mut self, vertices: Option<usize>) {
        let n = self.pieces.len();
        self.at_vertex.clear();
        self.next_at_vertex.clear();
        self.vertex_group.clear();
        self.vertex_group.resize(2 * n, u32::MAX);
        let Some(vertices) = vertices else {
            return;
        };
        if self.vertex_head.len() < vertices {
            self.vertex_head.resize(vertices, u32::MAX);
        }
        // From the last piece to the first, each end put at the head of its vertex's list.
        for q in (0..n).rev() {
            let p = self.pieces[q];
            for end in [p.start, p.end] {
                if let QiEnd::Vertex(v) = end {
                    let k = self.at_vertex.len() as u32;
                    self.at_vertex.push((v, q as u32));
                    self.next_at_vertex.push(self.vertex_head[v as usize]);
                    self.vertex_head[v as usize] = k;
                }
            }
        }
        for q in 0..n {
            let p = self.pieces[q];
            for (i, end) in [p.start, p.end].into_iter().enumerate() {
                if let QiEnd::Vertex(v) = end {
                    self.vertex_group[2 * q + i] = self.vertex_head[v as usize];
                }
            }
        }
        for &(v, _) in &self.at_vertex {
            self.vertex_head[v as usize] = u32::MAX;
        }
    }

    /// The other edge of crossing `id` (the edge of the other piece starting there).
    #[inline]
    fn crossing_partner(&self, id: u32, edge: u32) -> Option<usize> {
        let [a, b] = self.after[id as usize];
        if a == u32::MAX || b == u32::MAX {
            return None;
        }
        let (ea, eb) = (self.pieces[a as usize].edge, self.pieces[b as usize].edge);
        Some(if ea == edge { eb } else { ea } as usize)
    }

    /// Connected sets of pieces through every link, decided or not.
    fn components(&mut self) -> u32 {
        let n = self.pieces.len();
        self.parent.clear();
        self.parent.extend(0..n as u32);
        let union = |parent: &mut Vec<u32>, a: u32, b: u32| {
            let (ra, rb) = (find(parent, a), find(parent, b));
            if ra != rb {
                parent[ra as usize] = rb;
            }
        };
        for q in 0..n {
            if let QiEnd::Crossing(id) = self.pieces[q].start {
                union(&mut self.parent, q as u32, q as u32 - 1);
                let [a, b] = self.after[id as usize];
                union(&mut self.parent, a, b);
            }
        }
        for k in 0..self.at_vertex.len() {
            let next = self.next_at_vertex[k];
            if next != u32::MAX {
                union(
                    &mut self.parent,
                    self.at_vertex[k].1,
                    self.at_vertex[next as usize].1,
                );
            }
        }
        (0..n as u32)
            .filter(|&q| find(&mut self.parent, q) == q)
            .count() as u32
    }
}
