//! Silhouette trees built once for a set of meshes and lent to every prepared scene whose
//! meshes are affine images of them: the instance argument of [`super::prepared`] (001 Sect.
//! 5.4) applied across scenes instead of within one.
//!
//! `penumbra stress` generates millions of scenes, each a handful of the polyhedra of 001
//! Table 7.1 turned, scaled and moved at random. Building their trees per scene costs
//! 0.3–4.7 s a case; the library builds each polyhedron's trees once, in its own frame, over a
//! box around it, and a scene maps its points into that frame for the lookups. A point outside
//! the library's box takes the on-the-fly silhouette, exactly as a point outside a scene's own
//! tree does, so borrowing a tree changes where a silhouette is read from, never what it is.

use super::prepared::{MeshTrees, PreparedObject, build_mesh_trees, instance_map};
use crate::geometry::{IndexedPolyhedron, Polyhedron, star_centre};
use crate::scene::Mesh;
use glam::{DAffine3, DVec3};
use rayon::prelude::*;

/// One mesh of a library with its trees, in its own frame.
#[derive(Clone, Debug)]
pub struct LibraryEntry {
    pub poly: Polyhedron,
    pub trees: MeshTrees,
    /// A point strictly inside the kernel of a star-shaped non-convex mesh.
    pub star_centre: Option<DVec3>,
}

/// Trees built beforehand for a set of meshes (`PrepareOptions::library`).
#[derive(Clone, Debug, Default)]
pub struct TreeLibrary {
    pub entries: Vec<LibraryEntry>,
}

impl TreeLibrary {
    /// Builds the trees of every mesh (in parallel, without the disk cache) over the box
    /// `bounds`, with triangulations for the meshes that are neither convex nor star-shaped,
    /// within the size limits of `super::prepared::MAX_BSP_CELLS` and
    /// `super::prepared::MAX_EXACT_BSP_LEAVES` times `limit_factor`.
    pub fn build(meshes: &[Mesh], bounds: (DVec3, DVec3), limit_factor: usize) -> Self {
        let limits = (
            super::prepared::MAX_BSP_CELLS * limit_factor,
            super::prepared::MAX_EXACT_BSP_LEAVES * limit_factor,
        );
        let entries = meshes
            .par_iter()
            .map(|m| {
                let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
                let d = poly.diagnostics;
                let star = (!d.convex && d.closed_manifold)
                    .then(|| star_centre(&poly))
                    .flatten();
                let triangulate = !d.convex && d.closed_manifold && star.is_none();
                let trees = build_mesh_trees(&poly, bounds, triangulate, limits, usize::MAX, None);
                LibraryEntry {
                    poly: poly.mesh,
                    trees,
                    star_centre: star,
                }
            })
            .collect();
        TreeLibrary { entries }
    }

    /// The entry of which `poly` is an affine image (det > 0), and the map from `poly`'s frame
    /// into the entry's.
    pub(crate) fn find(&self, poly: &Polyhedron) -> Option<(&LibraryEntry, DAffine3)> {
        self.entries.iter().find_map(|e| {
            let has_tree = e.trees.tree.is_some();
            has_tree
                .then(|| instance_map(&e.poly, poly))
                .flatten()
                .map(|m| (e, m.inverse()))
        })
    }

    /// Whether `o` reads a tree of this library.
    pub fn lends_to(&self, o: &PreparedObject) -> bool {
        let Some(tree) = o.path.tree() else {
            return false;
        };
        self.entries.iter().any(|e| {
            e.trees
                .tree
                .as_ref()
                .is_some_and(|t| t.is_same(&tree.built))
        })
    }
}
