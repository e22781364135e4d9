//! The acceleration structures built over a [`Polyhedron`], kept apart from the mesh itself:
//! each is built from the mesh alone, when the mesh is large enough for it to pay, and read
//! by the silhouette stages that need it. [`IndexedPolyhedron`] is a mesh with its index, what
//! those stages take.

use crate::geometry::mesh::edge_hierarchy::{EDGE_HIERARCHY_MIN_EDGES, EdgeHierarchy};
use crate::geometry::mesh::face_bvh::{FACE_BVH_MIN_FACES, FaceBvh, FaceEdges};
use crate::geometry::mesh::polyhedron::Polyhedron;
use crate::geometry::silhouettes::quantitative_invisibility::VertexStars;
use crate::geometry::silhouettes::silhouette::PlanarOutline;
use crate::geometry::silhouettes::silhouette_walk::ContourWalk;
use glam::DVec3;
use std::sync::Arc;

/// What is built over a mesh to answer the silhouette stages' questions fast. Each is `None`
/// where it does not pay or does not apply; every stage then scans instead, with the same
/// answer.
#[derive(Clone, Debug, Default)]
pub struct MeshIndex {
    /// The faces' boxes in a hierarchy, for meshes of at least `FACE_BVH_MIN_FACES` faces
    /// (the exact silhouette's ray tests, the windowed silhouette's cone query).
    pub face_bvh: Option<Arc<FaceBvh>>,
    /// Each face's edges, with the hierarchy (the windowed silhouette walks from faces to edges).
    pub face_edges: Option<Arc<FaceEdges>>,
    /// Adjacency for walking the contour of a large convex mesh (`silhouette_walk`).
    pub contour_walk: Option<Arc<ContourWalk>>,
    /// The star of each vertex (its faces' fan triangles' corners there), for manifold meshes,
    /// closed or open (quantitative invisibility's vertex rule needs it, and no edge with more
    /// than two faces).
    pub vertex_stars: Option<Arc<VertexStars>>,
    /// Normal cones over the edges, for finding the contour edges of a large mesh without a
    /// scan (`edge_hierarchy`); large convex meshes walk their contour instead.
    pub edge_hierarchy: Option<Arc<EdgeHierarchy>>,
    /// The hierarchy also answers the queries of single points ([`EdgeHierarchy::pays`]
    /// against the scan). Where it does not, it serves only the lists a tile's region shares
    /// (`tile_candidates`), built once for many points; single points scan, or query the
    /// faces' hierarchy in a window.
    pub edge_hierarchy_per_point: bool,
    /// The outline of a flat mesh (a quad light, a card occluder), chained once: per point
    /// only the side of its plane is decided.
    pub planar_outline: Option<Arc<PlanarOutline>>,
}

impl MeshIndex {
    /// Everything that pays for `poly`.
    pub fn build(poly: &Polyhedron) -> Self {
        let (face_bvh, face_edges) = face_hierarchy(poly);
        let contour_walk = ContourWalk::new(poly).map(Arc::new);
        let vertex_stars =
            (poly.diagnostics.nonmanifold_edges == 0).then(|| Arc::new(VertexStars::build(poly)));
        let edge_hierarchy = (poly.edges.len() >= EDGE_HIERARCHY_MIN_EDGES
            && contour_walk.is_none())
        .then(|| EdgeHierarchy::build(poly));
        let edge_hierarchy_per_point = edge_hierarchy.as_ref().is_some_and(|h| h.pays(poly));
        let planar_outline = PlanarOutline::new(poly).map(Arc::new);
        MeshIndex {
            face_bvh,
            face_edges,
            contour_walk,
            vertex_stars,
            edge_hierarchy: edge_hierarchy.map(Arc::new),
            edge_hierarchy_per_point,
            planar_outline,
        }
    }

    /// The index of `moved`, the mesh this index was built for with its vertices moved
    /// ([`Polyhedron::moved`]): the topology (the contour walk's adjacency, each face's
    /// edges) is kept, the geometry (the faces' hierarchy, the edges' normal cones, the
    /// vertices' stars, whose degenerate fan triangles may change with a move's rounding)
    /// built again. The cones are built again only where the first build kept
    /// them, and serve single points only where they did before and still pay.
    pub(crate) fn moved(&self, moved: &Polyhedron) -> Self {
        let (face_bvh, face_edges) = face_hierarchy(moved);
        let edge_hierarchy = self
            .edge_hierarchy
            .as_ref()
            .map(|_| EdgeHierarchy::build(moved));
        let edge_hierarchy_per_point =
            self.edge_hierarchy_per_point && edge_hierarchy.as_ref().is_some_and(|h| h.pays(moved));
        MeshIndex {
            face_bvh,
            face_edges: self.face_edges.clone().or(face_edges),
            contour_walk: self.contour_walk.clone(),
            // Which fan triangles are degenerate may change with the rounding of a move.
            vertex_stars: self
                .vertex_stars
                .as_ref()
                .map(|_| Arc::new(VertexStars::build(moved))),
            edge_hierarchy: edge_hierarchy.map(Arc::new),
            edge_hierarchy_per_point,
            planar_outline: PlanarOutline::new(moved).map(Arc::new),
        }
    }
}

/// The faces' hierarchy and each face's edges, for a mesh of at least [`FACE_BVH_MIN_FACES`]
/// faces.
fn face_hierarchy(poly: &Polyhedron) -> (Option<Arc<FaceBvh>>, Option<Arc<FaceEdges>>) {
    if poly.face_count() < FACE_BVH_MIN_FACES {
        return (None, None);
    }
    let boxes: Vec<(DVec3, DVec3)> = (0..poly.face_count())
        .map(|f| {
            poly.face(f)
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &v| {
                    let p = poly.vertices[v as usize];
                    (a.min(p), b.max(p))
                })
        })
        .collect();
    let faces = poly.edges.iter().map(|e| e.faces);
    (
        Some(Arc::new(FaceBvh::build(&boxes))),
        Some(Arc::new(FaceEdges::build(poly.face_count(), faces))),
    )
}

/// A mesh with the index built over it: what the silhouette stages take. It reads as its mesh
/// (`Deref`), so that the stages that need no index take it as a [`Polyhedron`].
#[derive(Clone, Debug)]
pub struct IndexedPolyhedron {
    pub mesh: Polyhedron,
    pub index: MeshIndex,
}

impl IndexedPolyhedron {
    /// The mesh of `vertices` and `faces` ([`Polyhedron::new`]) with its index.
    pub fn new(vertices: &[DVec3], faces: &[Vec<u32>]) -> Self {
        Self::from(Polyhedron::new(vertices, faces))
    }

    /// This mesh with its vertices moved to `positions` ([`Polyhedron::moved`]), its index
    /// moved with it ([`MeshIndex::moved`]).
    pub(crate) fn moved(&self, positions: &[DVec3]) -> Option<Self> {
        let mesh = self.mesh.moved(positions)?;
        let index = self.index.moved(&mesh);
        Some(IndexedPolyhedron { mesh, index })
    }
}

impl From<Polyhedron> for IndexedPolyhedron {
    fn from(mesh: Polyhedron) -> Self {
        let index = MeshIndex::build(&mesh);
        IndexedPolyhedron { mesh, index }
    }
}

impl std::ops::Deref for IndexedPolyhedron {
    type Target = Polyhedron;
    fn deref(&self) -> &Polyhedron {
        &self.mesh
    }
}
