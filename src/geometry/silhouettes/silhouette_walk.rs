//! The silhouette of a large convex mesh by walking, in time proportional to its length
//! instead of its edge count (docs/silhouettes.md, "Walking the contour of a large convex
//! mesh").
//!
//! [`silhouette`](crate::geometry::silhouettes::silhouette) scans every face and edge: for the hull of a 32 × 16 UV
//! sphere that is 960 plane tests and 1,440 edge tests at every shading point for a loop of
//! about 40 edges. Here a contour edge is found first by a walk over the faces, from the face
//! whose normal is nearest the direction of the point (a cube-map lookup): down the signed plane
//! distance from a front face, or up it from a back face, until a neighbour has the other
//! sign. The loop is then traced vertex by vertex: at each silhouette vertex the next contour
//! edge is the one outgoing contour edge among the vertex's edges.
//!
//! The loop is written out starting at its smallest edge index, which is where the scan starts
//! it, so the result is the scan's bit for bit. Whenever the walk meets what the scan handles
//! and it does not (a walk that stops at a local minimum, a vertex with no or two outgoing
//! contour edges, where the front faces touch at a vertex), it reports failure and the caller
//! scans.

use crate::geometry::SphericalPolygon;
use crate::geometry::mesh::polyhedron::{NO_FACE, Polyhedron};
use crate::math::Frame;
use glam::DVec3;

/// Convex meshes with at least this many edges get a [`ContourWalk`] (below it the scan costs
/// about what the walk does).
pub(crate) const WALK_MIN_EDGES: usize = 96;

/// Cells per side of each cube-map face of the start lookup.
const GRID: usize = 4;

/// Adjacency for the walk, built once per mesh.
#[derive(Clone, Debug, Default)]
pub struct ContourWalk {
    /// Edges of each face: `face_edges[face_edge_start[f]..face_edge_start[f + 1]]`.
    face_edge_start: Vec<u32>,
    face_edges: Vec<u32>,
    /// Edges at each vertex, likewise.
    vertex_edge_start: Vec<u32>,
    vertex_edges: Vec<u32>,
    /// Per cube-map cell: the face whose normal is nearest the cell's central direction.
    start_face: Vec<u32>,
}

/// Per-thread state of the walk: which faces were tested at which point, and the loop found.
#[derive(Clone, Debug, Default)]
pub(crate) struct WalkScratch {
    /// Per face: `2·stamp + front` once tested at the current point.
    face_state: Vec<u64>,
    stamp: u64,
    /// The loop as (edge, start vertex), in walk order.
    edges: Vec<(u32, u32)>,
}

fn cell_of(d: DVec3) -> usize {
    let a = d.abs();
    let (axis, u, v, m) = if a.x >= a.y && a.x >= a.z {
        (usize::from(d.x < 0.0), d.y, d.z, a.x)
    } else if a.y >= a.z {
        (2 + usize::from(d.y < 0.0), d.z, d.x, a.y)
    } else {
        (4 + usize::from(d.z < 0.0), d.x, d.y, a.z)
    };
    let m = m.max(f64::MIN_POSITIVE);
    let cell = |t: f64| (((t / m + 1.0) * 0.5 * GRID as f64) as usize).min(GRID - 1);
    (axis * GRID + cell(u)) * GRID + cell(v)
}

fn cell_direction(c: usize) -> DVec3 {
    let (axis, rest) = (c / (GRID * GRID), c % (GRID * GRID));
    let t = |i: usize| ((i as f64 + 0.5) / GRID as f64) * 2.0 - 1.0;
    let (u, v) = (t(rest / GRID), t(rest % GRID));
    let s = if axis % 2 == 0 { 1.0 } else { -1.0 };
    match axis / 2 {
        0 => DVec3::new(s, u, v),
        1 => DVec3::new(v, s, u),
        _ => DVec3::new(u, v, s),
    }
    .normalize()
}

