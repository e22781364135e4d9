//! Contour edges (001 Eq. 4.2) and the ordered silhouette loop of a convex or flat polyhedron
//! (001 Sect. 4.2; 000 Alg. 2), as a spherical polygon in the shading frame.
//!
//! 000 Alg. 2 orders the silhouette edges by repeatedly searching the nearest endpoint in a
//! projection (quadratic, and fragile when endpoints nearly coincide). Here the contour edges
//! are oriented from the adjacency alone (001 Sect. 4.2: an edge runs counter-clockwise around
//! its front-facing face) and chained through their shared vertex indices: linear time, exact
//! and independent of any projection.

use crate::geometry::SphericalPolygon;
use crate::geometry::mesh::mesh_index::IndexedPolyhedron;
use crate::geometry::mesh::polyhedron::{NO_FACE, Plane, Polyhedron};
use crate::geometry::silhouettes::silhouette_walk::{WalkScratch, walk_silhouette};
use crate::geometry::trees::bsp::LOOP_END;
use crate::math::Frame;
use glam::DVec3;

const NONE: u32 = u32::MAX;

/// Reusable buffers for [`silhouette`]; sized lazily to the largest mesh seen.
#[derive(Clone, Debug, Default)]
pub struct SilhouetteScratch {
    front: Vec<bool>,
    /// Per vertex: first outgoing contour edge (index into `contour`), or NONE.
    head: Vec<u32>,
    /// Contour edges as (from, to, next outgoing edge of `from`).
    contour: Vec<(u32, u32, u32)>,
    used: Vec<bool>,
    /// Edges gathered by a lookup in a hoisted tree (`bsp_hoisted`), reused.
    pub hoisted: Vec<[u32; 2]>,
    walk: WalkScratch,
}

/// Is face `f` front-facing from `x`, i.e. does `x` lie strictly on its front side?
/// (001 Eq. 4.1, with the normal pointing to the front.) Points in the face plane see neither side.
#[inline]
pub(crate) fn is_front_facing(poly: &Polyhedron, f: usize, x: DVec3) -> bool {
    poly.face_planes[f].eval(x) > 0.0
}

/// Contour edges from `x` (001 Eq. 4.2): edges with exactly one front-facing adjacent face
/// (a boundary edge counts when its only face is front-facing). Each is returned with the
/// orientation that makes the silhouette positively oriented (see [`SphericalPolygon`]).
pub fn contour_edges<'a>(poly: &'a Polyhedron, x: DVec3) -> impl Iterator<Item = [u32; 2]> + 'a {
    poly.edges.iter().filter_map(move |e| {
        let f0 = is_front_facing(poly, e.faces[0] as usize, x);
        let f1 = e.faces[1] != NO_FACE && is_front_facing(poly, e.faces[1] as usize, x);
        match (f0, f1) {
            (true, false) => Some([e.v[1], e.v[0]]),
            (false, true) => Some([e.v[0], e.v[1]]),
            _ => None,
        }
    })
}

/// How the back of a flat mesh is treated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sidedness {
    /// Lights emit from the front only: a flat light seen from behind has no silhouette.
    FrontOnly,
    /// Occluders block from both sides: a flat occluder seen from behind is taken as a whole.
    TwoSided,
}

