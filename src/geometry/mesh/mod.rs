//! Meshes as the silhouette stages take them: the polyhedron (faces, planes, edges,
//! diagnostics), what is indexed over it (the faces' and edges' hierarchies), rays and the
//! watertight ray–triangle test, convex hulls and exact predicates, kernels, and the plane that
//! separates two meshes.

pub mod convex_hull;
pub mod edge_hierarchy;
pub mod exact_predicates;
pub mod face_bvh;
pub mod kernel;
pub mod mesh_index;
pub mod near_convex;
pub mod polyhedron;
pub mod ray;
pub mod separation;
pub mod triangle;
