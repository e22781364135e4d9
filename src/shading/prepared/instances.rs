//! Instances (001 Sect. 5.4: "multiple light sources can share the same buffers"): meshes with
//! the same faces whose vertices are one affine map (positive determinant) of another's share
//! one tree of precomputed silhouettes, built in the frame of the group's first member. Every
//! plane of the tree is a face plane, a three-endpoint plane or a validation split, and every
//! test it makes is the side of such a plane, i.e. the sign of det(a − x, b − x, c − x) for
//! points a, b, c of the mesh; an affine map `M` with det M > 0 multiplies that determinant by
//! det M, so `x` and `M x` fall in corresponding cells. What a leaf stores (vertex indices and
//! pairs of edges that appear to cross) is made of incidences and orientations, which `M`
//! preserves too, so it is the same for every instance: shading maps the point into the
//! tree's frame for the lookup and reads the silhouette off the instance's own vertices. This
//! covers rotations, uniform and non-uniform scales (a sheared or squashed copy has the same
//! silhouette structure from the corresponding point); mirror images (det M < 0) reverse the
//! orientations and are not shared.

use super::PreparedObject;
use crate::geometry::Polyhedron;
use glam::{DAffine3, DMat3, DVec3};

/// Relative tolerance (of the mesh's radius) within which an instance's vertices must be the
/// affine image of the first member's: far below the trees' own tolerances (1e-9 · radius),
/// far above the rounding of a scene file's scale, rotate and translate.
pub(crate) const INSTANCE_TOLERANCE: f64 = 1e-10;

/// The affine map `M` (det M > 0) with `other.vertices[k] = M(base.vertices[k])` for every `k`
/// within `INSTANCE_TOLERANCE`, if `other` has the same faces (vertex indices) as `base`.
/// `M` is solved from four vertices of `base` spanning a tetrahedron of large volume and then
/// verified on all vertices; flat meshes (no such tetrahedron) are not matched.
pub fn instance_map(base: &Polyhedron, other: &Polyhedron) -> Option<DAffine3> {
    let same_faces = base.vertices.len() == other.vertices.len()
        && base.face_indices == other.face_indices
        && base.face_starts == other.face_starts
        && base.edges == other.edges
        && base.diagnostics.convex == other.diagnostics.convex
        && base.diagnostics.closed_manifold == other.diagnostics.closed_manifold;
    if !same_faces || base.vertices.is_empty() {
        return None;
    }
    let p = &base.vertices;
    let q = &other.vertices;
    let argmax =
        |f: &dyn Fn(DVec3) -> f64| (0..p.len()).max_by(|&a, &b| f(p[a]).total_cmp(&f(p[b])));
    let i0 = 0;
    let i1 = argmax(&|v| v.distance_squared(p[i0]))?;
    let u = p[i1] - p[i0];
    let i2 = argmax(&|v| u.cross(v - p[i0]).length_squared())?;
    let n = u.cross(p[i2] - p[i0]);
    let i3 = argmax(&|v| n.dot(v - p[i0]).abs())?;
    let pm = DMat3::from_cols(u, p[i2] - p[i0], p[i3] - p[i0]);
    let r = base.radius.max(f64::MIN_POSITIVE);
    // A tetrahedron this thin would amplify rounding in the solve beyond the tolerance.
    if pm.determinant().abs() <= 1e-6 * r * r * r {
        return None;
    }
    let qm = DMat3::from_cols(q[i1] - q[i0], q[i2] - q[i0], q[i3] - q[i0]);
    let a = qm * pm.inverse();
    if !a.is_finite() || a.determinant() <= 0.0 {
        return None;
    }
    let m = DAffine3::from_mat3_translation(a, q[i0] - a * p[i0]);
    let tol = INSTANCE_TOLERANCE * other.radius.max(f64::MIN_POSITIVE);
    p.iter()
        .zip(q)
        .all(|(&a, &b)| m.transform_point3(a).distance(b) <= tol)
        .then_some(m)
}

/// Groups of objects that share one tree: the first member's frame is the tree's; every other
/// member gets its `to_tree` map. Only objects that can have a tree (convex, or manifold:
/// closed or open) are grouped; with `share` false every such object is its own group.
pub(super) fn instance_groups(objects: &mut [PreparedObject], share: bool) -> Vec<Vec<u32>> {
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for i in 0..objects.len() {
        objects[i].to_tree = None;
        let d = objects[i].poly.diagnostics;
        // Convex, closed, or open but manifold and not flat (a flat mesh chains its outline).
        let open_tree = d.nonmanifold_edges == 0 && !d.planar;
        if !d.convex && !d.closed_manifold && !open_tree {
            continue;
        }
        let found = share
            .then(|| {
                groups.iter().position(|g| {
                    let base = &objects[g[0] as usize].poly;
                    match instance_map(base, &objects[i].poly) {
                        Some(m) => {
                            objects[i].to_tree = Some(m.inverse());
                            true
                        }
                        None => false,
                    }
                })
            })
            .flatten();
        match found {
            Some(g) => groups[g].push(i as u32),
            None => groups.push(vec![i as u32]),
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Polyhedron;
    use crate::scene::shapes;
    use glam::DQuat;

    fn poly(mesh: &crate::scene::Mesh) -> Polyhedron {
        Polyhedron::new(&mesh.positions, &mesh.faces)
    }

    /// A turned, scaled and moved copy is found, and the map found carries every vertex onto
    /// its image (checked against the map the copy was made with).
    #[test]
    fn an_affine_copy_is_an_instance() {
        let base = shapes::l_shape(DVec3::ZERO, 1.0, 1.2, 0.3, 0.5);
        let made = DAffine3::from_scale_rotation_translation(
            DVec3::new(1.5, 0.7, 2.0),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 0.4),
            DVec3::new(3.0, -2.0, 0.5),
        );
        let copy = base.transformed(&made);
        let m = instance_map(&poly(&base), &poly(&copy)).expect("an affine image");
        for (a, b) in base.positions.iter().zip(&copy.positions) {
            assert!(m.transform_point3(*a).distance(*b) < 1e-12);
        }
        assert!((m.matrix3.determinant() - made.matrix3.determinant()).abs() < 1e-12);
    }

    /// A mirror image reverses every orientation a tree stores, and a copy bent beyond the
    /// tolerance is another mesh: neither shares the tree.
    #[test]
    fn mirror_images_and_bent_copies_are_not() {
        let base = shapes::l_shape(DVec3::ZERO, 1.0, 1.2, 0.3, 0.5);
        let mirror = base.transformed(&DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)));
        assert!(instance_map(&poly(&base), &poly(&mirror)).is_none());
        let mut bent = base.clone();
        let r = poly(&base).radius;
        bent.positions[3] += DVec3::splat(1e3 * INSTANCE_TOLERANCE * r);
        assert!(instance_map(&poly(&base), &poly(&bent)).is_none());
        let mut within = base.clone();
        within.positions[3] += DVec3::splat(1e-3 * INSTANCE_TOLERANCE * r);
        assert!(instance_map(&poly(&base), &poly(&within)).is_some());
    }
}
