//! The kernel of a polyhedron: the points that see its whole surface, the intersection of the
//! back half-spaces of its face planes. A closed mesh is star-shaped when the kernel has an
//! interior; a point in it is a centre from which every silhouette can be fanned (001 Sect.
//! 6.1: the projections of the faces from a kernel point never overlap).

use crate::geometry::Polyhedron;
use crate::geometry::trees::convex_cell::ConvexCell;
use glam::DVec3;

/// The kernel of a closed mesh (empty if it has no interior), by clipping the mesh's bounding
/// box to the back side of every face plane.
pub fn kernel(poly: &Polyhedron) -> ConvexCell {
    if !poly.diagnostics.closed_manifold || poly.face_count() == 0 {
        return ConvexCell::default();
    }
    let r = poly.radius.max(f64::MIN_POSITIVE);
    let tol = 1e-12 * r;
    let mut cell = ConvexCell::cuboid(poly.center - DVec3::splat(r), poly.center + DVec3::splat(r));
    for plane in &poly.face_planes {
        cell = cell.clip_to_back(plane, tol);
        if cell.is_empty() {
            break;
        }
    }
    // A kernel thinner than rounding is no kernel: it could not hold a centre robustly.
    if cell.volume() <= 1e-12 * r * r * r {
        return ConvexCell::default();
    }
    cell
}

/// A point strictly inside the kernel (the mean of its vertices), or `None` if the mesh is not
/// star-shaped. For a convex mesh that is a point inside the mesh.
pub fn star_centre(poly: &Polyhedron) -> Option<DVec3> {
    let k = kernel(poly);
    (!k.is_empty()).then(|| k.centroid())
}
