//! Polyhedra with edge adjacency, the data every silhouette computation starts from.

use glam::DVec3;
use std::collections::HashMap;

/// Marker for the missing second face of a boundary edge.
pub const NO_FACE: u32 = u32::MAX;

/// A plane `n · p = d` with unit normal `n` (the front side is where `n · p > d`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    pub n: DVec3,
    pub d: f64,
}

impl Plane {
    /// Signed distance of `p` to the plane (positive on the front side).
    #[inline]
    pub fn eval(&self, p: DVec3) -> f64 {
        self.n.dot(p) - self.d
    }
}

/// An edge between vertices `v[0]` and `v[1]`. It runs `v[0] → v[1]` in the counter-clockwise
/// winding of `faces[0]` (and `v[1] → v[0]` in that of `faces[1]`, if the mesh is oriented).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Edge {
    pub v: [u32; 2],
    pub faces: [u32; 2],
}

impl Edge {
    #[inline]
    pub fn is_boundary(&self) -> bool {
        self.faces[1] == NO_FACE
    }
}

/// What the mesh is, topologically and geometrically; decides which silhouette path it takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct MeshDiagnostics {
    /// Edges used by one face only.
    pub boundary_edges: u32,
    /// Edges used by more than two faces, or by two faces with the same direction.
    pub nonmanifold_edges: u32,
    /// Faces whose vertices deviate from the face plane by more than the tolerance.
    pub nonplanar_faces: u32,
    /// Every edge has exactly two faces, consistently oriented.
    pub closed_manifold: bool,
    /// Closed, manifold, planar faces and every vertex on the inner side of every face plane.
    pub convex: bool,
    /// All faces lie in one plane with one orientation (a flat light such as a quad).
    pub planar: bool,
    /// Vertices welded because they had identical coordinates.
    pub welded_vertices: u32,
}

/// Counts of [`Polyhedron::feature_counts`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FeatureCounts {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
}

/// A polygon mesh prepared for silhouette extraction: welded vertices, face planes (Newell
/// normals), the edge list with face adjacency, a bounding sphere and diagnostics. The
/// acceleration structures built over it are kept apart ([`crate::geometry::MeshIndex`], together in
/// [`crate::geometry::IndexedPolyhedron`]).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Polyhedron {
    pub vertices: Vec<DVec3>,
    /// Face vertex indices, all faces concatenated; face `f` is `face_indices[face_starts[f]..face_starts[f+1]]`.
    pub face_indices: Vec<u32>,
    pub face_starts: Vec<u32>,
    pub face_planes: Vec<Plane>,
    pub edges: Vec<Edge>,
    pub center: DVec3,
    pub radius: f64,
    pub diagnostics: MeshDiagnostics,
}

/// The plane of a face loop: Newell's normal (robust for a possibly non-planar polygon)
/// through the centroid; `None` for a face without area.
fn face_plane(vertices: &[DVec3], loop_: &[u32]) -> Option<Plane> {
    let points = loop_.iter().map(|&i| vertices[i as usize]);
    let centroid = points.clone().sum::<DVec3>() / loop_.len() as f64;
    let n = crate::math::polygon_area_vector(points).try_normalize()?;
    Some(Plane {
        n,
        d: n.dot(centroid),
    })
}

/// (convex, planar) of a mesh: `may_be_convex` (closed manifold with planar faces) and every
/// vertex a face uses on the inner side of every face plane; all faces in one plane with one
/// orientation.
fn shape_of(
    vertices: &[DVec3],
    face_indices: &[u32],
    face_planes: &[Plane],
    may_be_convex: bool,
    tol: f64,
) -> (bool, bool) {
    // Only vertices that faces use count for the geometric tests.
    let mut referenced = vec![false; vertices.len()];
    face_indices
        .iter()
        .for_each(|&i| referenced[i as usize] = true);
    let used = || {
        vertices
            .iter()
            .zip(&referenced)
            .filter(|(_, r)| **r)
            .map(|(v, _)| *v)
    };
    let convex = may_be_convex
        && face_planes
            .iter()
            .all(|pl| used().all(|v| pl.eval(v) <= tol));
    let planar = !face_planes.is_empty()
        && face_planes.iter().all(|pl| {
            pl.n.dot(face_planes[0].n) > 1.0 - 1e-12 && used().all(|v| pl.eval(v).abs() <= tol)
        });
    (convex, planar)
}

