//! Rays, ray–triangle intersection and a BVH over all scene triangles (camera rays, shadow
//! rays of the ray-cast oracle). See docs/accel.md.
//!
//! * [`Ray`]: origin and direction; `t` is always in units of the direction.
//! * [`intersect_triangle`], [`PreparedRay`]: the watertight test of Woop et al. 2013 in f64.
//! * [`Bvh`]: binned-SAH BVH with closest-hit [`Bvh::intersect`] and any-hit
//!   [`Bvh::occluded`] queries.
//!
//! No query uses an epsilon in world units: callers choose `t_min` (and `t_max`).

pub(crate) mod bvh;

pub use bvh::{Bvh, Hit, newell_normal};
// The ray and the ray–triangle test are geometry (the exact silhouettes' ray tests use them
// too), reached from outside the crate here; the hierarchy built over a scene's triangles is
// what lives here.
pub use crate::geometry::mesh::ray::Ray;
pub use crate::geometry::mesh::triangle::{
    PreparedRay, TriangleHit, intersect_triangle, is_degenerate,
};
pub(crate) use crate::geometry::mesh::{ray, triangle};
