//! Meshes that are convex up to the precision of their input, and the convex hull that stands
//! in for them (docs/silhouettes.md, "Convex up to the input's precision").
//!
//! A UV sphere written with six decimals is not convex as stored: rounding moves its vertices
//! by up to 5e-7 per coordinate, so some lie a little outside the planes of neighbouring faces.
//! As meant, it was convex. [`convex_stand_in`] tells the two apart and gives the convex path
//! a polyhedron that *is* convex, the hull H of the mesh's vertices, with a bound on what the
//! substitution changes.
//!
//! **Test.** Each face is split into the fan triangles t the renderer's ray caster sees; for
//! every vertex v and triangle t, the signed distance e = n_t·v − d_t must not exceed
//! `τ(v, t) = 1e-9 R + r (2 + |v − c_t| P_t / A_t)`, where r is the mesh's rounding radius
//! (`Mesh::rounding`), R its radius, c_t, P_t, A_t the triangle's centroid, perimeter and
//! area: moving every vertex by at most r moves v by r, the centroid by r and turns the normal
//! by at most r P_t / A_t (the change of the area vector over its length), hence the plane at
//! v by r |v − c_t| P_t / A_t. A mesh within that of convex could have been convex as meant.
//!
//! **Bound.** Let P₀ = ∩_t {n_t·y ≤ d_t} and M the solid the mesh bounds. A point strictly
//! inside every triangle's plane sees every triangle from behind, so the signed solid angles
//! of the triangles, which sum to 4π times its winding number, are all negative: the winding
//! number is nonzero and the point is in M. Hence P₀ ⊆ M ⊆ H. With c the vertices' centroid,
//! strictly inside P₀ by m_t = d_t − n_t·c, the point q = v + s(c − v) is in P₀ for
//! s = max_t e_t⁺/(e_t⁺ + m_t), so every vertex of H is within δ_v = s|c − v| of P₀, and by
//! convexity of the distance to a convex set every point of H is within δ = max_v δ_v of P₀.
//! Seen from a point x at distance D > δ from H, a direction that meets H but not M meets
//! P₀ ⊕ B(δ) and misses P₀, so it lies within w = asin(δ / (D − δ)) of the convex spherical
//! region K that P₀ subtends. The outline of M and that of H both lie between K and its
//! w-neighbourhood, whose extra area is at most L sin w + (2π − |K|)(1 − cos w) ≤
//! 2π (sin w + 1 − cos w) (Steiner's formula on the sphere; a convex region's perimeter L
//! is at most 2π): [`solid_angle_bound`]. The form factor (1/π)∫cos changes by at most that
//! over π, the diffuse shading by at most ρ L_e times that.

use crate::geometry::Polyhedron;
use crate::geometry::mesh::convex_hull::convex_hull;
use glam::DVec3;
use rayon::prelude::*;

/// A convex polyhedron standing in for a mesh that is convex up to its input's precision.
#[derive(Clone, Debug)]
pub struct ConvexStandIn {
    /// The convex hull of the mesh's vertices.
    pub hull: Polyhedron,
    /// Every point of the hull is within this distance of the mesh's solid (δ above).
    pub deviation: f64,
    /// The farthest any vertex lies outside a triangle's plane (max e⁺).
    pub outside: f64,
}

/// Meshes with more vertex–triangle pairs than this are not tested (the test is quadratic);
/// they keep their own path.
pub(crate) const MAX_NEAR_CONVEX_PAIRS: usize = 400_000_000;

/// The hull of `mesh` if the mesh is closed, not exactly convex, and convex up to `rounding`
/// (the test above); `None` otherwise.
pub fn convex_stand_in(mesh: &Polyhedron, rounding: f64) -> Option<ConvexStandIn> {
    let d = &mesh.diagnostics;
    if !d.closed_manifold || d.convex || !is_rounding(rounding) {
        return None;
    }
    let used = used_vertices(mesh);
    let tris = fan_triangles(mesh);
    if used.len().saturating_mul(tris.len()) > MAX_NEAR_CONVEX_PAIRS || tris.is_empty() {
        return None;
    }
    let floor = 1e-9 * mesh.radius.max(f64::MIN_POSITIVE);
    let centre = used.iter().copied().sum::<DVec3>() / used.len() as f64;
    let margins: Vec<f64> = tris.iter().map(|t| t.d - t.n.dot(centre)).collect();
    if margins.iter().any(|&m| m.is_nan() || m <= 0.0) {
        return None;
    }
    // Per vertex: None if it is too far outside some plane, else (its largest excess, δ_v).
    let per_vertex: Option<Vec<(f64, f64)>> = used
        .par_iter()
        .map(|&v| {
            let (mut excess, mut s) = (0.0f64, 0.0f64);
            for (t, &m) in tris.iter().zip(&margins) {
                let e = t.n.dot(v) - t.d;
                if e <= 0.0 {
                    continue;
                }
                if e > floor + rounding * (2.0 + v.distance(t.c) * t.slope) {
                    return None;
                }
                excess = excess.max(e);
                s = s.max(e / (e + m));
            }
            Some((excess, s * v.distance(centre)))
        })
        .collect();
    let per_vertex = per_vertex?;
    let outside = per_vertex.iter().map(|p| p.0).fold(0.0, f64::max);
    let deviation = per_vertex.iter().map(|p| p.1).fold(0.0, f64::max);
    let h = convex_hull(&used)?;
    let hull = Polyhedron::new(&h.vertices, &h.faces);
    hull.diagnostics.convex.then_some(ConvexStandIn {
        hull,
        deviation,
        outside,
    })
}

