//! The geometry of one shading point: polyhedra, contours and silhouettes, spherical polygons,
//! horizon clipping, the planar projection and the set difference (000 Alg. 1–3, 001 Sect. 4).

mod polygon_loops;
pub mod projection;
pub mod set_difference;
pub mod spherical_polygon;

pub use polygon_loops::PolygonLoops;
pub use projection::{PlanarPolygon, ProjectionPlane};
pub use set_difference::{GreinerHormannSteps, SetDifference};
pub use spherical_polygon::{SphericalPolygon, orient};
