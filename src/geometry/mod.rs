//! The geometry of one shading point: polyhedra, contours and silhouettes, spherical polygons,
//! horizon clipping, the planar projection and the set difference (000 Alg. 1–3, 001 Sect. 4).

pub mod bsp;
pub mod bsp_hoisted;
pub mod bsp_nonconvex;
pub mod bsp_sections;
pub mod cell_triangulation;
pub mod cone;
mod contour_pieces;
pub mod convex_cell;
pub mod convex_hull;
pub mod edge_hierarchy;
pub mod exact_predicates;
pub mod exact_silhouette;
pub mod face_bvh;
pub mod hole_difference;
pub mod horizon;
pub mod horizon_split;
pub mod kernel;
pub mod mesh_index;
pub mod near_convex;
pub mod overlap;
mod polygon_loops;
pub mod polyhedron;
pub mod projection;
pub mod quantitative_invisibility;
pub mod ray;
pub mod separation;
pub mod set_difference;
pub mod silhouette;
pub mod silhouette_tree;
pub mod silhouette_walk;
pub mod spherical_polygon;
#[cfg(test)]
pub(crate) mod test_util;
pub mod tile_candidates;
pub mod triangle;
pub mod windowed_silhouette;

pub use bsp::{BspNode, BspPath, BspStats, SilhouetteBsp, bsp_cell, bsp_leaf};
pub use bsp_hoisted::{HoistedKind, HoistedSilhouetteBsp};
pub use bsp_nonconvex::{ExactBspLimits, ExactBspStats, ExactSilhouetteBsp};
pub use bsp_sections::{PlaneSection, path_sections};
pub use cell_triangulation::{SilhouetteTriangulation, TriangulationLimits, TriangulationStats};
pub use convex_cell::{CellSide, ConvexCell};
pub use exact_silhouette::{
    Degenerate, EDGE_PAIRS_MAX_EDGES, ExactSilhouetteScratch, ExactSilhouetteStats, PointCoding,
    SilhouettePoint, count_ray_hits, exact_silhouette, symbolic_loops,
};
pub use hole_difference::{HoleScratch, part_inside_convex};
pub use horizon::{HorizonScratch, clip_to_horizon};
pub use kernel::{kernel, star_centre};
pub use mesh_index::{IndexedPolyhedron, MeshIndex};
pub use near_convex::{ConvexStandIn, convex_stand_in, flat_up_to_rounding, solid_angle_bound};
pub use overlap::{Overlap, classify as classify_overlap};
pub use polygon_loops::PolygonLoops;
pub use polyhedron::{Edge, FeatureCounts, MeshDiagnostics, Plane, Polyhedron};
pub use projection::{PlanarPolygon, ProjectionPlane};
pub use quantitative_invisibility::QiStats;
pub use separation::separating_plane;
pub use set_difference::{GreinerHormannSteps, SetDifference};
pub use silhouette::{Sidedness, SilhouetteScratch, contour_edges, face_polygon, silhouette};
pub use silhouette_tree::{SilhouetteTree, TreeKind, TreeNode};
pub use spherical_polygon::{SphericalPolygon, orient};
pub use tile_candidates::{TileCandidates, TileQuery, TileRegion};
pub use windowed_silhouette::{
    WindowScratch, WindowStats, clip_to_window, exact_silhouette_in_window, window_cone,
};