impl Polyhedron {
    /// Builds the adjacency of a polygon mesh. Faces with fewer than three distinct vertices or
    /// zero area are skipped (the scene loader has already reported them).
    pub fn new(positions: &[DVec3], faces: &[Vec<u32>]) -> Polyhedron {
        // Weld bit-identical positions so that meshes with split vertices still close up.
        let mut weld: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
        let mut remap = Vec::with_capacity(positions.len());
        let mut vertices = Vec::with_capacity(positions.len());
        for p in positions {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            let id = *weld.entry(key).or_insert_with(|| {
                vertices.push(*p);
                (vertices.len() - 1) as u32
            });
            remap.push(id);
        }
        let welded_vertices = (positions.len() - vertices.len()) as u32;

        let (lo, hi) = vertices
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let center = if vertices.is_empty() {
            DVec3::ZERO
        } else {
            0.5 * (lo + hi)
        };
        let radius = vertices
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0, f64::max);
        let scale = radius.max(f64::MIN_POSITIVE);
        let tol = 1e-9 * scale;

        let mut face_indices = Vec::new();
        let mut face_starts = vec![0u32];
        let mut face_planes = Vec::new();
        let mut nonplanar_faces = 0;
        let mut loop_buf: Vec<u32> = Vec::new();
        for face in faces {
            loop_buf.clear();
            for &i in face {
                let Some(&v) = remap.get(i as usize) else {
                    continue;
                };
                if loop_buf.last() != Some(&v) {
                    loop_buf.push(v);
                }
            }
            while loop_buf.len() > 1 && loop_buf.first() == loop_buf.last() {
                loop_buf.pop();
            }
            if loop_buf.len() < 3 {
                continue;
            }
            // Zero-area (degenerate) faces have no normal and are skipped.
            let Some(plane) = face_plane(&vertices, &loop_buf) else {
                continue;
            };
            if loop_buf
                .iter()
                .any(|&v| plane.eval(vertices[v as usize]).abs() > tol)
            {
                nonplanar_faces += 1;
            }
            face_indices.extend_from_slice(&loop_buf);
            face_starts.push(face_indices.len() as u32);
            face_planes.push(plane);
        }

