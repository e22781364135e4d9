//! Procedural meshes and mesh transforms (docs/scenes.md).
//!
//! Every shape is built in f64 and, unless noted, is a closed two-manifold whose faces are
//! planar convex polygons, counter-clockwise seen from outside (so the signed volume is
//! positive). Light and occluder shapes that the convex method of paper 000 uses (cuboid,
//! cylinder, truncated cone, icosahedron, icospheres, ellipsoid) are convex polyhedra; `l_shape`
//! and `u_shape` are deliberately non-convex (paper 000, Sect. 4.4).
//!
//! Bad parameters never panic: segment counts are clamped to their minimum, negative radii and
//! sizes are treated as their absolute value, subdivision levels are capped; a shape whose size
//! is zero degenerates gracefully (zero-area faces), it is never malformed in its indices.

use super::Mesh;
use crate::math::polygon_area_vector;
use glam::{DAffine3, DMat3, DVec2, DVec3};
use std::collections::HashMap;

/// Highest icosphere subdivision level honoured (40962 vertices); larger requests are capped.
pub(crate) const MAX_ICOSPHERE_SUBDIVISIONS: u32 = 6;
/// Highest segment / slice / stack count honoured; larger requests are capped.
pub(crate) const MAX_SEGMENTS: u32 = 4096;

// ---------------------------------------------------------------------------------------------
// Mesh helpers: transforms and geometric queries.
// ---------------------------------------------------------------------------------------------

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The mesh under the affine map `t`. If `t` mirrors space (negative determinant) every
    /// face is reversed so that fronts stay fronts (CCW seen from the front is preserved).
    pub fn transformed(&self, t: &DAffine3) -> Mesh {
        let positions = self
            .positions
            .iter()
            .map(|&p| t.transform_point3(p))
            .collect();
        let mut faces = self.faces.clone();
        if t.matrix3.determinant() < 0.0 {
            for f in &mut faces {
                reverse_face(f);
            }
        }
        // The Frobenius norm bounds how much the map stretches any vector.
        let stretch = DVec3::new(
            t.matrix3.x_axis.length(),
            t.matrix3.y_axis.length(),
            t.matrix3.z_axis.length(),
        )
        .length();
        Mesh {
            positions,
            faces,
            rounding: self.rounding * stretch,
        }
    }

    /// The mesh moved by `offset`.
    pub fn translated(&self, offset: DVec3) -> Mesh {
        self.transformed(&DAffine3::from_translation(offset))
    }

    /// The mesh scaled per axis about the origin. An odd number of negative factors mirrors the
    /// mesh, so faces are reversed to keep the outward winding.
    pub(crate) fn scaled(&self, factors: DVec3) -> Mesh {
        self.transformed(&DAffine3::from_mat3(DMat3::from_diagonal(factors)))
    }

    /// Appends `other` (indices are offset). Used to merge shapes into one object.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.rounding = self.rounding.max(other.rounding);
        self.positions.extend_from_slice(&other.positions);
        self.faces.extend(
            other
                .faces
                .iter()
                .map(|f| f.iter().map(|&i| i + base).collect()),
        );
    }

    /// Newell's area vector of face `face`: its direction is the front normal (CCW winding) and
    /// its length the polygon's area. Zero for an unknown face or out-of-range indices.
    pub(crate) fn face_area_vector(&self, face: usize) -> DVec3 {
        let Some(f) = self.faces.get(face) else {
            return DVec3::ZERO;
        };
        let pts: Option<Vec<DVec3>> = f
            .iter()
            .map(|&i| self.positions.get(i as usize).copied())
            .collect();
        pts.map_or(DVec3::ZERO, polygon_area_vector)
    }

    /// Unit front normal of face `face`, or `None` if the face has no area.
    pub fn face_normal(&self, face: usize) -> Option<DVec3> {
        self.face_area_vector(face).try_normalize()
    }

    /// Signed enclosed volume (positive for a closed mesh whose faces wind CCW seen from
    /// outside). Meaningless for open meshes.
    pub fn signed_volume(&self) -> f64 {
        let p = |i: u32| {
            self.positions
                .get(i as usize)
                .copied()
                .unwrap_or(DVec3::ZERO)
        };
        self.triangles()
            .map(|[a, b, c]| p(a).dot(p(b).cross(p(c))))
            .sum::<f64>()
            / 6.0
    }

    /// Axis-aligned bounding box `(min, max)`, or `None` for a mesh without vertices.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// Defects that keep the mesh from being a closed, consistently oriented two-manifold:
    /// every directed edge must occur exactly once and its reverse exactly once. Empty when the
    /// mesh is closed and consistently wound.
    pub fn manifold_defects(&self) -> Vec<String> {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        let mut out = Vec::new();
        for (fi, f) in self.faces.iter().enumerate() {
            if f.len() < 3 {
                out.push(format!("face {fi} has fewer than 3 vertices"));
            }
            if f.iter().any(|&i| i as usize >= self.positions.len()) {
                out.push(format!("face {fi} has an out-of-range vertex index"));
            }
            for k in 0..f.len() {
                let e = (f[k], f[(k + 1) % f.len()]);
                if e.0 == e.1 {
                    out.push(format!("face {fi} repeats vertex {}", e.0));
                }
                *directed.entry(e).or_default() += 1;
            }
        }
        let mut edges: Vec<_> = directed.iter().collect();
        edges.sort();
        for (&(a, b), &n) in edges {
            if n != 1 {
                out.push(format!("directed edge {a}->{b} occurs {n} times"));
            }
            if !directed.contains_key(&(b, a)) {
                out.push(format!("edge {a}->{b} has no opposite edge {b}->{a}"));
            }
        }
        out
    }

    /// True when [`Mesh::manifold_defects`] finds nothing.
    pub fn is_closed_manifold(&self) -> bool {
        !self.faces.is_empty() && self.manifold_defects().is_empty()
    }

    /// True when no vertex lies in front of any face plane by more than `tol` times the mesh
    /// size (a closed outward mesh that passes is convex). Faces without area are skipped.
    pub fn is_convex(&self, tol: f64) -> bool {
        let Some((lo, hi)) = self.bounds() else {
            return false;
        };
        let size = (hi - lo).length().max(f64::MIN_POSITIVE);
        (0..self.faces.len()).all(|fi| {
            let Some(n) = self.face_normal(fi) else {
                return true;
            };
            let Some(&origin) = self.positions.get(self.faces[fi][0] as usize) else {
                return false;
            };
            self.positions
                .iter()
                .all(|&p| n.dot(p - origin) <= tol * size)
        })
    }

    /// Largest distance of a face vertex from the face's best plane (through the vertex
    /// centroid, normal = Newell normal), over all faces. 0 for triangles.
    pub fn max_face_nonplanarity(&self) -> f64 {
        let mut worst = 0.0f64;
        for (fi, f) in self.faces.iter().enumerate() {
            let Some(n) = self.face_normal(fi) else {
                continue;
            };
            let pts: Vec<DVec3> = f
                .iter()
                .filter_map(|&i| self.positions.get(i as usize).copied())
                .collect();
            let c = pts.iter().copied().sum::<DVec3>() / pts.len().max(1) as f64;
            for p in pts {
                worst = worst.max(n.dot(p - c).abs());
            }
        }
        worst
    }
}

