//! The geometry of one shading point: polyhedra, contours and silhouettes, spherical polygons,
//! horizon clipping, the planar projection and the set difference (000 Alg. 1–3, 001 Sect. 4).

pub(crate) mod mesh;
pub(crate) mod silhouettes;
pub(crate) mod spherical;
#[cfg(test)]
pub(crate) mod test_util;
pub(crate) mod trees;

pub use mesh::edge_hierarchy::{
    BuildParams, ContourScratch, CoplanarFace, EdgeHierarchy, EdgeQueryStats, contour_edge_indices,
    coplanar_tolerance,
};
pub use mesh::face_bvh::{FaceBvh, FaceEdges};
pub use mesh::kernel::{kernel, star_centre};
pub use mesh::mesh_index::{IndexedPolyhedron, MeshIndex};
pub use mesh::near_convex::{
    ConvexStandIn, convex_stand_in, flat_up_to_rounding, solid_angle_bound,
};
pub use mesh::polyhedron::{Edge, FeatureCounts, MeshDiagnostics, NO_FACE, Plane, Polyhedron};
pub use mesh::separation::separating_plane;
pub use silhouettes::exact_silhouette::{
    Degenerate, EDGE_PAIRS_MAX_EDGES, ExactSilhouetteScratch, ExactSilhouetteStats, PointCoding,
    SilhouettePoint, count_ray_hits, exact_silhouette, symbolic_loops,
};
pub use silhouettes::quantitative_invisibility::{QiScratch, QiStats, VertexStars};
pub use silhouettes::silhouette::{
    FrontCut, PlanarOutline, Sidedness, SilhouetteScratch, contour_edges, face_polygon, silhouette,
};
pub use silhouettes::silhouette_walk::ContourWalk;
pub use silhouettes::tile_candidates::{TileCandidates, TileQuery, TileRegion};
pub use silhouettes::windowed_silhouette::{
    WindowScratch, WindowStats, clip_to_window, exact_silhouette_in_window, window_cone,
};
pub use spherical::boundary_integral::{
    BoundaryPiece, BoundaryScratch, OccluderRegion, PieceSource, boundary_pieces,
    clamped_integral_of_boundary, visible_integral_from_boundary,
};
pub use spherical::cone::Cone;
pub use spherical::hole_difference::{HoleScratch, part_inside_convex};
pub use spherical::horizon::{HorizonScratch, clip_to_horizon};
pub use spherical::overlap::{Overlap, classify as classify_overlap};
pub use spherical::polygon_loops::PolygonLoops;
pub use spherical::projection::{PlanarPolygon, ProjectionPlane};
pub use spherical::set_difference::{
    COLLAPSE_RADIUS, ChainKind, EPS_LINE, EPS_POINT, EdgePoint, FragmentSide, GreinerHormannSteps,
    IntersectionKind, IntersectionRecord, LabelRecord, Operand, OverlapChain, SetDifference,
    Transition, TraversalStep, TraversedLoop, UntouchedLoop, VertexLabel,
};
pub use spherical::spherical_polygon::{SphericalPolygon, orient, solid_angle_of_triangle};
pub use trees::bsp::{BspNode, BspPath, BspStats, LOOP_END, SilhouetteBsp, bsp_cell, bsp_leaf};
pub use trees::bsp_hoisted::{HoistedKind, HoistedNode, HoistedSilhouetteBsp, loop_runs};
pub use trees::bsp_nonconvex::{ExactBspLimits, ExactBspStats, ExactSilhouetteBsp};
pub use trees::bsp_sections::{PlaneSection, path_sections};
pub use trees::cell_triangulation::{
    SilhouetteTriangulation, TriangulationLimits, TriangulationStats, concave_edge_endpoints,
    triangulate_silhouette,
};
pub use trees::convex_cell::{CellSide, ConvexCell};
pub use trees::silhouette_tree::{SilhouetteTree, TreeKind, TreeNode};