/// `SphPolySilhouette` of 000 Alg. 1/2 for a mesh with `Polyhedron::has_simple_silhouette`:
/// the contour of the mesh seen from `x`, chained into loops, moved to `x` as origin, expressed
/// in `frame` and projected to the unit sphere. Writes positively oriented loops into `out`
/// (cleared first). Vertices that coincide with `x` are dropped (they subtend no solid angle).
pub fn silhouette(
    poly: &IndexedPolyhedron,
    x: DVec3,
    frame: &Frame,
    sidedness: Sidedness,
    out: &mut SphericalPolygon,
    scratch: &mut SilhouetteScratch,
) {
    // A large convex mesh: walk the contour instead of scanning it (the same loop).
    if let Some(walk) = &poly.index.contour_walk
        && walk_silhouette(poly, walk, x, frame, out, &mut scratch.walk)
    {
        return;
    }
    out.clear();
    if let Some(outline) = &poly.index.planar_outline
        && let Some(loops) = outline.seen_from(poly, x, sidedness)
    {
        emit_loops(poly, x, frame, loops, out);
        return;
    }
    let nf = poly.face_count();
    let nv = poly.vertices.len();
    scratch.front.clear();
    scratch
        .front
        .extend((0..nf).map(|f| is_front_facing(poly, f, x)));
    if sidedness == Sidedness::TwoSided
        && poly.diagnostics.planar
        && !scratch.front.iter().any(|&b| b)
    {
        // Seen from behind: the back of a flat occluder blocks just as its front does. Its
        // outline is the boundary of all faces, wound the other way.
        let behind = (0..nf).all(|f| poly.face_planes[f].eval(x) < 0.0);
        if behind {
            scratch.front.iter_mut().for_each(|b| *b = true);
            chain_contour(poly, x, frame, true, out, scratch);
        }
        return;
    }
    if scratch.head.len() < nv {
        scratch.head.resize(nv, NONE);
    }
    chain_contour(poly, x, frame, false, out, scratch);
}

fn chain_contour(
    poly: &Polyhedron,
    x: DVec3,
    frame: &Frame,
    reversed: bool,
    out: &mut SphericalPolygon,
    scratch: &mut SilhouetteScratch,
) {
    chain_contour_indices(poly, reversed, scratch, |v| match v {
        Some(a) => {
            if let Some(d) = frame
                .to_local(poly.vertices[a as usize] - x)
                .try_normalize()
            {
                out.push_vertex(d);
            }
        }
        None => {
            out.close_loop();
        }
    });
}

/// The contour edges of the faces marked in `scratch.front` chained into loops: `emit(Some(v))`
/// for each loop's vertices in order, `emit(None)` at the end of each loop.
fn chain_contour_indices(
    poly: &Polyhedron,
    reversed: bool,
    scratch: &mut SilhouetteScratch,
    mut emit: impl FnMut(Option<u32>),
) {
    let nv = poly.vertices.len();
    if scratch.head.len() < nv {
        scratch.head.resize(nv, NONE);
    }
    scratch.contour.clear();
    for e in &poly.edges {
        let f0 = scratch.front[e.faces[0] as usize];
        let f1 = e.faces[1] != NO_FACE && scratch.front[e.faces[1] as usize];
        let (a, b) = match (f0, f1) {
            (true, false) => (e.v[1], e.v[0]),
            (false, true) => (e.v[0], e.v[1]),
            _ => continue,
        };
        let (a, b) = if reversed { (b, a) } else { (a, b) };
        let id = scratch.contour.len() as u32;
        scratch.contour.push((a, b, scratch.head[a as usize]));
        scratch.head[a as usize] = id;
    }
    scratch.used.clear();
    scratch.used.resize(scratch.contour.len(), false);

    // Chain: from each unused edge, follow the outgoing edges of its end vertex until the loop
    // closes. The boundary of a set of faces of an oriented manifold is a 1-cycle (as many edges
    // leave each vertex as enter it), so the walk always closes.
    for start in 0..scratch.contour.len() {
        if scratch.used[start] {
            continue;
        }
        // Bound: each step marks an unused contour edge used (the candidates skip used ones): at
        // most `contour.len()` steps over all loops; the scan along a vertex's list is as long as
        // the list, which holds each edge once.
        let mut e = start as u32;
        let first_vertex = scratch.contour[start].0;
        loop {
            scratch.used[e as usize] = true;
            let (a, b, _) = scratch.contour[e as usize];
            emit(Some(a));
            if b == first_vertex {
                break;
            }
            // Next unused outgoing edge of b.
            let mut cand = scratch.head[b as usize];
            while cand != NONE && scratch.used[cand as usize] {
                cand = scratch.contour[cand as usize].2;
            }
            if cand == NONE {
                break; // open chain (non-manifold input): drop what cannot close
            }
            e = cand;
        }
        emit(None);
    }
    for &(a, _, _) in &scratch.contour {
        scratch.head[a as usize] = NONE;
    }
}

