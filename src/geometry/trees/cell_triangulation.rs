//! Triangulated silhouettes of closed non-convex meshes, precomputed per BSP cell (001 Sect.
//! 6.2) and *proved* valid over the whole cell.
//!
//! The thesis tests a cell's triangulation at 256 random points and admits this is no
//! guarantee (001 Sect. 6.2.3, Fig. 6.6). Here the guarantee rests on one observation:
//!
//! > Let P be a region of the sphere bounded by the loops ∂P, and T₁…Tₙ spherical triangles
//! > whose boundaries add up to ∂P as chains (the diagonals of a triangulation cancel). Then
//! > Σᵢ 1_{Tᵢ} = 1_P + k for an integer k, since both sides are 2-chains with the same boundary
//! > and a 2-cycle of the sphere is a multiple of the sphere. If every Tᵢ is positively oriented
//! > (and smaller than a hemisphere), the left side counts every direction once per triangle
//! > that holds it; if moreover Σ Ω(Tᵢ) < 4π, then k = 0 and the triangles cover P exactly once.
//!
//! A triangulation found at one point of a cell keeps the same symbolic triangles everywhere in
//! the cell, so the chain identity holds everywhere; k cannot jump while no triangle
//! degenerates. What remains to prove is that **no triangle changes orientation in the cell**:
//!
//! * a triangle of three mesh vertices A, B, C has orientation det(A−x, B−x, C−x), an *affine*
//!   function of the point x: positive at the cell's corners means positive in the cell;
//! * a corner that is an apparent intersection of edges a₁a₂ and b₁b₂ (Eq. 4.4) has the
//!   direction sign(γ)(α(x)(a₂−x) − β(x)(a₁−x)), with the affine α(x) = det(a₁−x, b₁−x, b₂−x),
//!   β(x) = det(a₂−x, b₁−x, b₂−x) and γ = α − β (the point of edge a on the plane through x
//!   and edge b). Expanded by multilinearity, the orientation is a sum of products of affine
//!   dets ([`triangle_keeps_orientation`]): a single product is decided exactly by the signs
//!   of its factors at the cell's corners; otherwise the polynomial is bounded about the centre
//!   of the cell's bounding box term by term, the cell bisected until the bound is positive
//!   ([`TriangulationLimits::max_proof_depth`]).
//!
//! Where no triangulation of the cell's silhouette can be proved, the cell is split (across
//! the plane where a triangle flips, when the factors name one) and each half triangulated
//! again; what is still unproved at the depth limit is marked, and the sampler takes the faces
//! there (always correct, only slower). The proof assumes the leaf's silhouette itself is
//! right; that is validated at the corners of its cell by the tree build
//! ([`crate::geometry::trees::bsp_nonconvex`]).
//!
//! The triangulation of a silhouette at a point (001 Sect. 6.2.1–6.2.2) bridges holes into
//! their outer loop and takes, by dynamic programming, the triangulation whose smallest
//! orientation over the cell's samples is largest (so that the proof is likely to succeed);
//! when a loop has none (silhouettes larger than a hemisphere, 001 Fig. 6.3) it clips ears
//! with *optional vertices*: the ends of the mesh's concave edges, as the thesis does.

use crate::geometry::silhouettes::exact_silhouette::SilhouettePoint;
use crate::geometry::trees::bsp::BspNode;
use crate::geometry::trees::bsp_nonconvex::{ExactSilhouetteBsp, ON_THE_FLY};
use crate::geometry::trees::convex_cell::{CellSide, ConvexCell};
use crate::geometry::{Plane, Polyhedron, orient};
use glam::DVec3;

/// Precomputed triangulations of a non-convex mesh's silhouettes, one per leaf cell: the
/// cells of an [`ExactSilhouetteBsp`], some split further where one triangulation could not be
/// proved for the whole cell.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SilhouetteTriangulation {
    pub planes: Vec<Plane>,
    pub nodes: Vec<BspNode>,
    /// Leaf data: a leaf holds `tris[first..first + count]`, each triangle as three points in
    /// the 32-bit encoding of 001 Sect. 5.4 ([`SilhouettePoint::pack`]), positively oriented.
    /// `count == ON_THE_FLY`: no proved triangulation (sample the faces).
    pub tris: Vec<[u32; 3]>,
    pub lo: DVec3,
    pub hi: DVec3,
}

/// Limits of a build.
#[derive(Clone, Copy, Debug)]
pub struct TriangulationLimits {
    /// How often a cell is split to find triangulations that can be proved.
    pub max_split_depth: u32,
    /// How often a cell is bisected to prove that a triangle keeps its orientation.
    pub max_proof_depth: u32,
}

impl Default for TriangulationLimits {
    fn default() -> Self {
        TriangulationLimits {
            max_split_depth: 6,
            max_proof_depth: 8,
        }
    }
}

/// What a build produced (001 Table 7.4, "Triangulated silhouettes").
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TriangulationStats {
    pub seconds: f64,
    pub nodes: usize,
    pub leaves: usize,
    pub triangles: usize,
    /// Leaves of the silhouette tree that had to be split to prove their triangulations.
    pub split_cells: usize,
    /// Leaves with a silhouette but no proved triangulation, and their share of the volume of
    /// all leaves with a silhouette.
    pub unproved_leaves: usize,
    pub unproved_volume_fraction: f64,
    /// Triangles with an optional vertex (a vertex that is not a silhouette point).
    pub triangles_with_optional_vertices: usize,
    /// Size at 20 bytes per node and 12 per triangle (three 32-bit points), as in Table 7.4.
    pub table_7_4_bytes: usize,
}

