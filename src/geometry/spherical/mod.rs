//! Spherical polygons and what is done to them at a shading point: loops of unit vectors,
//! horizon clipping (000 Alg. 3), the planar projection, overlap tests, and the set difference
//! of a light and an occluder (Greiner–Hormann, 000 appendix); cones of directions.

pub mod boundary_integral;
pub mod cone;
pub mod hole_difference;
pub mod horizon;
pub mod horizon_split;
pub mod overlap;
pub(crate) mod polygon_loops;
pub mod projection;
pub mod set_difference;
pub mod spherical_polygon;