/// The outline of a flat mesh, chained once when the mesh is indexed: seen from either side of
/// its plane the contour is the boundary of all its faces, so only the side is decided per
/// point. The loops are those [`silhouette`]'s chaining would produce (the same edges, the same
/// order), so the result is the same to the bit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanarOutline {
    /// Vertex indices of the loops seen from the front (every face front-facing), each loop
    /// ended by `LOOP_END`.
    front: Vec<u32>,
    /// The same seen from behind, wound the other way (a two-sided occluder's back).
    behind: Vec<u32>,
}

impl PlanarOutline {
    /// The outline of `poly` if it is flat (every face in one plane), else `None`.
    pub fn new(poly: &Polyhedron) -> Option<Self> {
        if !poly.diagnostics.planar || poly.face_count() == 0 {
            return None;
        }
        let mut scratch = SilhouetteScratch {
            front: vec![true; poly.face_count()],
            ..Default::default()
        };
        let mut chain = |reversed: bool| {
            let mut loops = Vec::new();
            chain_contour_indices(poly, reversed, &mut scratch, |v| {
                loops.push(v.unwrap_or(LOOP_END))
            });
            loops
        };
        Some(PlanarOutline {
            front: chain(false),
            behind: chain(true),
        })
    }

    /// The loops seen from `x` when every face is strictly on one side of it, and that side
    /// shows an outline: `Some(&[])` where `x` sees no outline (behind a light, in the plane of
    /// a two-sided occluder's faces), `None` where the faces' planes disagree (within
    /// rounding of the plane: the caller then decides face by face).
    fn seen_from(&self, poly: &Polyhedron, x: DVec3, sidedness: Sidedness) -> Option<&[u32]> {
        let (mut front, mut behind) = (0usize, 0usize);
        for plane in &poly.face_planes {
            let s = plane.eval(x);
            front += (s > 0.0) as usize;
            behind += (s < 0.0) as usize;
        }
        let n = poly.face_planes.len();
        if front == n {
            Some(&self.front)
        } else if front > 0 {
            None
        } else if sidedness == Sidedness::TwoSided && behind == n {
            Some(&self.behind)
        } else {
            Some(&[])
        }
    }
}

/// Appends `loops` (vertex indices, each loop ended by `LOOP_END`, as a silhouette tree's leaf
/// and [`PlanarOutline`] hold them) seen from `x` to `out`, as `chain_contour` writes them:
/// vertices that coincide with `x` are dropped.
pub(crate) fn emit_loops(
    poly: &Polyhedron,
    x: DVec3,
    frame: &Frame,
    loops: &[u32],
    out: &mut SphericalPolygon,
) {
    for &v in loops {
        if v == LOOP_END {
            out.close_loop();
        } else if let Some(d) = frame
            .to_local(poly.vertices[v as usize] - x)
            .try_normalize()
        {
            out.push_vertex(d);
        }
    }
}

/// The part of a face in front of a plane, with a tolerance: a corner within `tol` of the plane
/// lies on it. The pipeline cuts an occluder face at a light face's plane so that only what is
/// in front of that light face (seen from `x`, on the plane's positive side) is subtracted:
/// exact depth order for planar light pieces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontCut {
    pub plane: Plane,
    /// Distance (in the plane's units, `eval`) within which a corner lies on the plane.
    pub tol: f64,
}

impl FrontCut {
    /// The plane moved by the tolerance toward its front: what lies strictly in front of it is
    /// in front of the cut.
    #[inline]
    pub fn front_plane(&self) -> Plane {
        Plane {
            n: self.plane.n,
            d: self.plane.d + self.tol,
        }
    }
}