/// Sample points of a cell used to choose ears: its centroid and up to this many corners.
const SCORE_CORNERS: usize = 16;

/// A silhouette point with its direction at the triangulation point and at the score samples.
#[derive(Clone, Copy, Debug)]
struct Node {
    p: SilhouettePoint,
    d: DVec3,
    at: [DVec3; SCORE_CORNERS + 1],
}

/// Normalised orientation below which a triangle or ear counts as degenerate.
const FLAT: f64 = 1e-12;

/// The ends of the concave edges of `poly` (the optional vertices of 001 Sect. 6.2.2): an edge
/// is concave where a vertex of one face lies in front of the other face's plane.
pub fn concave_edge_endpoints(poly: &Polyhedron) -> Vec<u32> {
    let tol = 1e-9 * poly.radius.max(f64::MIN_POSITIVE);
    let mut out: Vec<u32> = Vec::new();
    for e in &poly.edges {
        if e.is_boundary() {
            continue;
        }
        let plane = poly.face_planes[e.faces[0] as usize];
        let concave = poly
            .face(e.faces[1] as usize)
            .iter()
            .any(|&v| plane.eval(poly.vertices[v as usize]) > tol);
        if concave {
            out.extend(e.v);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Triangulates the silhouette `loops` (positively oriented loops of silhouette points, holes
/// included) seen from `x`, into `out` (cleared first), choosing ears that keep their
/// orientation best at `samples` (at most `SCORE_CORNERS` + 1 points); `optional` vertices
/// are brought in only where no ear exists. Every triangle is positively oriented at `x`.
/// `false` if no triangulation was found.
pub fn triangulate_silhouette(
    poly: &Polyhedron,
    loops: &[Vec<SilhouettePoint>],
    optional: &[u32],
    x: DVec3,
    samples: &[DVec3],
    out: &mut Vec<[SilhouettePoint; 3]>,
) -> bool {
    out.clear();
    let samples = &samples[..samples.len().min(SCORE_CORNERS + 1)];
    let node = |p: SilhouettePoint| -> Option<Node> {
        let mut at = [DVec3::ZERO; SCORE_CORNERS + 1];
        for (a, &s) in at.iter_mut().zip(samples) {
            *a = p.direction(poly, s)?;
        }
        Some(Node {
            p,
            d: p.direction(poly, x)?,
            at,
        })
    };
    let mut polys: Vec<Vec<Node>> = Vec::with_capacity(loops.len());
    for lp in loops {
        let Some(nodes) = lp.iter().map(|&p| node(p)).collect::<Option<Vec<_>>>() else {
            return false;
        };
        if nodes.len() >= 3 {
            polys.push(nodes);
        }
    }
    merge_holes(&mut polys);
    let mut extra: Vec<Node> = Vec::new();
    for &v in optional {
        let p = SilhouettePoint::Vertex(v);
        if polys.iter().flatten().any(|n| n.p == p) {
            continue;
        }
        match node(p) {
            Some(n) => extra.push(n),
            None => return false,
        }
    }
    let ns = samples.len();
    polys.into_iter().all(|poly_loop| {
        best_triangulation(&poly_loop, ns, out) || clip_ears(poly_loop, &extra, ns, out)
    })
}

/// The triangulation of a (weakly) simple loop, using its vertices only, that maximises the
/// smallest orientation of its triangles over the samples (dynamic programming over the
/// sub-polygons cut off by diagonals, O(n³)): the one most likely to stay valid over the
/// whole cell. `false` if the loop has none (it needs optional vertices).
fn best_triangulation(lp: &[Node], ns: usize, out: &mut Vec<[SilhouettePoint; 3]>) -> bool {
    let n = lp.len();
    if n < 3 {
        return true;
    }
    // Which pairs may be joined: the loop's edges, and diagonals through the interior.
    let mut joinable = vec![false; n * n];
    for i in 0..n {
        for j in i + 1..n {
            let ok = if j == i + 1 || (i == 0 && j == n - 1) {
                true
            } else {
                let (a, b) = (&lp[i], &lp[j]);
                a.p != b.p
                    && a.d.dot(b.d) > -1.0 + 1e-9
                    && in_wedge(lp[(i + n - 1) % n].d, a.d, lp[i + 1].d, b.d)
                    && in_wedge(lp[j - 1].d, b.d, lp[(j + 1) % n].d, a.d)
                    && (0..n).all(|k| {
                        let (s, t) = (&lp[k], &lp[(k + 1) % n]);
                        [s.p, t.p].iter().any(|&q| q == a.p || q == b.p)
                            || !arcs_cross(a.d, b.d, s.d, t.d)
                    })
            };
            joinable[i * n + j] = ok;
        }
    }
    // best[i][j]: the best smallest score of a triangulation of the sub-polygon i, i+1, …, j.
    let mut best = vec![f64::NEG_INFINITY; n * n];
    let mut split = vec![usize::MAX; n * n];
    for i in 0..n - 1 {
        best[i * n + i + 1] = f64::INFINITY;
    }
    for len in 2..n {
        for i in 0..n - len {
            let j = i + len;
            if !joinable[i * n + j] {
                continue;
            }
            for k in i + 1..j {
                if !joinable[i * n + k] || !joinable[k * n + j] {
                    continue;
                }
                let (a, b, c) = (&lp[i], &lp[k], &lp[j]);
                if orient(a.d, b.d, c.d) <= FLAT {
                    continue;
                }
                let score = (0..ns)
                    .map(|s| orient(a.at[s], b.at[s], c.at[s]))
                    .fold(f64::INFINITY, f64::min)
                    .min(best[i * n + k])
                    .min(best[k * n + j]);
                if score > best[i * n + j] {
                    best[i * n + j] = score;
                    split[i * n + j] = k;
                }
            }
        }
    }
    if split[n - 1] == usize::MAX {
        return false;
    }
    let mut stack = vec![(0, n - 1)];
    // Bound: every pop with j > i + 1 writes one triangle of the n-gon and splits (i, j) into
    // two shorter intervals: n − 2 triangles, 2n − 3 pops at most.
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let k = split[i * n + j];
        out.push([lp[i].p, lp[k].p, lp[j].p]);
        stack.push((i, k));
        stack.push((k, j));
    }
    true
}

/// Joins loops that bound one connected region (an outer loop and its holes) by bridges: arcs
/// between two of their vertices that run through the region's interior and cross no edge.
/// Loops of different components cannot be joined: any arc between them leaves the region.
fn merge_holes(polys: &mut Vec<Vec<Node>>) {
    // Bound: every round joins two loops into one or returns: `polys.len()` rounds at most.
    loop {
        let mut best: Option<(usize, usize, usize, usize, f64)> = None;
        for i in 0..polys.len() {
            for j in i + 1..polys.len() {
                for ia in 0..polys[i].len() {
                    for jb in 0..polys[j].len() {
                        let (a, b) = (&polys[i][ia], &polys[j][jb]);
                        let closeness = a.d.dot(b.d);
                        if best.is_some_and(|bst| bst.4 >= closeness) {
                            continue;
                        }
                        if bridge_is_valid(polys, (i, ia), (j, jb)) {
                            best = Some((i, ia, j, jb, closeness));
                        }
                    }
                }
            }
        }
        let Some((i, ia, j, jb, _)) = best else {
            return;
        };
        let hole = polys.remove(j);
        let outer = &mut polys[i];
        // … a, b, (the hole from b round to b), b, a, …
        let mut spliced: Vec<Node> = Vec::with_capacity(hole.len() + 2);
        spliced.extend(hole[jb..].iter().copied());
        spliced.extend(hole[..=jb].iter().copied());
        spliced.push(outer[ia]);
        outer.splice(ia + 1..ia + 1, spliced);
    }
}

/// Is the arc from vertex `a` of one loop to vertex `b` of another inside the region at both
/// ends and free of crossings with every edge?
fn bridge_is_valid(polys: &[Vec<Node>], a: (usize, usize), b: (usize, usize)) -> bool {
    let at = |(l, k): (usize, usize)| {
        let lp = &polys[l];
        (
            lp[(k + lp.len() - 1) % lp.len()].d,
            lp[k],
            lp[(k + 1) % lp.len()].d,
        )
    };
    let (pa, na, qa) = at(a);
    let (pb, nb, qb) = at(b);
    if na.p == nb.p || na.d.dot(nb.d) < -1.0 + 1e-9 {
        return false;
    }
    if !in_wedge(pa, na.d, qa, nb.d) || !in_wedge(pb, nb.d, qb, na.d) {
        return false;
    }
    !polys.iter().any(|lp| {
        (0..lp.len()).any(|k| {
            let (s, t) = (&lp[k], &lp[(k + 1) % lp.len()]);
            let touches = [s.p, t.p].iter().any(|&q| q == na.p || q == nb.p);
            !touches && arcs_cross(na.d, nb.d, s.d, t.d)
        })
    })
}

/// Does the arc from `c` toward `q` start into the interior at vertex `c` of a positively
/// oriented loop … p → c → n …? The interior lies to the left of both edges at a convex
/// vertex, to the left of either at a reflex one.
fn in_wedge(p: DVec3, c: DVec3, n: DVec3, q: DVec3) -> bool {
    let (l1, l2) = (orient(p, c, q) > FLAT, orient(c, n, q) > FLAT);
    if orient(p, c, n) > 0.0 {
        l1 && l2
    } else {
        l1 || l2
    }
}

/// Do the arcs p→q and r→s (each shorter than π) cross or touch? Touching counts (a bridge or
/// optional edge that touches an edge is refused).
fn arcs_cross(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
    let (o1, o2) = (orient(p, q, r), orient(p, q, s));
    let (o3, o4) = (orient(r, s, p), orient(r, s, q));
    if o1 * o2 > FLAT * FLAT || o3 * o4 > FLAT * FLAT {
        return false;
    }
    // The two great circles meet at ±d; the arcs cross where d lies on both.
    let Some(mut d) = p.cross(q).cross(r.cross(s)).try_normalize() else {
        return true; // one great circle: overlapping or not, refuse
    };
    if d.dot(p + q) < 0.0 {
        d = -d;
    }
    d.dot(r + s) > -FLAT
}

/// Ear clipping of one loop (bridged holes included) on the sphere; see
/// [`triangulate_silhouette`].
fn clip_ears(
    mut lp: Vec<Node>,
    extra: &[Node],
    ns: usize,
    out: &mut Vec<[SilhouettePoint; 3]>,
) -> bool {
    let mut used = vec![false; extra.len()];
    // Bound: every round clips an ear (one vertex fewer), brings in an unused optional vertex
    // (at most `extra.len()` times), or returns: `lp.len() + 3 extra.len()` rounds at most.
    while lp.len() >= 3 {
        let n = lp.len();
        if n == 3 {
            let (a, b, c) = (&lp[0], &lp[1], &lp[2]);
            if orient(a.d, b.d, c.d) > FLAT {
                out.push([a.p, b.p, c.p]);
                return true;
            }
            if a.p == b.p || b.p == c.p || c.p == a.p {
                return true; // a spike: zero area, its arcs cancel
            }
            // A triangle larger than a hemisphere: it needs an optional vertex.
        }
        let mut best: Option<(usize, f64)> = None;
        for i in 0..n {
            if n == 3 {
                break;
            }
            let (p, c, q) = (&lp[(i + n - 1) % n], &lp[i], &lp[(i + 1) % n]);
            if orient(p.d, c.d, q.d) <= FLAT {
                continue;
            }
            let score = (0..ns)
                .map(|s| orient(p.at[s], c.at[s], q.at[s]))
                .fold(f64::INFINITY, f64::min);
            if best.is_some_and(|b| b.1 >= score) {
                continue;
            }
            let blocked = lp.iter().any(|v| {
                v.p != p.p && v.p != c.p && v.p != q.p && in_closed_triangle(p.d, c.d, q.d, v.d)
            });
            if !blocked {
                best = Some((i, score));
            }
        }
        if let Some((i, _)) = best {
            out.push([lp[(i + n - 1) % n].p, lp[i].p, lp[(i + 1) % n].p]);
            lp.remove(i);
            continue;
        }
        // No ear: bring in an optional vertex reachable from a vertex of the loop, as a spike
        // … a, v, a … (zero area; its two arcs cancel as chains).
        let mut inserted = false;
        'search: for (k, e) in extra.iter().enumerate() {
            if used[k] {
                continue;
            }
            for i in 0..n {
                let (p, c, q) = (lp[(i + n - 1) % n].d, lp[i], lp[(i + 1) % n].d);
                if c.d.dot(e.d) < -1.0 + 1e-9 || !in_wedge(p, c.d, q, e.d) {
                    continue;
                }
                let free = (0..n).all(|j| {
                    let (s, t) = (&lp[j], &lp[(j + 1) % n]);
                    s.p == c.p || t.p == c.p || !arcs_cross(c.d, e.d, s.d, t.d)
                });
                if free {
                    used[k] = true;
                    lp.splice(i + 1..i + 1, [*e, c]);
                    inserted = true;
                    break 'search;
                }
            }
        }
        if !inserted {
            return false;
        }
    }
    true
}

/// Is `v` inside or on the boundary of the positively oriented triangle (a, b, c)?
#[inline]
fn in_closed_triangle(a: DVec3, b: DVec3, c: DVec3, v: DVec3) -> bool {
    orient(a, b, v) >= -FLAT && orient(b, c, v) >= -FLAT && orient(c, a, v) >= -FLAT
}

// ---------------------------------------------------------------------------------------------
// The proof that a triangle keeps its orientation over a cell.
//
// Each corner's direction is written as a sum of terms c(x)·(v − x), v a mesh vertex and c a
// product of affine factors det(p − x, q − x, r − x) of mesh vertices: a vertex is 1·(v − x); a
// crossing of edges a and b is sign(γ)·(α·(a₂ − x) − β·(a₁ − x)), γ = α − β the affine
// denominator, of one sign wherever the crossing exists. Expanding det(d₀, d₁, d₂) by
// multilinearity, terms with a repeated vertex vanish and the others group by their vertex
// triple: orientation = Σ_groups (Σ ±Π factors) · det(p − x, q − x, r − x). The cancellation
// matters: where a crossing slides into the end of its edge (a three-endpoint plane, a face of
// the cell) a triangle holding both degenerates; written this way its orientation is α times
// an affine function, whose signs the cell's corners decide exactly, instead of a polynomial
// an interval bound cannot separate from zero near that face.

/// det(p − x, q − x, r − x) for three mesh vertices: affine in x.
type Affine = [u32; 3];

/// ±Π factors (at most two: one per crossing corner outside the vertex triple).
#[derive(Clone, Copy, Debug)]
struct Coefficient {
    sign: f64,
    factors: [Option<Affine>; 3],
}

/// The terms sharing one vertex triple.
#[derive(Clone, Debug)]
struct Group {
    base: [u32; 3],
    coefficients: Vec<Coefficient>,
}

/// Highest total degree of [`Polynomial`]: a term has up to three affine factors (one per
/// crossing corner) times the affine det of its vertex triple.
const MAX_DEGREE: usize = 4;

/// A polynomial in δ = x − m (three variables) of total degree ≤ [`MAX_DEGREE`], dense by
/// exponents: `c[i][j][k]` multiplies δₓⁱ δᵧʲ δ_zᵏ.
#[derive(Clone, Copy, Debug)]
struct Polynomial {
    c: [[[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1]; MAX_DEGREE + 1],
}

impl Polynomial {
    fn constant(v: f64) -> Polynomial {
        let mut c = [[[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1]; MAX_DEGREE + 1];
        c[0][0][0] = v;
        Polynomial { c }
    }

    /// The monomials (exponents, coefficient) with a non-zero coefficient.
    fn terms(&self) -> impl Iterator<Item = ([usize; 3], f64)> + '_ {
        (0..=MAX_DEGREE).flat_map(move |i| {
            (0..=MAX_DEGREE - i).flat_map(move |j| {
                (0..=MAX_DEGREE - i - j)
                    .map(move |k| ([i, j, k], self.c[i][j][k]))
                    .filter(|&(_, v)| v != 0.0)
            })
        })
    }

    /// self × (v + g·δ), exactly; `None` if the degree would exceed [`MAX_DEGREE`] (never for
    /// the orientations built here, whose terms have at most four affine factors).
    fn times_affine(&self, v: f64, g: DVec3) -> Option<Polynomial> {
        let mut out = Polynomial::constant(0.0);
        let g = g.to_array();
        for ([i, j, k], coef) in self.terms() {
            out.c[i][j][k] += coef * v;
            if g.iter().any(|&gk| gk != 0.0) {
                if i + j + k == MAX_DEGREE {
                    return None;
                }
                out.c[i + 1][j][k] += coef * g[0];
                out.c[i][j + 1][k] += coef * g[1];
                out.c[i][j][k + 1] += coef * g[2];
            }
        }
        Some(out)
    }

    fn add(&mut self, o: &Polynomial) {
        for ([i, j, k], v) in o.terms() {
            self.c[i][j][k] += v;
        }
    }

    /// Lower and upper bounds over |δₖ| ≤ hₖ (each non-constant monomial bounded by its
    /// magnitude), and the sum of the terms' magnitudes.
    fn bounds(&self, h: DVec3) -> (f64, f64, f64) {
        let h = h.to_array();
        let mut slack = 0.0;
        for ([i, j, k], coef) in self.terms() {
            if i + j + k > 0 {
                slack +=
                    coef.abs() * h[0].powi(i as i32) * h[1].powi(j as i32) * h[2].powi(k as i32);
            }
        }
        let c0 = self.c[0][0][0];
        (c0 - slack, c0 + slack, c0.abs() + slack)
    }

    #[cfg(test)]
    fn eval(&self, d: DVec3) -> f64 {
        self.terms()
            .map(|([i, j, k], c)| c * d.x.powi(i as i32) * d.y.powi(j as i32) * d.z.powi(k as i32))
            .sum()
    }
}

/// det(p − x, q − x, r − x) around m: its value at m and its gradient in δ = x − m, from
/// det(p', q', r') − δ · (p'×q' + q'×r' + r'×p'), primes relative to m.
fn affine_about(poly: &Polyhedron, f: Affine, m: DVec3) -> (f64, DVec3) {
    let [p, q, r] = f.map(|i| poly.vertices[i as usize] - m);
    (p.dot(q.cross(r)), -(p.cross(q) + q.cross(r) + r.cross(p)))
}

#[inline]
fn affine_at(poly: &Polyhedron, f: Affine, x: DVec3) -> f64 {
    let [p, q, r] = f.map(|i| poly.vertices[i as usize] - x);
    p.dot(q.cross(r))
}

/// The sign an affine function keeps over a cell: `Some(±1)` if it is of one sign (zero
/// allowed) at every corner and nonzero at the centroid, so nonzero inside the cell.
fn affine_sign(
    g: impl Fn(DVec3) -> f64,
    corners: &[DVec3],
    centre: DVec3,
    tol: f64,
) -> Option<f64> {
    let c = g(centre);
    if c.abs() <= tol {
        return None;
    }
    let s = c.signum();
    corners.iter().all(|&x| g(x) * s >= -tol).then_some(s)
}

/// What [`triangle_keeps_orientation`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Orientation {
    /// Positive at every interior point of the cell (it may degenerate on the boundary).
    Kept,
    /// Not proved; with the plane of an affine factor that changes sign inside the cell (the
    /// triangle flips across it), when the orientation factors into affine functions.
    NotProved(Option<Plane>),
}

/// Does the triangle `tri` (positively oriented as seen from the cell's centroid) stay
/// positively oriented at every interior point of `cell`?
pub(crate) fn triangle_keeps_orientation(
    poly: &Polyhedron,
    tri: &[SilhouettePoint; 3],
    cell: &ConvexCell,
    max_proof_depth: u32,
) -> Orientation {
    use Orientation::{Kept, NotProved};
    let mut corners: Vec<DVec3> = Vec::new();
    for p in cell.vertices() {
        if !corners.contains(&p) {
            corners.push(p);
        }
    }
    if corners.is_empty() {
        return NotProved(None);
    }
    let centre = cell.centroid();
    let r = poly.radius + (centre - poly.center).length() + cell_extent(&corners);
    // Relative tolerance for affine dets (cubic in lengths).
    let tol = 1e-12 * r * r * r;
    let orient_at = |x: DVec3| -> Option<f64> {
        let d = tri.map(|p| p.direction(poly, x));
        Some(orient(d[0]?, d[1]?, d[2]?))
    };
    if orient_at(centre).is_none_or(|o| o <= FLAT) {
        return NotProved(None);
    }
    let Some(groups) = expand_orientation(poly, tri, &corners, centre, tol) else {
        return NotProved(None);
    };
    let plane_of = |f: Affine| {
        let [p, q, r] = f.map(|i| poly.vertices[i as usize]);
        (q - p)
            .cross(r - p)
            .try_normalize()
            .map(|n| Plane { n, d: n.dot(p) })
    };
    // One group with one coefficient: a product of affine functions, each of known sign, or
    // one of them changes sign in the cell and its plane is where the triangle flips.
    if let [g] = groups.as_slice() {
        let Some(sb) = affine_sign(|x| affine_at(poly, g.base, x), &corners, centre, tol) else {
            return NotProved(plane_of(g.base));
        };
        if let [c] = g.coefficients.as_slice() {
            let mut sign = c.sign * sb;
            for f in c.factors.iter().flatten() {
                match affine_sign(|x| affine_at(poly, *f, x), &corners, centre, tol) {
                    Some(s) => sign *= s,
                    None => return NotProved(plane_of(*f)),
                }
            }
            return if sign > 0.0 { Kept } else { NotProved(None) };
        }
        // The coefficient is a polynomial that should not vanish in the cell: bound it.
        if corners
            .iter()
            .any(|&x| orient_at(x).is_some_and(|o| o < -1e-9))
        {
            return NotProved(None);
        }
        let coefficient_only = Group {
            base: g.base,
            coefficients: g.coefficients.clone(),
        };
        return if prove_sign(poly, &[coefficient_only], true, sb, cell, max_proof_depth) {
            Kept
        } else {
            NotProved(None)
        };
    }
    // A flip at a real point is final (and cheap to see).
    if corners
        .iter()
        .any(|&x| orient_at(x).is_some_and(|o| o < -1e-9))
    {
        return NotProved(None);
    }
    if prove_sign(poly, &groups, false, 1.0, cell, max_proof_depth) {
        Kept
    } else {
        NotProved(None)
    }
}

/// The orientation of `tri` as Σ_groups (Σ ±Π affine factors)·det(base); `None` if a
/// crossing's denominator γ is not of one sign over the cell.
fn expand_orientation(
    poly: &Polyhedron,
    tri: &[SilhouettePoint; 3],
    corners: &[DVec3],
    centre: DVec3,
    tol: f64,
) -> Option<Vec<Group>> {
    let tri_vertices: Vec<u32> = tri
        .iter()
        .filter_map(|p| match p {
            SilhouettePoint::Vertex(v) => Some(*v),
            _ => None,
        })
        .collect();
    // The terms of each corner: (sign, factor, vertex).
    let mut expansions: [Vec<(f64, Option<Affine>, u32)>; 3] = Default::default();
    for (k, p) in tri.iter().enumerate() {
        expansions[k] = match *p {
            SilhouettePoint::Vertex(v) => vec![(1.0, None, v)],
            SilhouettePoint::Crossing(a, b) => {
                // Written on the edge that shares a vertex with the triangle, if one does:
                // that is what makes the terms cancel.
                let on_b = !a.iter().any(|v| tri_vertices.contains(v))
                    && b.iter().any(|v| tri_vertices.contains(v));
                let ([a1, a2], [b1, b2]) = if on_b { (b, a) } else { (a, b) };
                let alpha: Affine = [a1, b1, b2];
                let beta: Affine = [a2, b1, b2];
                let gamma = |x: DVec3| affine_at(poly, alpha, x) - affine_at(poly, beta, x);
                // γ may not vanish in the closed cell: the crossing would run off to infinity.
                let c = gamma(centre);
                if c == 0.0 || corners.iter().any(|&x| gamma(x) * c.signum() <= tol) {
                    return None;
                }
                let s = c.signum();
                vec![(s, Some(alpha), a2), (-s, Some(beta), a1)]
            }
        };
    }
    // Expand det(d₀, d₁, d₂) and group by vertex triple.
    let mut groups: Vec<Group> = Vec::new();
    for t0 in &expansions[0] {
        for t1 in &expansions[1] {
            for t2 in &expansions[2] {
                let mut base = [t0.2, t1.2, t2.2];
                if base[0] == base[1] || base[1] == base[2] || base[0] == base[2] {
                    continue;
                }
                let sign = t0.0 * t1.0 * t2.0 * sort3(&mut base);
                let coefficient = Coefficient {
                    sign,
                    factors: [t0.1, t1.1, t2.1],
                };
                match groups.iter_mut().find(|g| g.base == base) {
                    Some(g) => g.coefficients.push(coefficient),
                    None => groups.push(Group {
                        base,
                        coefficients: vec![coefficient],
                    }),
                }
            }
        }
    }
    Some(groups)
}

/// Sorts three distinct indices; returns the sign of the permutation.
fn sort3(b: &mut [u32; 3]) -> f64 {
    let mut sign = 1.0;
    for (i, j) in [(0, 1), (1, 2), (0, 1)] {
        if b[i] > b[j] {
            b.swap(i, j);
            sign = -sign;
        }
    }
    sign
}

fn cell_extent(corners: &[DVec3]) -> f64 {
    let (lo, hi) = corners
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    (hi - lo).length()
}

/// Proves `want_sign × Σ_groups (Σ ±Π factors)·det(base) > 0` over the cell: the expression
/// is a polynomial in x (degree ≤ 4), expanded exactly about the centre of the cell's bounding
/// box and bounded there term by term (the constant and linear parts exactly, so the
/// overestimate shrinks with the square of the box, where a plain interval evaluation loses the
/// cancellations between nearly parallel directions); the cell is bisected while the bound
/// straddles zero. With `coefficients_only`, the det(base) factor is left out (its sign is
/// known).
fn prove_sign(
    poly: &Polyhedron,
    groups: &[Group],
    coefficients_only: bool,
    want_sign: f64,
    cell: &ConvexCell,
    depth: u32,
) -> bool {
    let (lo, hi) = cell.bounds();
    if lo.x > hi.x {
        return true; // empty: nothing to prove
    }
    let (m, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
    let mut total = Polynomial::constant(0.0);
    for g in groups {
        for c in &g.coefficients {
            let mut term = Polynomial::constant(c.sign * want_sign);
            let base = (!coefficients_only).then_some(g.base);
            for f in c.factors.iter().flatten().chain(base.iter()) {
                let (v, grad) = affine_about(poly, *f, m);
                match term.times_affine(v, grad) {
                    Some(t) => term = t,
                    None => return false,
                }
            }
            total.add(&term);
        }
    }
    let (lower, upper, magnitude) = total.bounds(h);
    // A relative margin for the rounding of the expansion itself.
    if lower > 1e-12 * magnitude {
        return true;
    }
    if depth == 0 || upper < 0.0 {
        return false;
    }
    let plane = cell.longest_axis_plane(m);
    let split_tol = 1e-12 * (poly.radius + (hi - lo).length());
    let (back, front) = cell.split(&plane, split_tol);
    [back, front].iter().all(|half| {
        half.is_empty() || prove_sign(poly, groups, coefficients_only, want_sign, half, depth - 1)
    })
}

// ---------------------------------------------------------------------------------------------
// The tree.

struct Builder<'a> {
    poly: &'a Polyhedron,
    exact: &'a ExactSilhouetteBsp,
    optional: Vec<u32>,
    limits: TriangulationLimits,
    tol: f64,
    out: SilhouetteTriangulation,
    stats: TriangulationStats,
    silhouette_volume: f64,
    unproved_volume: f64,
    tris: Vec<[SilhouettePoint; 3]>,
}

impl SilhouetteTriangulation {
    /// Triangulates every leaf of `exact` (the tree of `poly`'s exact silhouettes).
    pub fn build(
        poly: &Polyhedron,
        exact: &ExactSilhouetteBsp,
        limits: TriangulationLimits,
    ) -> (Self, TriangulationStats) {
        let start = web_time::Instant::now();
        let mut b = Builder {
            poly,
            exact,
            optional: concave_edge_endpoints(poly),
            limits,
            tol: 1e-9 * poly.radius.max(f64::MIN_POSITIVE),
            out: SilhouetteTriangulation {
                planes: exact.planes.clone(),
                lo: exact.lo,
                hi: exact.hi,
                ..Default::default()
            },
            stats: TriangulationStats::default(),
            silhouette_volume: 0.0,
            unproved_volume: 0.0,
            tris: Vec::new(),
        };
        if !exact.nodes.is_empty() {
            b.copy(0, ConvexCell::cuboid(exact.lo, exact.hi));
        }
        let mut stats = b.stats;
        stats.seconds = start.elapsed().as_secs_f64();
        stats.nodes = b.out.nodes.len();
        stats.triangles = b.out.tris.len();
        stats.unproved_volume_fraction = if b.silhouette_volume > 0.0 {
            b.unproved_volume / b.silhouette_volume
        } else {
            0.0
        };
        stats.table_7_4_bytes = 20 * stats.nodes + 12 * stats.triangles;
        (b.out, stats)
    }

    /// The triangles (packed points) of the leaf of `x`; `None` outside the box or where no
    /// triangulation was proved.
    #[inline]
    pub(crate) fn triangles(&self, x: DVec3) -> Option<&[[u32; 3]]> {
        if x.cmplt(self.lo).any() || x.cmpgt(self.hi).any() || self.nodes.is_empty() {
            return None;
        }
        match self.nodes[super::bsp::bsp_leaf(&self.nodes, &self.planes, x)] {
            BspNode::Leaf { first, count } if count != ON_THE_FLY => {
                Some(&self.tris[first as usize..(first + count) as usize])
            }
            _ => None,
        }
    }

    /// Every leaf with its cell (for tests and the debugger): (node index, cell).
    pub fn leaf_cells(&self, tol: f64) -> Vec<(usize, ConvexCell)> {
        let mut out = Vec::new();
        if self.nodes.is_empty() {
            return out;
        }
        let mut stack = vec![(0usize, ConvexCell::cuboid(self.lo, self.hi))];
        // Bound: a well-formed tree (children after parents): each node is pushed once.
        while let Some((n, cell)) = stack.pop() {
            match self.nodes[n] {
                BspNode::Inner { plane, back, front } => {
                    let (b, f) = cell.split(&self.planes[plane as usize], tol);
                    stack.push((back as usize, b));
                    stack.push((front as usize, f));
                }
                BspNode::Leaf { .. } => out.push((n, cell)),
            }
        }
        out
    }

    /// Whether every index is in range for a mesh of `vertices` vertices (a tree read from a
    /// file is checked before use).
    pub fn is_well_formed(&self, vertices: usize) -> bool {
        let tris = self.tris.len();
        super::bsp::nodes_well_formed(&self.nodes, self.planes.len(), |first, count| {
            count == ON_THE_FLY
                || (first as usize)
                    .checked_add(count as usize)
                    .is_some_and(|e| e <= tris)
        }) && self
            .tris
            .iter()
            .flatten()
            .all(|&p| match SilhouettePoint::unpack(p) {
                SilhouettePoint::Vertex(v) => (v as usize) < vertices,
                SilhouettePoint::Crossing(a, b) => {
                    a.iter().chain(&b).all(|&v| (v as usize) < vertices)
                }
            })
    }
}

impl Builder<'_> {
    fn push_leaf(&mut self, first: u32, count: u32) -> u32 {
        self.stats.leaves += 1;
        self.out.nodes.push(BspNode::Leaf { first, count });
        (self.out.nodes.len() - 1) as u32
    }

    /// Copies node `n` of the silhouette tree (cell `cell`), triangulating its leaves.
    fn copy(&mut self, n: usize, cell: ConvexCell) -> u32 {
        match self.exact.nodes[n] {
            BspNode::Inner { plane, back, front } => {
                let me = self.out.nodes.len() as u32;
                self.out.nodes.push(BspNode::Leaf { first: 0, count: 0 });
                let (bc, fc) = cell.split(&self.exact.planes[plane as usize], self.tol);
                let b = self.copy(back as usize, bc);
                let f = self.copy(front as usize, fc);
                self.out.nodes[me as usize] = BspNode::Inner {
                    plane,
                    back: b,
                    front: f,
                };
                me
            }
            BspNode::Leaf { count, .. } if count == ON_THE_FLY => self.push_leaf(0, ON_THE_FLY),
            BspNode::Leaf { first, count } => {
                let loops: Vec<Vec<SilhouettePoint>> = self.exact.loops
                    [first as usize..(first + count) as usize]
                    .iter()
                    .map(|&[a, b]| {
                        self.exact.points[a as usize..b as usize]
                            .iter()
                            .map(|&p| SilhouettePoint::unpack(p))
                            .collect()
                    })
                    .collect();
                let volume = cell.volume();
                self.silhouette_volume += volume;
                let nodes_before = self.out.nodes.len();
                let me = self.leaf(cell, &loops, 0);
                if self.out.nodes.len() > nodes_before + 1 {
                    self.stats.split_cells += 1;
                }
                me
            }
        }
    }

    /// A proved triangulation of `loops` over `cell`, else the cell split in two: across the
    /// plane where a triangle flips when there is one, else across its longest side.
    fn leaf(&mut self, cell: ConvexCell, loops: &[Vec<SilhouettePoint>], depth: u32) -> u32 {
        if cell.is_empty() {
            return self.push_leaf(0, ON_THE_FLY);
        }
        let verdict = self.proved_triangulation(&cell, loops);
        if verdict == Orientation::Kept {
            let first = self.out.tris.len() as u32;
            for t in &self.tris {
                let packed = t.map(|p| p.pack().unwrap_or(0));
                self.out.tris.push(packed);
                if t.iter().any(|p| {
                    matches!(p, SilhouettePoint::Vertex(_))
                        && !loops.iter().flatten().any(|q| q == p)
                }) {
                    self.stats.triangles_with_optional_vertices += 1;
                }
            }
            return self.push_leaf(first, self.tris.len() as u32);
        }
        if depth >= self.limits.max_split_depth {
            self.stats.unproved_leaves += 1;
            self.unproved_volume += cell.volume();
            return self.push_leaf(0, ON_THE_FLY);
        }
        let flip = match verdict {
            Orientation::NotProved(Some(p)) if cell.side(&p, self.tol) == CellSide::Straddles => {
                Some(p)
            }
            _ => None,
        };
        let plane = flip.unwrap_or_else(|| cell.longest_axis_plane(cell.centroid()));
        let me = self.out.nodes.len() as u32;
        self.out.nodes.push(BspNode::Leaf { first: 0, count: 0 });
        self.out.planes.push(plane);
        let k = (self.out.planes.len() - 1) as u32;
        let (bc, fc) = cell.split(&plane, self.tol);
        let b = self.leaf(bc, loops, depth + 1);
        let f = self.leaf(fc, loops, depth + 1);
        self.out.nodes[me as usize] = BspNode::Inner {
            plane: k,
            back: b,
            front: f,
        };
        me
    }

    /// Triangulates at the cell's centroid into `self.tris` and tries to prove it for the
    /// whole cell.
    fn proved_triangulation(
        &mut self,
        cell: &ConvexCell,
        loops: &[Vec<SilhouettePoint>],
    ) -> Orientation {
        let c = cell.centroid();
        let mut corners: Vec<DVec3> = Vec::new();
        for p in cell.vertices() {
            if !corners.iter().any(|q| q.distance(p) <= self.tol) {
                corners.push(p);
            }
        }
        // The centroid and the corners farthest from it (pulled in slightly: a corner may lie
        // on a face plane of the mesh, where directions degenerate).
        corners.sort_by(|a, b| b.distance(c).total_cmp(&a.distance(c)));
        let samples: Vec<DVec3> = std::iter::once(c)
            .chain(
                corners
                    .iter()
                    .take(SCORE_CORNERS)
                    .map(|&p| c + (p - c) * 0.98),
            )
            .collect();
        let mut tris = std::mem::take(&mut self.tris);
        let mut verdict = Orientation::NotProved(None);
        if triangulate_silhouette(self.poly, loops, &self.optional, c, &samples, &mut tris)
            && solid_angle_sum(self.poly, &tris, c) < 4.0 * std::f64::consts::PI - 1e-6
        {
            verdict = Orientation::Kept;
            for t in &tris {
                let v = triangle_keeps_orientation(self.poly, t, cell, self.limits.max_proof_depth);
                if v != Orientation::Kept {
                    verdict = v;
                    break;
                }
            }
        }
        self.tris = tris;
        verdict
    }
}

/// Σ Ω(Tᵢ) at `x` (the k = 0 condition of the module documentation).
fn solid_angle_sum(poly: &Polyhedron, tris: &[[SilhouettePoint; 3]], x: DVec3) -> f64 {
    tris.iter()
        .map(|t| {
            let d = t.map(|p| p.direction(poly, x).unwrap_or(DVec3::ZERO));
            crate::geometry::spherical::spherical_polygon::solid_angle_of_triangle(d[0], d[1], d[2])
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    /// The exact expansion of a product of four affine functions against direct evaluation,
    /// and its bounds against the values at random points of the box.
    #[test]
    fn polynomial_products_are_exact_and_their_bounds_hold() {
        let mut rng = Pcg32::new(3, 7);
        let mut r = |s: f64| s * (2.0 * rng.next_f64() - 1.0);
        for _ in 0..200 {
            let factors: Vec<(f64, DVec3)> = (0..4)
                .map(|_| (r(2.0), DVec3::new(r(1.0), r(1.0), r(1.0))))
                .collect();
            let mut p = Polynomial::constant(1.5);
            for &(v, g) in &factors {
                p = p.times_affine(v, g).unwrap();
            }
            assert!(
                p.times_affine(1.0, DVec3::X).is_none(),
                "degree 5 is refused"
            );
            let h = DVec3::new(r(0.5).abs(), r(0.5).abs(), r(0.5).abs());
            let (lo, hi, _) = p.bounds(h);
            for _ in 0..50 {
                let d = DVec3::new(r(h.x), r(h.y), r(h.z));
                let direct: f64 = 1.5 * factors.iter().map(|&(v, g)| v + g.dot(d)).product::<f64>();
                let expanded = p.eval(d);
                assert!((direct - expanded).abs() <= 1e-12 * (1.0 + direct.abs()));
                assert!(lo - 1e-12 <= direct && direct <= hi + 1e-12);
            }
        }
    }
}