impl ContourWalk {
    /// The walk's adjacency for a closed convex mesh; `None` for other meshes or small ones.
    pub fn new(poly: &Polyhedron) -> Option<ContourWalk> {
        let d = &poly.diagnostics;
        if !d.convex || !d.closed_manifold || poly.edges.len() < WALK_MIN_EDGES {
            return None;
        }
        let mut face_pairs = Vec::with_capacity(2 * poly.edges.len());
        let mut vertex_pairs = Vec::with_capacity(2 * poly.edges.len());
        for (e, edge) in poly.edges.iter().enumerate() {
            for &f in &edge.faces {
                if f != NO_FACE {
                    face_pairs.push((f, e as u32));
                }
            }
            vertex_pairs.push((edge.v[0], e as u32));
            vertex_pairs.push((edge.v[1], e as u32));
        }
        let (face_edge_start, face_edges) = compressed_rows(poly.face_count(), face_pairs);
        let (vertex_edge_start, vertex_edges) = compressed_rows(poly.vertices.len(), vertex_pairs);
        let start_face = (0..6 * GRID * GRID)
            .map(|c| {
                let dir = cell_direction(c);
                (0..poly.face_count())
                    .max_by(|&a, &b| {
                        poly.face_planes[a]
                            .n
                            .dot(dir)
                            .total_cmp(&poly.face_planes[b].n.dot(dir))
                    })
                    .unwrap_or(0) as u32
            })
            .collect();
        Some(ContourWalk {
            face_edge_start,
            face_edges,
            vertex_edge_start,
            vertex_edges,
            start_face,
        })
    }
}

/// `(row, value)` pairs as compressed rows: row `k` is `values[start[k]..start[k + 1]]`, in
/// the pairs' order.
fn compressed_rows(rows: usize, mut pairs: Vec<(u32, u32)>) -> (Vec<u32>, Vec<u32>) {
    pairs.sort_by_key(|p| p.0);
    let mut start = vec![0u32; rows + 1];
    for &(k, _) in &pairs {
        start[k as usize + 1] += 1;
    }
    for k in 0..rows {
        start[k + 1] += start[k];
    }
    (start, pairs.into_iter().map(|p| p.1).collect())
}