/// One face of a mesh as a spherical polygon from `x` (the per-triangle method, 000 Sect. 4.4):
/// positively oriented; empty when `x` lies in the face plane, or behind a light's face.
///
/// With `keep_front_of = Some(cut)` the face is first cut to its part in front of the cut
/// (Sutherland–Hodgman in 3D), empty when no corner lies in front. A corner on the plane (within
/// the tolerance) is kept as itself, not replaced by a point computed on an edge beside it: the
/// faces of a mesh that share a corner of the light face then give that corner to the bit, as
/// the light face does, where a computed point would lie up to tol / sin(angle) away and leave
/// a sliver between the copies (the boundary formulation's pieces, docs/boundary-integral.md).
/// A point where an edge crosses is computed from the edge's lower-indexed end, so that the two
/// faces sharing the edge get the same point.
#[allow(clippy::too_many_arguments)]
pub fn face_polygon(
    poly: &Polyhedron,
    f: usize,
    x: DVec3,
    frame: &Frame,
    sidedness: Sidedness,
    keep_front_of: Option<&FrontCut>,
    out: &mut SphericalPolygon,
    buf: &mut Vec<DVec3>,
) {
    out.clear();
    let s = poly.face_planes[f].eval(x);
    let forward = if s > 0.0 {
        false
    } else if s < 0.0 && sidedness == Sidedness::TwoSided {
        true
    } else {
        return;
    };
    buf.clear();
    let idx = poly.face(f);
    match keep_front_of {
        None => buf.extend(idx.iter().map(|&i| poly.vertices[i as usize])),
        Some(cut) => {
            let front = cut.front_plane();
            // More than `tol` in front of the cut's plane (1), more than `tol` behind it (−1),
            // on it within `tol` (0); `d` is measured from the plane moved by `tol`.
            let side = |d: f64| {
                if d > 0.0 {
                    1
                } else if d < -2.0 * cut.tol {
                    -1
                } else {
                    0
                }
            };
            let n = idx.len();
            let mut any_front = false;
            for k in 0..n {
                let (ia, ib) = (idx[k], idx[(k + 1) % n]);
                let (a, b) = (poly.vertices[ia as usize], poly.vertices[ib as usize]);
                let (da, db) = (front.eval(a), front.eval(b));
                let (sa, sb) = (side(da), side(db));
                any_front |= sa > 0;
                if sa >= 0 {
                    buf.push(a);
                }
                if sa * sb < 0 {
                    // A convex combination with non-negative weights stays on the segment;
                    // taken from the lower-indexed end, both faces of the edge get one point.
                    let (p, q, dp, dq) = if ia < ib {
                        (a, b, da, db)
                    } else {
                        (b, a, db, da)
                    };
                    buf.push(p + (q - p) * (dp / (dp - dq)));
                }
            }
            if !any_front {
                // Nothing in front: at most a polygon in the plane, which hides nothing.
                return;
            }
        }
    }
    let mut push = |p: DVec3| {
        if let Some(d) = frame.to_local(p - x).try_normalize() {
            out.push_vertex(d);
        }
    };
    if forward {
        buf.iter().for_each(|&p| push(p));
    } else {
        buf.iter().rev().for_each(|&p| push(p));
    }
    out.close_loop();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    fn cube() -> Polyhedron {
        let m = crate::scene::shapes::cuboid(DVec3::ZERO, DVec3::ONE);
        Polyhedron::new(&m.positions, &m.faces)
    }

    /// Solid angle of the cube seen from x by brute-force ray casting against its 12 triangles.
    fn cube_solid_angle_mc(poly: &Polyhedron, x: DVec3, rng: &mut Pcg32, n: usize) -> (f64, f64) {
        let mut hits = 0usize;
        for _ in 0..n {
            let d = rng.unit_vector();
            // Slab test against [-1, 1]^3.
            let inv = d.recip();
            let t0 = (DVec3::splat(-1.0) - x) * inv;
            let t1 = (DVec3::splat(1.0) - x) * inv;
            let tmin = t0.min(t1).max_element();
            let tmax = t0.max(t1).min_element();
            if tmax >= tmin.max(0.0) {
                hits += 1;
            }
        }
        let _ = poly;
        let p = hits as f64 / n as f64;
        (
            4.0 * std::f64::consts::PI * p,
            4.0 * std::f64::consts::PI * (p * (1.0 - p) / n as f64).sqrt(),
        )
    }

    /// A flat mesh's outline chained once is the outline chained at the point: the same
    /// loops to the bit, from the front, from behind (two-sided or not) and from its plane.
    #[test]
    fn planar_outline_is_the_chained_outline() {
        // A square ring of eight quads in the plane y = 0.5 (two loops: outside and the hole),
        // facing +y.
        let g = |i: usize, j: usize| DVec3::new(i as f64 - 1.5, 0.5, j as f64 - 1.5);
        let positions: Vec<DVec3> = (0..16).map(|k| g(k % 4, k / 4)).collect();
        let id = |i: usize, j: usize| (j * 4 + i) as u32;
        let mut faces = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                if (i, j) != (1, 1) {
                    faces.push(vec![id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
                }
            }
        }
        let once = IndexedPolyhedron::from(Polyhedron::new(&positions, &faces));
        assert!(once.index.planar_outline.is_some());
        let mut each = once.clone();
        each.index.planar_outline = None;
        let mut rng = Pcg32::new(5, 11);
        let frame = Frame::from_z(DVec3::new(0.3, 0.8, -0.2).normalize());
        let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
        let mut scratch = SilhouetteScratch::default();
        let mut loops_seen = [0usize; 3];
        for k in 0..300 {
            let mut x = rng.unit_vector() * rng.range(0.2, 4.0);
            if k % 10 == 0 {
                x.y = 0.5; // in the plane
            }
            if k % 10 == 1 {
                x = g(1, 1) + DVec3::new(0.5, 0.0, 0.5); // a vertex-free point of the plane
            }
            for sidedness in [Sidedness::FrontOnly, Sidedness::TwoSided] {
                silhouette(&once, x, &frame, sidedness, &mut a, &mut scratch);
                silhouette(&each, x, &frame, sidedness, &mut b, &mut scratch);
                assert_eq!(a.loop_count(), b.loop_count(), "{x} {sidedness:?}");
                assert_eq!(a.vertices(), b.vertices(), "{x} {sidedness:?}");
                loops_seen[a.loop_count().min(2)] += 1;
            }
        }
        // Every case was met: nothing seen, and the ring's two loops.
        assert!(loops_seen[0] > 0 && loops_seen[2] > 0, "{loops_seen:?}");
    }

    #[test]
    fn cube_silhouette_is_one_positive_loop_with_the_right_solid_angle() {
        let poly = IndexedPolyhedron::from(cube());
        let mut scratch = SilhouetteScratch::default();
        let mut out = SphericalPolygon::new();
        let mut rng = Pcg32::new(3, 9);
        for _ in 0..50 {
            let x = rng.unit_vector() * rng.range(1.8, 6.0);
            let frame = Frame::from_z(rng.unit_vector());
            silhouette(
                &poly,
                x,
                &frame,
                Sidedness::FrontOnly,
                &mut out,
                &mut scratch,
            );
            assert_eq!(out.loop_count(), 1);
            let n = out.loop_at(0).len();
            assert!(
                n == 4 || n == 6,
                "a cube's silhouette has 4 or 6 edges, got {n}"
            );
            // The silhouette of a convex body from outside lies in a hemisphere: exact solid angle.
            let omega = out.signed_solid_angle();
            let (mc, sigma) = cube_solid_angle_mc(&poly, x, &mut rng, 100_000);
            assert!(
                (omega - mc).abs() < 4.5 * sigma,
                "{omega} vs {mc} ± {sigma}"
            );
            assert_eq!(contour_edges(&poly, x).count(), n);
        }
    }

    #[test]
    fn flat_occluder_seen_from_behind_is_two_sided_but_a_flat_light_is_not() {
        let p = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ];
        let quad = IndexedPolyhedron::new(&p, &[vec![0, 1, 2, 3]]); // front = +z
        let mut scratch = SilhouetteScratch::default();
        let mut out = SphericalPolygon::new();
        let frame = Frame::from_z(DVec3::Z);
        for (x, side, expect) in [
            (DVec3::new(0.2, 0.1, 2.0), Sidedness::FrontOnly, true),
            (DVec3::new(0.2, 0.1, -2.0), Sidedness::FrontOnly, false),
            (DVec3::new(0.2, 0.1, -2.0), Sidedness::TwoSided, true),
            (DVec3::new(3.0, 0.1, 0.0), Sidedness::TwoSided, false),
        ] {
            silhouette(&quad, x, &frame, side, &mut out, &mut scratch);
            assert_eq!(!out.is_empty(), expect, "x = {x}, {side:?}");
            if expect {
                assert!(out.signed_solid_angle() > 0.0);
                let mut face = SphericalPolygon::new();
                face_polygon(&quad, 0, x, &frame, side, None, &mut face, &mut Vec::new());
                assert!((face.signed_solid_angle() - out.signed_solid_angle()).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn point_on_a_face_plane_sees_no_silhouette_of_a_convex_body_from_inside_its_face() {
        let poly = IndexedPolyhedron::from(cube());
        let mut scratch = SilhouetteScratch::default();
        let mut out = SphericalPolygon::new();
        // A point on the +z face: no face is strictly front-facing.
        silhouette(
            &poly,
            DVec3::new(0.3, -0.2, 1.0),
            &Frame::from_z(DVec3::Z),
            Sidedness::TwoSided,
            &mut out,
            &mut scratch,
        );
        assert!(out.is_empty());
    }

    /// A light face's corners reach its neighbours' cut polygons to the bit, and an edge
    /// crossing the cut plane gives its two faces one point: the copies the boundary
    /// formulation must not see as two (oracle: the light face's own polygon, and each other).
    #[test]
    fn a_cut_keeps_shared_corners_and_shares_crossings() {
        let positions = [
            DVec3::ZERO,                  // c: a corner of the light face
            DVec3::new(1.0, 0.0, 0.0),    // p1
            DVec3::new(0.0, 0.0, 1.0),    // p2: a corner of the light face
            DVec3::new(-1.0, -1e-3, 0.2), // q: just in front (front is −y)
            DVec3::new(-0.5, -0.5, -1.0), // r: in front
            DVec3::new(0.5, 0.5, -1.0),   // s: behind
            DVec3::new(0.0, 0.2, -2.0),   // t: behind
        ];
        let faces = vec![
            vec![0, 1, 2], // the light face, normal −y
            vec![0, 2, 3], // shares the edge c p2, nearly coplanar
            vec![0, 4, 5], // shares c, crosses the plane along r s
            vec![4, 6, 5], // shares r s, the other way round
        ];
        let poly = Polyhedron::new(&positions, &faces);
        let x = DVec3::new(0.3, -1.0, 0.3);
        let frame = Frame::from_z(DVec3::new(0.1, -1.0, 0.2).normalize());
        let cut = FrontCut {
            plane: poly.face_planes[0],
            tol: 1e-12 * 3.0,
        };
        let polygon = |f: usize, cut: Option<&FrontCut>| {
            let mut out = SphericalPolygon::new();
            face_polygon(
                &poly,
                f,
                x,
                &frame,
                Sidedness::TwoSided,
                cut,
                &mut out,
                &mut Vec::new(),
            );
            out.vertices().to_vec()
        };
        let light = polygon(0, None);
        let (c, p2) = (light[2], light[0]);
        let direction = |p: DVec3| frame.to_local(p - x).normalize();
        assert_eq!(c, direction(positions[0]));
        assert_eq!(p2, direction(positions[2]));
        let near = polygon(1, Some(&cut));
        assert_eq!(near.len(), 3, "{near:?}");
        assert!(near.contains(&c) && near.contains(&p2), "{near:?} {c} {p2}");
        let a = polygon(2, Some(&cut));
        let b = polygon(3, Some(&cut));
        assert_eq!(a.len(), 3, "{a:?}");
        assert!(a.contains(&c), "{a:?}");
        let shared: Vec<&DVec3> = a.iter().filter(|v| b.contains(v)).collect();
        // r and the crossing of r s.
        assert_eq!(shared.len(), 2, "{a:?} {b:?}");
        // The crossing lies on the light face's plane (to rounding).
        let crossing = shared
            .iter()
            .find(|v| ***v != direction(positions[4]))
            .unwrap();
        let along = positions[4] + (positions[5] - positions[4]) * 0.5;
        assert!((**crossing - direction(along)).length() < 1e-9);
    }
}
