//! The forms a mesh takes besides its own faces: the triangles rays see when a face is bent
//! ([`FanMesh`]), and the convex hull that stands in for a mesh convex up to the rounding of its
//! coordinates ([`StandIn`]).

use crate::geometry::{IndexedPolyhedron, convex_stand_in, flat_up_to_rounding, solid_angle_bound};
use glam::DVec3;
use std::sync::Arc;

/// A mesh's faces as the triangles every ray sees (each face fanned from its first vertex,
/// `Mesh::triangles`, as the BVH and the ray-cast reference take them). The face-by-face paths
/// subtract and integrate these when some face of the mesh is bent, even only by the rounding
/// of its digits: seen nearly edge-on, a bent face's image folds into a bow tie, which the set
/// difference cannot take; a triangle's never does.
#[derive(Clone, Debug)]
pub struct FanMesh {
    pub poly: Arc<IndexedPolyhedron>,
    /// The face of the mesh each triangle comes from.
    pub face_of: Vec<u32>,
}

impl FanMesh {
    /// The fan of `mesh`; `None` when every face of it is planar to the polyhedron's tolerance
    /// (1e-9 of its bounding radius, as `Polyhedron::new` judges; the faces are then their own
    /// pieces).
    pub(crate) fn of(mesh: &crate::scene::Mesh) -> Option<FanMesh> {
        let p = |i: u32| mesh.positions[i as usize];
        let (_, radius) = mesh.bounding_sphere();
        let tol = 1e-9 * radius.max(f64::MIN_POSITIVE);
        let bent = mesh.faces.iter().any(|f| {
            f.len() > 3 && {
                let pts: Vec<DVec3> = f.iter().map(|&i| p(i)).collect();
                crate::scene::precision::plane_deviation(&pts) > tol
            }
        });
        if !bent {
            return None;
        }
        let mut faces = Vec::new();
        let mut face_of = Vec::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            for k in 1..face.len().saturating_sub(1) {
                let t = [face[0], face[k], face[k + 1]];
                if crate::accel::is_degenerate(p(t[0]), p(t[1]), p(t[2])) {
                    continue;
                }
                faces.push(t.to_vec());
                face_of.push(f as u32);
            }
        }
        let fan = IndexedPolyhedron::new(&mesh.positions, &faces);
        (fan.face_count() == face_of.len()).then(|| FanMesh {
            poly: Arc::new(fan),
            face_of,
        })
    }
}

/// What replacing a mesh by its convex hull changes (`geometry::mesh::near_convex`).
#[derive(Clone, Debug)]
pub struct StandIn {
    /// The mesh itself: the face-by-face paths (the per-triangle method) go over its faces.
    pub mesh: Arc<IndexedPolyhedron>,
    /// Every point of the hull is within this distance of the mesh.
    pub deviation: f64,
    /// The farthest a vertex of the mesh lies outside the plane of one of its faces.
    pub outside: f64,
    /// The mesh's own vertex and face counts.
    pub mesh_vertices: usize,
    pub mesh_faces: usize,
}

impl StandIn {
    /// The polyhedron to prepare for `mesh`: its convex hull when the mesh is convex up to
    /// `rounding` (with the stand-in's record), else the mesh itself. The one place that
    /// decides it, for a first preparation and after a move alike.
    ///
    /// A mesh flat up to `rounding` (`geometry::mesh::near_convex::flat_up_to_rounding`) is
    /// classified planar instead, with no stand-in: it keeps its own vertices, and its faces
    /// tile its outline's image exactly.
    pub(crate) fn of(
        mut mesh: IndexedPolyhedron,
        rounding: f64,
    ) -> (IndexedPolyhedron, Option<StandIn>) {
        if flat_up_to_rounding(&mesh, rounding).is_some() {
            mesh.mesh.diagnostics.planar = true;
            return (mesh, None);
        }
        match convex_stand_in(&mesh, rounding) {
            Some(s) => {
                let stand_in = StandIn {
                    mesh_vertices: mesh.vertices.len(),
                    mesh_faces: mesh.face_count(),
                    mesh: Arc::new(mesh),
                    deviation: s.deviation,
                    outside: s.outside,
                };
                (s.hull.into(), Some(stand_in))
            }
            None => (mesh, None),
        }
    }

    /// The largest change of solid angle from a point at `distance` from the hull.
    pub fn solid_angle_bound(&self, distance: f64) -> f64 {
        solid_angle_bound(self.deviation, distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Mesh, shapes};

    /// A quad bent out of its plane is fanned into the two triangles rays see, each naming its
    /// face; a planar mesh has no fan.
    #[test]
    fn only_bent_faces_are_fanned() {
        let flat = shapes::cuboid(DVec3::ZERO, DVec3::splat(0.5));
        assert!(FanMesh::of(&flat).is_none());
        let mut bent = flat.clone();
        bent.positions[0] += DVec3::new(0.0, 0.0, 1e-3);
        let fan = FanMesh::of(&bent).expect("bent faces");
        assert_eq!(fan.poly.face_count(), 2 * flat.faces.len());
        for (t, &f) in fan.face_of.iter().enumerate() {
            let face = &bent.faces[f as usize];
            assert!(fan.poly.face(t).iter().all(|v| face.contains(v)));
        }
    }

    /// A cube whose corner was rounded inward by less than the input's rounding is convex as
    /// meant: its hull stands in, the mesh is kept for the face-by-face paths, and the hull is
    /// within the recorded deviation of every mesh vertex. Bent beyond the rounding, it is
    /// itself.
    #[test]
    fn a_cube_convex_up_to_rounding_takes_its_hull() {
        let mut cube: Mesh = shapes::cuboid(DVec3::ZERO, DVec3::splat(0.5));
        cube.positions[7] -= DVec3::splat(2e-7);
        let mesh = IndexedPolyhedron::new(&cube.positions, &cube.faces);
        assert!(!mesh.has_simple_silhouette());
        let (hull, stand_in) = StandIn::of(mesh.clone(), 1e-6);
        let s = stand_in.expect("convex up to 1e-6");
        assert!(hull.has_simple_silhouette());
        assert_eq!(s.mesh.face_count(), mesh.face_count());
        assert!(s.deviation > 0.0 && s.deviation < 1e-5);
        let (same, none) = StandIn::of(mesh, 1e-9);
        assert!(none.is_none());
        assert!(!same.has_simple_silhouette());
    }
}