/// The largest change of the solid angle a mesh subtends when its stand-in replaces it, seen
/// from a point at distance `distance` from the stand-in (the module's bound); 4π when the
/// point is within `deviation` of it.
pub fn solid_angle_bound(deviation: f64, distance: f64) -> f64 {
    use std::f64::consts::PI;
    if distance.is_nan() || distance <= deviation {
        return 4.0 * PI;
    }
    let sin_w = (deviation / (distance - deviation)).min(1.0);
    let cos_w = (1.0 - sin_w * sin_w).sqrt();
    2.0 * PI * (sin_w + 1.0 - cos_w)
}

/// A mesh flat up to rounding is bent by at most this much of its radius (coordinates written
/// with one decimal have a rounding that would admit a folded sheet): from points farther than
/// that from its plane, all its faces face one way.
pub(crate) const MAX_FLAT_BEND: f64 = 1e-6;

/// Meshes with more vertex–triangle pairs than this are not tested for flatness (flat lights
/// and cards are small).
pub(crate) const MAX_NEAR_FLAT_PAIRS: usize = 1_000_000;

/// For a mesh that is not planar as stored but flat as meant (a quad light whose six-decimal
/// corners bend it by 1e-8): the farthest a vertex lies off the plane of one of its fan
/// triangles, when every vertex lies within the tolerance `τ(v, t)` of the convexity test
/// (module documentation) of every triangle's plane and within `MAX_FLAT_BEND` of the radius,
/// and every triangle faces the same way; `None` otherwise, and for closed or non-manifold meshes.
///
/// Such a mesh's faces are one polygon as meant, and seen from a point not within the
/// tolerance of that plane they all face the same way, so the images of its faces tile the
/// image of its outline exactly: the flat path (the outline of the boundary edges) and the
/// face-by-face path integrate the same region, with the mesh's own vertices. Within the
/// bend of the plane (at most `MAX_FLAT_BEND` of the radius) the light is seen edge-on.
pub fn flat_up_to_rounding(mesh: &Polyhedron, rounding: f64) -> Option<f64> {
    let d = &mesh.diagnostics;
    if d.closed_manifold || d.planar || d.nonmanifold_edges > 0 || !is_rounding(rounding) {
        return None;
    }
    let used = used_vertices(mesh);
    let tris = fan_triangles(mesh);
    if tris.is_empty() || used.len().saturating_mul(tris.len()) > MAX_NEAR_FLAT_PAIRS {
        return None;
    }
    let n0 = tris[0].n;
    let floor = 1e-9 * mesh.radius.max(f64::MIN_POSITIVE);
    let thin = MAX_FLAT_BEND * mesh.radius;
    let mut off = 0.0f64;
    for t in &tris {
        if t.n.dot(n0) <= 0.0 {
            return None; // folded: not one polygon
        }
        for &v in &used {
            let e = (t.n.dot(v) - t.d).abs();
            if !(e <= floor + rounding * (2.0 + v.distance(t.c) * t.slope) && e <= thin) {
                return None;
            }
            off = off.max(e);
        }
    }
    Some(off)
}

/// A rounding radius the tests can use: positive and finite.
fn is_rounding(r: f64) -> bool {
    r > 0.0 && r.is_finite()
}

/// The vertices some face uses (only they count for the geometric tests).
fn used_vertices(mesh: &Polyhedron) -> Vec<DVec3> {
    let mut seen = vec![false; mesh.vertices.len()];
    mesh.face_indices
        .iter()
        .for_each(|&i| seen[i as usize] = true);
    (0..mesh.vertices.len())
        .filter(|&i| seen[i])
        .map(|i| mesh.vertices[i])
        .collect()
}

/// A fan triangle of a face with what the tolerance `τ(v, t)` needs: unit normal, plane
/// offset, centroid and perimeter over area.
struct Tri {
    n: DVec3,
    d: f64,
    c: DVec3,
    slope: f64,
}

/// The fan triangles of every face (the ones the renderer's ray caster sees), without the
/// slivers of no area (their neighbours carry the face).
fn fan_triangles(mesh: &Polyhedron) -> Vec<Tri> {
    let mut tris = Vec::new();
    for f in 0..mesh.face_count() {
        let idx = mesh.face(f);
        for k in 1..idx.len() - 1 {
            let [a, b, c] = [idx[0], idx[k], idx[k + 1]].map(|i| mesh.vertices[i as usize]);
            let area2 = (b - a).cross(c - a);
            let len = area2.length();
            if len.is_nan() || len <= 0.0 {
                continue;
            }
            let n = area2 / len;
            let perimeter = a.distance(b) + b.distance(c) + c.distance(a);
            tris.push(Tri {
                n,
                d: n.dot(a),
                c: (a + b + c) / 3.0,
                slope: perimeter / (0.5 * len),
            });
        }
    }
    tris
}