impl Mesh {
    /// Irradiance at `x` (surface normal `n`) per unit radiance of this mesh seen as a light,
    /// without any occlusion (not even self-occlusion of a non-convex mesh): Lambert's formula
    /// summed over the faces whose front faces `x`, each clipped to the hemisphere of `n`.
    /// For a single unit-radiance polygon this is pi times its form factor. Used to calibrate
    /// the embedded scenes and as a test oracle.
    pub fn irradiance_factor(&self, x: DVec3, n: DVec3) -> f64 {
        let Some(n) = n.try_normalize() else {
            return 0.0;
        };
        let mut sum = 0.0;
        for (fi, f) in self.faces.iter().enumerate() {
            let area = self.face_area_vector(fi);
            let Some(&p0) = f.first().and_then(|&i| self.positions.get(i as usize)) else {
                continue;
            };
            if area.dot(x - p0) <= 0.0 {
                continue; // back side or edge-on: emits nothing towards x
            }
            let rel: Vec<DVec3> = f
                .iter()
                .filter_map(|&i| self.positions.get(i as usize))
                .map(|&p| p - x)
                .collect();
            let clipped = clip_to_halfspace(&rel, n);
            let m = clipped.len();
            for k in 0..m {
                let (Some(a), Some(b)) = (
                    clipped[k].try_normalize(),
                    clipped[(k + 1) % m].try_normalize(),
                ) else {
                    continue;
                };
                let Some(c) = a.cross(b).try_normalize() else {
                    continue;
                };
                sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(c);
            }
        }
        // A polygon wound CCW seen from x gives edge normals pointing away from it.
        -0.5 * sum
    }
}