        // Edge adjacency keyed by the unordered vertex pair.
        let mut edge_of: HashMap<(u32, u32), u32> = HashMap::new();
        let mut edges: Vec<Edge> = Vec::new();
        let mut nonmanifold = 0u32;
        let face_count = face_planes.len();
        for f in 0..face_count {
            let idx = &face_indices[face_starts[f] as usize..face_starts[f + 1] as usize];
            for k in 0..idx.len() {
                let (a, b) = (idx[k], idx[(k + 1) % idx.len()]);
                let key = (a.min(b), a.max(b));
                match edge_of.get(&key) {
                    None => {
                        edge_of.insert(key, edges.len() as u32);
                        edges.push(Edge {
                            v: [a, b],
                            faces: [f as u32, NO_FACE],
                        });
                    }
                    Some(&e) => {
                        let edge = &mut edges[e as usize];
                        if edge.faces[1] == NO_FACE && edge.v == [b, a] {
                            edge.faces[1] = f as u32;
                        } else {
                            // A third face, or a second face with the same direction: the mesh is
                            // not an oriented manifold here. Keep the face as its own boundary edge
                            // so that per-face methods still see it.
                            nonmanifold += 1;
                            edges.push(Edge {
                                v: [a, b],
                                faces: [f as u32, NO_FACE],
                            });
                        }
                    }
                }
            }
        }
        let boundary_edges = edges.iter().filter(|e| e.is_boundary()).count() as u32;
        let closed_manifold = face_count > 0 && boundary_edges == 0 && nonmanifold == 0;
        let (convex, planar) = shape_of(
            &vertices,
            &face_indices,
            &face_planes,
            closed_manifold && nonplanar_faces == 0,
            tol,
        );
        let diagnostics = MeshDiagnostics {
            boundary_edges,
            nonmanifold_edges: nonmanifold,
            nonplanar_faces,
            closed_manifold,
            convex,
            planar,
            welded_vertices,
        };
        Polyhedron {
            vertices,
            face_indices,
            face_starts,
            face_planes,
            edges,
            center,
            radius,
            diagnostics,
        }
    }

    /// This mesh with its vertices moved to `positions` (the positions it was built from,
    /// moved rigidly or by another affine map of positive determinant): the topology (edges,
    /// faces) is kept, the geometry (face planes, bounds, diagnostics) computed again exactly
    /// as [`Polyhedron::new`] computes it. `None` when the positions do not weld to as many vertices, a face loses its area or
    /// the diagnostics change: build the mesh anew then.
    pub(crate) fn moved(&self, positions: &[DVec3]) -> Option<Polyhedron> {
        let mut weld: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
        let mut vertices = Vec::with_capacity(self.vertices.len());
        for p in positions {
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            weld.entry(key).or_insert_with(|| {
                vertices.push(*p);
                (vertices.len() - 1) as u32
            });
        }
        // Welding must leave the indices as they were: only meshes without welded vertices
        // are moved (the others are built anew).
        if self.diagnostics.welded_vertices != 0
            || vertices.len() != self.vertices.len()
            || vertices.len() != positions.len()
        {
            return None;
        }
        let (lo, hi) = vertices
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let center = 0.5 * (lo + hi);
        let radius = vertices
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0, f64::max);
        let tol = 1e-9 * radius.max(f64::MIN_POSITIVE);
        let mut face_planes = Vec::with_capacity(self.face_planes.len());
        let mut nonplanar_faces = 0;
        for f in 0..self.face_count() {
            let idx = self.face(f);
            let plane = face_plane(&vertices, idx)?;
            if idx
                .iter()
                .any(|&v| plane.eval(vertices[v as usize]).abs() > tol)
            {
                nonplanar_faces += 1;
            }
            face_planes.push(plane);
        }
        let d = self.diagnostics;
        let (convex, planar) = shape_of(
            &vertices,
            &self.face_indices,
            &face_planes,
            d.closed_manifold && nonplanar_faces == 0,
            tol,
        );
        let diagnostics = MeshDiagnostics {
            nonplanar_faces,
            convex,
            planar,
            ..d
        };
        if diagnostics != d {
            return None;
        }
        Some(Polyhedron {
            vertices,
            face_indices: self.face_indices.clone(),
            face_starts: self.face_starts.clone(),
            face_planes,
            edges: self.edges.clone(),
            center,
            radius,
            diagnostics,
        })
    }

    #[inline]
    pub fn face_count(&self) -> usize {
        self.face_planes.len()
    }

    /// Vertex indices of face `f`, counter-clockwise seen from its front.
    #[inline]
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_indices[self.face_starts[f] as usize..self.face_starts[f + 1] as usize]
    }

    /// Whether the silhouette of this mesh from any outside point is the boundary of its
    /// front-facing faces and bounds their projection exactly once: convex closed meshes and
    /// flat (single-plane) meshes. Other meshes take the per-face path.
    pub(crate) fn has_simple_silhouette(&self) -> bool {
        self.diagnostics.convex || self.diagnostics.planar
    }

    /// Vertices, edges and faces counted as a modeller would (001 Table 7.1): adjacent faces in
    /// one plane with one orientation are one face (a non-convex face or one with holes, stored
    /// as convex pieces), an edge between two such pieces is no edge, and a vertex only inside
    /// such a face is no vertex.
    pub fn feature_counts(&self) -> FeatureCounts {
        let nf = self.face_count();
        let mut parent: Vec<usize> = (0..nf).collect();
        fn find(parent: &mut [usize], mut i: usize) -> usize {
            // Bound: links only ever join two roots, so the parents form a forest: `nf` steps
            // at most.
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        let tol = 1e-9 * self.radius.max(f64::MIN_POSITIVE);
        let coplanar =
            |a: &Plane, b: &Plane| a.n.dot(b.n) > 1.0 - 1e-12 && (a.d - b.d).abs() <= tol;
        for e in &self.edges {
            if e.is_boundary() {
                continue;
            }
            let (f0, f1) = (e.faces[0] as usize, e.faces[1] as usize);
            if coplanar(&self.face_planes[f0], &self.face_planes[f1]) {
                let (r0, r1) = (find(&mut parent, f0), find(&mut parent, f1));
                parent[r0] = r1;
            }
        }
        let mut used = vec![false; self.vertices.len()];
        let mut edges = 0;
        for e in &self.edges {
            let feature = e.is_boundary()
                || find(&mut parent, e.faces[0] as usize) != find(&mut parent, e.faces[1] as usize);
            if feature {
                edges += 1;
                used[e.v[0] as usize] = true;
                used[e.v[1] as usize] = true;
            }
        }
        let faces = (0..nf).filter(|&f| find(&mut parent, f) == f).count();
        FeatureCounts {
            vertices: used.iter().filter(|&&u| u).count(),
            edges,
            faces,
        }
    }

    /// Every face as a fan of triangles from its first vertex, with the face index; triangles
    /// of zero area (`accel::is_degenerate`) are left out (no ray hits them).
    pub fn fan_triangles(&self) -> impl Iterator<Item = (usize, [DVec3; 3])> + '_ {
        (0..self.face_count()).flat_map(move |f| {
            let idx = self.face(f);
            let v0 = self.vertices[idx[0] as usize];
            (1..idx.len().saturating_sub(1)).filter_map(move |k| {
                let (v1, v2) = (
                    self.vertices[idx[k] as usize],
                    self.vertices[idx[k + 1] as usize],
                );
                (!crate::geometry::mesh::triangle::is_degenerate(v0, v1, v2))
                    .then_some((f, [v0, v1, v2]))
            })
        })
    }

    /// Volume enclosed by a closed mesh (positive when faces are counter-clockwise outward).
    pub fn signed_volume(&self) -> f64 {
        let mut v = 0.0;
        for f in 0..self.face_count() {
            let idx = self.face(f);
            let a = self.vertices[idx[0] as usize];
            for k in 1..idx.len() - 1 {
                let b = self.vertices[idx[k] as usize];
                let c = self.vertices[idx[k + 1] as usize];
                v += a.dot(b.cross(c)) / 6.0;
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let m = crate::scene::shapes::cuboid(DVec3::ZERO, DVec3::ONE);
        (m.positions, m.faces)
    }

    #[test]
    fn cube_is_convex_closed_and_outward() {
        let (p, f) = cube();
        let poly = Polyhedron::new(&p, &f);
        assert_eq!(poly.edges.len(), 12);
        assert!(
            poly.diagnostics.closed_manifold && poly.diagnostics.convex && !poly.diagnostics.planar
        );
        assert!((poly.signed_volume() - 8.0).abs() < 1e-12);
        for (f, pl) in poly.face_planes.iter().enumerate() {
            assert!(pl.eval(DVec3::ZERO) < 0.0, "face {f} normal points inward");
        }
    }

    #[test]
    fn open_and_flat_meshes_are_diagnosed() {
        let (p, mut f) = cube();
        f.pop();
        let poly = Polyhedron::new(&p, &f);
        assert_eq!(poly.diagnostics.boundary_edges, 4);
        assert!(!poly.diagnostics.closed_manifold && !poly.diagnostics.convex);
        let quad = Polyhedron::new(&p, &[vec![0, 2, 3, 1]]);
        assert!(quad.diagnostics.planar && quad.has_simple_silhouette());
    }

    #[test]
    fn split_vertices_are_welded() {
        let (p, f) = cube();
        // Give every face its own copy of its vertices.
        let mut pos = Vec::new();
        let mut faces = Vec::new();
        for face in &f {
            let start = pos.len() as u32;
            pos.extend(face.iter().map(|&i| p[i as usize]));
            faces.push((0..face.len() as u32).map(|k| start + k).collect());
        }
        let poly = Polyhedron::new(&pos, &faces);
        assert!(poly.diagnostics.convex);
        assert_eq!(poly.diagnostics.welded_vertices, 24 - 8);
    }

    #[test]
    fn non_convex_and_inconsistent_meshes_are_not_convex() {
        let (mut p, f) = cube();
        p[7] = DVec3::splat(0.2); // dent one corner inward
        assert!(!Polyhedron::new(&p, &f).diagnostics.convex);
        let (p, mut f) = cube();
        f[0].reverse(); // flipped face
        let poly = Polyhedron::new(&p, &f);
        assert!(poly.diagnostics.nonmanifold_edges > 0 && !poly.diagnostics.convex);
    }
}