/// The silhouette of `poly` (closed, convex, with walk adjacency `walk`) from `x`, exactly as
/// the scan in [`crate::geometry::silhouettes::silhouette`] writes it; `false` (with `out` cleared) where the walk
/// cannot decide and the caller must scan.
pub(crate) fn walk_silhouette(
    poly: &Polyhedron,
    walk: &ContourWalk,
    x: DVec3,
    frame: &Frame,
    out: &mut SphericalPolygon,
    s: &mut WalkScratch,
) -> bool {
    out.clear();
    let nf = poly.face_count();
    if s.face_state.len() < nf {
        s.face_state.resize(nf, 0);
    }
    s.stamp += 1;
    let stamp = s.stamp;
    let mut front = |f: u32| -> bool {
        let st = s.face_state[f as usize];
        if st >> 1 == stamp {
            return st & 1 == 1;
        }
        let b = poly.face_planes[f as usize].eval(x) > 0.0;
        s.face_state[f as usize] = (stamp << 1) | u64::from(b);
        b
    };
    let other = |e: u32, f: u32| {
        let faces = poly.edges[e as usize].faces;
        if faces[0] == f { faces[1] } else { faces[0] }
    };

    // 1. A first contour edge: walk down (from a front face) or up (from a back face) the
    //    signed distance until a neighbour has the other side.
    let mut cur = walk.start_face[cell_of(x - poly.center)];
    let mut cur_eval = poly.face_planes[cur as usize].eval(x);
    let cur_front = front(cur);
    let mut found = None;
    for _ in 0..nf {
        let edges = &walk.face_edges[walk.face_edge_start[cur as usize] as usize
            ..walk.face_edge_start[cur as usize + 1] as usize];
        let mut best: Option<(u32, f64)> = None;
        for &e in edges {
            let g = other(e, cur);
            if front(g) != cur_front {
                found = Some(e);
                break;
            }
            let eg = poly.face_planes[g as usize].eval(x);
            let better = if cur_front {
                eg < cur_eval
            } else {
                eg > cur_eval
            };
            if better && best.is_none_or(|(_, b)| if cur_front { eg < b } else { eg > b }) {
                best = Some((g, eg));
            }
        }
        if found.is_some() {
            break;
        }
        match best {
            Some((g, eg)) => (cur, cur_eval) = (g, eg),
            None => return false, // a local extremum: let the scan decide
        }
    }
    let Some(first) = found else { return false };

    // 2. Trace the loop: oriented so that the front face lies to its left (the scan's rule).
    let oriented = |e: u32, front: &mut dyn FnMut(u32) -> bool| -> Option<(u32, u32)> {
        let edge = &poly.edges[e as usize];
        match (front(edge.faces[0]), front(edge.faces[1])) {
            (true, false) => Some((edge.v[1], edge.v[0])),
            (false, true) => Some((edge.v[0], edge.v[1])),
            _ => None,
        }
    };
    s.edges.clear();
    let Some((a0, mut b)) = oriented(first, &mut front) else {
        return false;
    };
    s.edges.push((first, a0));
    let mut prev = first;
    while b != a0 {
        if s.edges.len() > poly.edges.len() {
            return false;
        }
        let at = &walk.vertex_edges[walk.vertex_edge_start[b as usize] as usize
            ..walk.vertex_edge_start[b as usize + 1] as usize];
        let mut next = None;
        for &e in at {
            if e == prev {
                continue;
            }
            if let Some((from, to)) = oriented(e, &mut front)
                && from == b
            {
                if next.is_some() {
                    return false; // two outgoing contour edges: the front faces touch here
                }
                next = Some((e, to));
            }
        }
        let Some((e, to)) = next else { return false };
        s.edges.push((e, b));
        prev = e;
        b = to;
    }
    // The scan starts at the smallest contour edge index.
    let start = s
        .edges
        .iter()
        .enumerate()
        .min_by_key(|(_, (e, _))| *e)
        .map_or(0, |(k, _)| k);
    let n = s.edges.len();
    for k in 0..n {
        let (_, a) = s.edges[(start + k) % n];
        if let Some(d) = frame
            .to_local(poly.vertices[a as usize] - x)
            .try_normalize()
        {
            out.push_vertex(d);
        }
    }
    out.close_loop();
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{IndexedPolyhedron, Sidedness, SilhouetteScratch, silhouette};
    use crate::math::Pcg32;
    use crate::scene::shapes::{icosphere, uv_ellipsoid};

    fn vertices_of(p: &SphericalPolygon) -> Vec<[u64; 3]> {
        p.loops()
            .flat_map(|l| l.iter().map(|v| v.to_array().map(f64::to_bits)))
            .collect()
    }

    /// The walk against the scan (a second algorithm over the same predicate), bit for bit, at
    /// random points and at points in the planes of faces and on vertices' lines of sight.
    #[test]
    fn walk_gives_the_scan_bit_for_bit() {
        let mut rng = Pcg32::new(21, 4);
        let meshes = [
            uv_ellipsoid(
                DVec3::new(0.3, 1.0, -0.2),
                DVec3::new(0.8, 0.5, 0.6),
                32,
                16,
            ),
            icosphere(DVec3::ZERO, 1.0, 3),
        ];
        let (mut walked, mut fell_back) = (0, 0);
        for m in &meshes {
            let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
            assert!(poly.index.contour_walk.is_some());
            let mut scan_only = poly.clone();
            scan_only.index.contour_walk = None;
            let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
            let (mut sa, mut sb) = (SilhouetteScratch::default(), SilhouetteScratch::default());
            let mut ws = WalkScratch::default();
            for k in 0..6000 {
                let x = match k % 3 {
                    0 => poly.center + rng.unit_vector() * poly.radius * rng.range(1.0, 6.0),
                    // In the plane of a face, outside the mesh.
                    1 => {
                        let f = rng.below(poly.face_count() as u32) as usize;
                        let v = poly.vertices[poly.face(f)[0] as usize];
                        let n = poly.face_planes[f].n;
                        let t = rng.unit_vector().cross(n).normalize_or_zero();
                        v + t * poly.radius * rng.range(0.01, 3.0)
                    }
                    // On the line through two vertices, beyond one of them.
                    _ => {
                        let i = rng.below(poly.vertices.len() as u32) as usize;
                        let j = rng.below(poly.vertices.len() as u32) as usize;
                        let (p, q) = (poly.vertices[i], poly.vertices[j]);
                        p + (p - q) * rng.range(0.1, 3.0)
                    }
                };
                let frame = Frame::from_z(rng.unit_vector());
                silhouette(&poly, x, &frame, Sidedness::TwoSided, &mut a, &mut sa);
                silhouette(&scan_only, x, &frame, Sidedness::TwoSided, &mut b, &mut sb);
                assert_eq!(vertices_of(&a), vertices_of(&b), "at {x}");
                let mut c = SphericalPolygon::new();
                if walk_silhouette(
                    &poly,
                    poly.index.contour_walk.as_ref().unwrap(),
                    x,
                    &frame,
                    &mut c,
                    &mut ws,
                ) {
                    walked += 1;
                } else {
                    fell_back += 1;
                }
            }
        }
        // The walk decides almost everywhere; the scan takes the rest.
        assert!(
            walked > 10 * fell_back,
            "{walked} walked, {fell_back} fell back"
        );
        eprintln!("{walked} walked, {fell_back} fell back to the scan");
    }
}