/// Sutherland-Hodgman clip of a polygon to the half-space `n . p >= 0`.
fn clip_to_halfspace(poly: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Reverses a face's winding, keeping its first vertex first.
pub(crate) fn reverse_face(f: &mut [u32]) {
    if f.len() > 1 {
        f[1..].reverse();
    }
}

fn finite_or(x: f64, fallback: f64) -> f64 {
    if x.is_finite() { x } else { fallback }
}

fn size(x: f64) -> f64 {
    finite_or(x, 0.0).abs()
}

fn finite_vec(v: DVec3) -> DVec3 {
    DVec3::new(
        finite_or(v.x, 0.0),
        finite_or(v.y, 0.0),
        finite_or(v.z, 0.0),
    )
}

// ---------------------------------------------------------------------------------------------
// Shapes.
// ---------------------------------------------------------------------------------------------

/// One planar quadrilateral (open, single face) with corners `center ± u_half ± v_half`.
/// Its front is the `u_half × v_half` side (CCW seen from there).
pub fn quad(center: DVec3, u_half: DVec3, v_half: DVec3) -> Mesh {
    let (c, u, v) = (finite_vec(center), finite_vec(u_half), finite_vec(v_half));
    Mesh {
        positions: vec![c - u - v, c + u - v, c + u + v, c - u + v],
        faces: vec![vec![0, 1, 2, 3]],
        rounding: 0.0,
    }
}

/// Axis-aligned box with 8 vertices and 6 quads, outward CCW.
pub fn cuboid(center: DVec3, half_extents: DVec3) -> Mesh {
    let c = finite_vec(center);
    let h = finite_vec(half_extents).abs();
    // Vertex index bits: bit k set = +half extent along axis k.
    let positions = (0..8u32)
        .map(|i| {
            let s = |k: u32| if (i >> k) & 1 == 1 { 1.0 } else { -1.0 };
            c + h * DVec3::new(s(0), s(1), s(2))
        })
        .collect();
    let mut faces = Vec::with_capacity(6);
    for k in 0..3u32 {
        // In-plane axes a, b with a x b = axis k (cyclic order X, Y, Z).
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        for side in [0u32, 1] {
            let idx = |sa: u32, sb: u32| (side << k) | (sa << a) | (sb << b);
            let mut f = vec![idx(0, 0), idx(1, 0), idx(1, 1), idx(0, 1)];
            if side == 0 {
                reverse_face(&mut f);
            }
            faces.push(f);
        }
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// Capped cylinder with its axis along +y, centred at `center`: `2 * segments` vertices,
/// `segments` side quads and two `segments`-gon caps. `segments` is clamped to [3, 4096].
pub fn cylinder(center: DVec3, radius: f64, height: f64, segments: u32) -> Mesh {
    truncated_cone(center, radius, radius, height, segments)
}

/// Capped truncated cone with its axis along +y, centred at `center` (the bottom ring at
/// `center.y - height/2` has radius `r_bottom`, the top ring `r_top`). A zero radius collapses
/// that ring to an apex vertex (a cone); if both are zero the mesh is empty.
/// With both radii positive: `2 * segments` vertices.
pub fn truncated_cone(
    center: DVec3,
    r_bottom: f64,
    r_top: f64,
    height: f64,
    segments: u32,
) -> Mesh {
    let c = finite_vec(center);
    let (rb, rt, h) = (size(r_bottom), size(r_top), size(height));
    let n = segments.clamp(3, MAX_SEGMENTS);
    if rb == 0.0 && rt == 0.0 {
        return Mesh::default();
    }
    let mut positions = Vec::new();
    // Returns the indices of a ring (or n copies of the apex index).
    let mut ring = |r: f64, y: f64| -> Vec<u32> {
        if r == 0.0 {
            positions.push(c + DVec3::new(0.0, y, 0.0));
            vec![positions.len() as u32 - 1; n as usize]
        } else {
            (0..n)
                .map(|j| {
                    let t = std::f64::consts::TAU * j as f64 / n as f64;
                    positions.push(c + DVec3::new(r * t.cos(), y, r * t.sin()));
                    positions.len() as u32 - 1
                })
                .collect()
        }
    };
    let bottom = ring(rb, -0.5 * h);
    let top = ring(rt, 0.5 * h);
    let mut faces = Vec::new();
    // Increasing angle runs clockwise seen from +y, so the bottom cap (normal -y) takes the
    // ring in order and the top cap (normal +y) in reverse.
    if rb > 0.0 {
        faces.push(bottom.clone());
    }
    if rt > 0.0 {
        faces.push(top.iter().rev().copied().collect());
    }
    let n = n as usize;
    for j in 0..n {
        let k = (j + 1) % n;
        let mut f = vec![bottom[j], top[j], top[k], bottom[k]];
        f.dedup();
        if f.first() == f.last() {
            f.pop();
        }
        faces.push(f);
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// Regular icosahedron inscribed in the sphere of `radius`: 12 vertices, 20 triangles.
pub fn icosahedron(center: DVec3, radius: f64) -> Mesh {
    let unit = unit_icosahedron();
    unit.scaled(DVec3::splat(size(radius)))
        .translated(finite_vec(center))
}

fn unit_icosahedron() -> Mesh {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions = Vec::with_capacity(12);
    // Cyclic permutations of (0, ±1, ±g).
    for perm in 0..3 {
        for s1 in [-1.0, 1.0] {
            for s2 in [-1.0, 1.0] {
                let v = [0.0, s1, s2 * g];
                let p = DVec3::new(v[perm % 3], v[(perm + 1) % 3], v[(perm + 2) % 3]);
                positions.push(p.normalize());
            }
        }
    }
    // Faces are the triples of mutually adjacent vertices (edge length = the minimum distance).
    let edge = positions[1..]
        .iter()
        .map(|p| p.distance(positions[0]))
        .fold(f64::INFINITY, f64::min);
    let adjacent =
        |a: usize, b: usize| (positions[a].distance(positions[b]) - edge).abs() < 1e-9 * edge;
    let mut faces = Vec::with_capacity(20);
    for a in 0..12 {
        for b in a + 1..12 {
            for c in b + 1..12 {
                if adjacent(a, b) && adjacent(b, c) && adjacent(a, c) {
                    faces.push(outward(&positions, [a as u32, b as u32, c as u32]));
                }
            }
        }
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// Orders a triangle of a origin-centred convex solid so that it winds CCW seen from outside.
fn outward(positions: &[DVec3], [a, b, c]: [u32; 3]) -> Vec<u32> {
    let (pa, pb, pc) = (
        positions[a as usize],
        positions[b as usize],
        positions[c as usize],
    );
    if (pb - pa).cross(pc - pa).dot(pa + pb + pc) >= 0.0 {
        vec![a, b, c]
    } else {
        vec![a, c, b]
    }
}

/// Icosphere: the icosahedron with each triangle split into four `subdivisions` times, new
/// vertices pushed onto the sphere. Vertex counts 12, 42, 162, 642, ... (10 * 4^s + 2).
/// `subdivisions` is capped at `MAX_ICOSPHERE_SUBDIVISIONS`.
pub fn icosphere(center: DVec3, radius: f64, subdivisions: u32) -> Mesh {
    let mut m = unit_icosahedron();
    for _ in 0..subdivisions.min(MAX_ICOSPHERE_SUBDIVISIONS) {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut faces = Vec::with_capacity(m.faces.len() * 4);
        let positions = &mut m.positions;
        let mut midpoint = |a: u32, b: u32| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        for f in &m.faces {
            let (a, b, c) = (f[0], f[1], f[2]);
            let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
            faces.extend([
                vec![a, ab, ca],
                vec![b, bc, ab],
                vec![c, ca, bc],
                vec![ab, bc, ca],
            ]);
        }
        m.faces = faces;
    }
    m.scaled(DVec3::splat(size(radius)))
        .translated(finite_vec(center))
}

/// The 16-vertex "icosphere" used for paper 000's Fig. 4 (which reports an icosphere with 16
/// vertices, a count no subdivision level gives): the icosahedron with four pairwise
/// vertex-disjoint faces each replaced by three triangles meeting at a new vertex, the face
/// centre pushed out onto the sphere. 16 vertices, 28 triangles, convex, all on the sphere.
pub fn capped_icosahedron(center: DVec3, radius: f64) -> Mesh {
    let mut m = unit_icosahedron();
    let chosen = disjoint_faces(&m.faces, 4);
    let mut faces = Vec::with_capacity(28);
    for (fi, f) in m.faces.iter().enumerate() {
        if chosen.contains(&fi) {
            let apex = (m.positions[f[0] as usize]
                + m.positions[f[1] as usize]
                + m.positions[f[2] as usize])
                .normalize();
            m.positions.push(apex);
            let v = m.positions.len() as u32 - 1;
            for k in 0..3 {
                faces.push(vec![f[k], f[(k + 1) % 3], v]);
            }
        } else {
            faces.push(f.clone());
        }
    }
    m.faces = faces;
    m.scaled(DVec3::splat(size(radius)))
        .translated(finite_vec(center))
}

/// First (lexicographic) set of `k` pairwise vertex-disjoint faces, by backtracking.
fn disjoint_faces(faces: &[Vec<u32>], k: usize) -> Vec<usize> {
    fn search(faces: &[Vec<u32>], start: usize, k: usize, chosen: &mut Vec<usize>) -> bool {
        if chosen.len() == k {
            return true;
        }
        for fi in start..faces.len() {
            let free = chosen
                .iter()
                .all(|&c| faces[c].iter().all(|v| !faces[fi].contains(v)));
            if free {
                chosen.push(fi);
                if search(faces, fi + 1, k, chosen) {
                    return true;
                }
                chosen.pop();
            }
        }
        false
    }
    let mut chosen = Vec::new();
    search(faces, 0, k, &mut chosen);
    chosen
}

/// Latitude-longitude ellipsoid with semi-axes `radii` (x, y, z), poles on the y axis:
/// `slices` meridians (>= 3), `stacks` latitude bands (>= 2); vertex count
/// `slices * (stacks - 1) + 2`. Triangles at the poles, planar quads elsewhere (an ellipsoid is
/// an affine image of the sphere, so the trapezoids stay planar); convex.
pub fn uv_ellipsoid(center: DVec3, radii: DVec3, slices: u32, stacks: u32) -> Mesh {
    let c = finite_vec(center);
    let r = finite_vec(radii).abs();
    let (ns, nt) = (
        slices.clamp(3, MAX_SEGMENTS) as usize,
        stacks.clamp(2, MAX_SEGMENTS) as usize,
    );
    let mut positions = Vec::with_capacity(ns * (nt - 1) + 2);
    positions.push(c + DVec3::new(0.0, r.y, 0.0)); // north pole, index 0
    for k in 1..nt {
        let phi = std::f64::consts::PI * k as f64 / nt as f64;
        for j in 0..ns {
            let theta = std::f64::consts::TAU * j as f64 / ns as f64;
            let d = DVec3::new(phi.sin() * theta.cos(), phi.cos(), phi.sin() * theta.sin());
            positions.push(c + r * d);
        }
    }
    positions.push(c - DVec3::new(0.0, r.y, 0.0)); // south pole
    let south = (positions.len() - 1) as u32;
    let at = |k: usize, j: usize| (1 + (k - 1) * ns + j % ns) as u32;
    let mut faces = Vec::with_capacity(ns * nt);
    for j in 0..ns {
        faces.push(vec![0, at(1, j + 1), at(1, j)]);
    }
    for k in 1..nt - 1 {
        for j in 0..ns {
            faces.push(vec![at(k + 1, j), at(k, j), at(k, j + 1), at(k + 1, j + 1)]);
        }
    }
    for j in 0..ns {
        faces.push(vec![south, at(nt - 1, j), at(nt - 1, j + 1)]);
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// A prism: the simple polygon `outline` (CCW seen from +z, in the xy plane) extruded from
/// z = -depth/2 to +depth/2. `pieces` is a decomposition of the outline into convex polygons
/// (indices into `outline`, each CCW) used for the two caps, so every face is convex.
/// Pieces with out-of-range indices are skipped.
pub fn prism(outline: &[DVec2], pieces: &[Vec<u32>], depth: f64) -> Mesh {
    let n = outline.len() as u32;
    let hz = 0.5 * size(depth);
    let mut positions: Vec<DVec3> = outline.iter().map(|p| p.extend(-hz)).collect();
    positions.extend(outline.iter().map(|p| p.extend(hz)));
    let mut faces = Vec::new();
    for piece in pieces
        .iter()
        .filter(|p| p.len() >= 3 && p.iter().all(|&i| i < n))
    {
        faces.push(piece.iter().map(|&i| i + n).collect());
        let mut bottom = piece.clone();
        reverse_face(&mut bottom);
        faces.push(bottom);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, j + n, i + n]);
    }
    Mesh {
        positions,
        faces,
        rounding: 0.0,
    }
}

/// Non-convex L-shaped prism (closed, outward CCW, 12 vertices, all faces convex): the L lies
/// in the xy plane (a `width`-long foot along +x, a `height`-tall upright along +y, both
/// `thickness` thick) and is extruded `depth` along z; `center` is its bounding-box centre.
/// `thickness` is clamped below `min(width, height)`.
pub fn l_shape(center: DVec3, width: f64, height: f64, thickness: f64, depth: f64) -> Mesh {
    let (w, h) = (size(width), size(height));
    let t = size(thickness).min(0.999 * w.min(h));
    let outline = [
        DVec2::new(0.0, 0.0),
        DVec2::new(w, 0.0),
        DVec2::new(w, t),
        DVec2::new(t, t),
        DVec2::new(t, h),
        DVec2::new(0.0, h),
    ];
    let pieces = [vec![0, 1, 2, 3], vec![0, 3, 4, 5]];
    prism(&outline, &pieces, depth).translated(finite_vec(center) - DVec3::new(w, h, 0.0) / 2.0)
}

/// Non-convex U-shaped prism (closed, outward CCW, 16 vertices, all faces convex): the U lies
/// in the xy plane, opening towards +y (`width` wide, `height` tall, walls `thickness` thick),
/// extruded `depth` along z; `center` is its bounding-box centre. `thickness` is clamped below
/// `min(width / 2, height)`. Rotate it (`Mesh::transformed`) to lay it flat.
pub fn u_shape(center: DVec3, width: f64, height: f64, thickness: f64, depth: f64) -> Mesh {
    let (w, h) = (size(width), size(height));
    let t = size(thickness).min(0.999 * (0.5 * w).min(h));
    let outline = [
        DVec2::new(0.0, 0.0),
        DVec2::new(w, 0.0),
        DVec2::new(w, h),
        DVec2::new(w - t, h),
        DVec2::new(w - t, t),
        DVec2::new(t, t),
        DVec2::new(t, h),
        DVec2::new(0.0, h),
    ];
    let pieces = [vec![0, 5, 6, 7], vec![0, 1, 4, 5], vec![1, 2, 3, 4]];
    prism(&outline, &pieces, depth).translated(finite_vec(center) - DVec3::new(w, h, 0.0) / 2.0)
}

/// Non-convex T-shaped prism (closed, outward CCW, 20 vertices, all faces convex): the T lies
/// in the xy plane (a `width`-wide bar at the top, a stem down the middle, both `thickness`
/// thick, `height` tall in all), extruded `depth` along z; `center` is its bounding-box centre.
/// The top edge carries the stem's two corners too, so that the bar splits into three
/// rectangles that share whole edges. `thickness` is clamped below `min(width, height)`.
pub fn t_shape(center: DVec3, width: f64, height: f64, thickness: f64, depth: f64) -> Mesh {
    let (w, h) = (size(width), size(height));
    let t = size(thickness).min(0.999 * w.min(h));
    let a = 0.5 * (w - t);
    let outline = [
        DVec2::new(a, 0.0),
        DVec2::new(a + t, 0.0),
        DVec2::new(a + t, h - t),
        DVec2::new(w, h - t),
        DVec2::new(w, h),
        DVec2::new(a + t, h),
        DVec2::new(a, h),
        DVec2::new(0.0, h),
        DVec2::new(0.0, h - t),
        DVec2::new(a, h - t),
    ];
    let pieces = [
        vec![0, 1, 2, 9],
        vec![2, 3, 4, 5],
        vec![9, 2, 5, 6],
        vec![8, 9, 6, 7],
    ];
    prism(&outline, &pieces, depth).translated(finite_vec(center) - DVec3::new(w, h, 0.0) / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_closed_convex(name: &str, m: &Mesh, convex: bool) {
        let defects = m.manifold_defects();
        assert!(defects.is_empty(), "{name}: {defects:?}");
        assert!(
            m.signed_volume() > 0.0,
            "{name}: volume {}",
            m.signed_volume()
        );
        assert!(
            m.max_face_nonplanarity() < 1e-12,
            "{name}: non-planar {}",
            m.max_face_nonplanarity()
        );
        for fi in 0..m.faces.len() {
            assert!(
                m.face_area_vector(fi).length() > 1e-9,
                "{name}: face {fi} degenerate"
            );
            assert!(face_is_convex(m, fi), "{name}: face {fi} not convex");
        }
        assert_eq!(m.is_convex(1e-12), convex, "{name}: convexity");
    }

    fn face_is_convex(m: &Mesh, fi: usize) -> bool {
        let n = m.face_area_vector(fi);
        let f = &m.faces[fi];
        let p = |k: usize| m.positions[f[k % f.len()] as usize];
        (0..f.len()).all(|k| (p(k + 1) - p(k)).cross(p(k + 2) - p(k + 1)).dot(n) > -1e-12)
    }

    #[test]
    fn closed_shapes_are_outward_manifolds() {
        let c = DVec3::new(0.3, -1.0, 2.0);
        let shapes = [
            ("cuboid", cuboid(c, DVec3::new(0.5, 1.0, 2.0)), true),
            ("cylinder", cylinder(c, 0.5, 2.0, 10), true),
            ("cone", truncated_cone(c, 0.6, 0.3, 1.0, 10), true),
            ("apex cone", truncated_cone(c, 0.6, 0.0, 1.0, 7), true),
            ("inverted apex", truncated_cone(c, 0.0, 0.6, 1.0, 5), true),
            ("icosahedron", icosahedron(c, 1.5), true),
            ("icosphere1", icosphere(c, 1.5, 1), true),
            ("icosphere2", icosphere(c, 1.5, 2), true),
            ("capped icosahedron", capped_icosahedron(c, 1.5), true),
            (
                "ellipsoid",
                uv_ellipsoid(c, DVec3::new(1.0, 0.5, 0.7), 19, 9),
                true,
            ),
            ("ellipsoid min", uv_ellipsoid(c, DVec3::ONE, 0, 0), true),
            ("l_shape", l_shape(c, 1.0, 1.5, 0.3, 0.5), false),
            ("u_shape", u_shape(c, 1.5, 1.0, 0.3, 0.2), false),
            ("t_shape", t_shape(c, 1.2, 1.5, 0.3, 0.2), false),
        ];
        for (name, m, convex) in &shapes {
            check_closed_convex(name, m, *convex);
        }
    }

    #[test]
    fn vertex_counts() {
        assert_eq!(quad(DVec3::ZERO, DVec3::X, DVec3::Z).vertex_count(), 4);
        assert_eq!(cuboid(DVec3::ZERO, DVec3::ONE).vertex_count(), 8);
        assert_eq!(cylinder(DVec3::ZERO, 1.0, 1.0, 10).vertex_count(), 20);
        assert_eq!(
            truncated_cone(DVec3::ZERO, 1.0, 0.5, 1.0, 10).vertex_count(),
            20
        );
        assert_eq!(icosahedron(DVec3::ZERO, 1.0).vertex_count(), 12);
        assert_eq!(icosahedron(DVec3::ZERO, 1.0).faces.len(), 20);
        assert_eq!(icosphere(DVec3::ZERO, 1.0, 1).vertex_count(), 42);
        assert_eq!(icosphere(DVec3::ZERO, 1.0, 2).vertex_count(), 162);
        let capped = capped_icosahedron(DVec3::ZERO, 1.0);
        assert_eq!((capped.vertex_count(), capped.faces.len()), (16, 28));
        assert_eq!(
            uv_ellipsoid(DVec3::ZERO, DVec3::ONE, 19, 9).vertex_count(),
            154
        );
        assert_eq!(l_shape(DVec3::ZERO, 1.0, 1.0, 0.2, 1.0).vertex_count(), 12);
        assert_eq!(u_shape(DVec3::ZERO, 1.0, 1.0, 0.2, 1.0).vertex_count(), 16);
        assert_eq!(t_shape(DVec3::ZERO, 1.0, 1.0, 0.2, 1.0).vertex_count(), 20);
    }

    #[test]
    fn quad_front_is_u_cross_v() {
        let q = quad(DVec3::new(1.0, 2.0, 3.0), DVec3::X * 0.5, DVec3::Z * 0.25);
        let n = q.face_normal(0).unwrap();
        assert!((n - DVec3::X.cross(DVec3::Z).normalize()).length() < 1e-15);
        assert!((q.face_area_vector(0).length() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn shapes_have_the_requested_size() {
        let (lo, hi) = cylinder(DVec3::new(1.0, 2.0, 3.0), 0.5, 2.0, 8)
            .bounds()
            .unwrap();
        assert!((lo.y - 1.0).abs() < 1e-15 && (hi.y - 3.0).abs() < 1e-15);
        assert!((hi.x - 1.5).abs() < 1e-15);
        let (lo, hi) = l_shape(DVec3::ONE, 2.0, 1.0, 0.2, 0.4).bounds().unwrap();
        assert!((lo - DVec3::new(0.0, 0.5, 0.8)).length() < 1e-15);
        assert!((hi - DVec3::new(2.0, 1.5, 1.2)).length() < 1e-15);
        let v = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)).signed_volume();
        assert!((v - 48.0).abs() < 1e-12);
        let s = icosphere(DVec3::ZERO, 1.0, 3);
        let vol = s.signed_volume();
        assert!(vol < 4.0 / 3.0 * std::f64::consts::PI && vol > 4.0);
        for p in &s.positions {
            assert!((p.length() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn transforms_keep_outward_winding() {
        let m = cuboid(DVec3::ZERO, DVec3::ONE);
        for s in [
            DVec3::new(-1.0, 1.0, 1.0),
            DVec3::new(-1.0, -2.0, 1.0),
            DVec3::new(2.0, 3.0, -0.5),
        ] {
            let t = m.scaled(s);
            assert!(t.signed_volume() > 0.0, "{s}");
            assert!(t.manifold_defects().is_empty());
        }
        let r = m.transformed(&DAffine3::from_rotation_x(0.7));
        assert!((r.signed_volume() - 8.0).abs() < 1e-12);
        let t = m.translated(DVec3::new(5.0, 0.0, 0.0));
        assert!((t.bounds().unwrap().0.x - 4.0).abs() < 1e-15);
    }

    #[test]
    fn irradiance_factor_matches_known_cases() {
        // Small square (side 0.02) facing down, 1 above: E/L ~ A / d^2.
        let q = quad(DVec3::Y, DVec3::X * 0.01, DVec3::Z * 0.01);
        let e = q.irradiance_factor(DVec3::ZERO, DVec3::Y);
        assert!((e / 4e-4 - 1.0).abs() < 1e-3, "{e}");
        // Seen from behind: nothing.
        assert_eq!(q.irradiance_factor(DVec3::Y * 2.0, -DVec3::Y), 0.0);
        // Huge quad: the whole hemisphere, E/L -> pi.
        let big = quad(DVec3::Y, DVec3::X * 1e6, DVec3::Z * 1e6);
        let e = big.irradiance_factor(DVec3::ZERO, DVec3::Y);
        assert!((e - std::f64::consts::PI).abs() < 1e-5, "{e}");
        // Half of it below the horizon of a tilted receiver: clipped, pi/2 for n = +x.
        let e = big.irradiance_factor(DVec3::ZERO, DVec3::X);
        assert!((e - std::f64::consts::FRAC_PI_2).abs() < 1e-5, "{e}");
        // Closed convex light seen from outside: same as its silhouette. A far cube
        // (side 0.02, centre 10 along +y) gives ~ bottom area / 9.99^2.
        let c = cuboid(DVec3::Y * 10.0, DVec3::splat(0.01));
        let e = c.irradiance_factor(DVec3::ZERO, DVec3::Y);
        assert!((e / (4e-4 / (9.99f64 * 9.99)) - 1.0).abs() < 1e-5, "{e}");
    }

    #[test]
    fn bad_parameters_do_not_panic() {
        for m in [
            cylinder(DVec3::NAN, f64::NAN, f64::INFINITY, 0),
            truncated_cone(DVec3::ZERO, 0.0, 0.0, 1.0, 3),
            truncated_cone(DVec3::ZERO, -1.0, -2.0, -1.0, u32::MAX),
            icosphere(DVec3::ZERO, -1.0, u32::MAX),
            uv_ellipsoid(DVec3::ZERO, DVec3::splat(f64::NAN), 1, 1),
            l_shape(DVec3::ZERO, 0.0, 0.0, 5.0, 0.0),
            u_shape(DVec3::ZERO, -1.0, 1.0, 5.0, 1.0),
            prism(&[DVec2::ZERO], &[vec![0, 7, 9]], 1.0),
            quad(DVec3::INFINITY, DVec3::NAN, DVec3::ZERO),
        ] {
            for f in &m.faces {
                assert!(f.iter().all(|&i| (i as usize) < m.positions.len()));
            }
            assert!(m.positions.iter().all(|p| p.is_finite()));
        }
        let empty = Mesh::default();
        assert_eq!(empty.bounds(), None);
        assert_eq!(empty.signed_volume(), 0.0);
        assert!(!empty.is_closed_manifold());
    }
}
