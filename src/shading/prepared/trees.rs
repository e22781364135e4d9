//! The trees of precomputed silhouettes of a prepared scene: built (or read from the disk
//! cache or a library) once per group of instances, each within the budget the cost model
//! gives it.

use super::mesh_path::{BuiltTree, WINDOWED_MIN_FACES};
use super::report::{NoExactTree, PrepareNote};
use super::{PrepareOptions, PreparedObject};
use crate::geometry::trees::bsp::face_planes_exceed;
use crate::geometry::{
    EDGE_PAIRS_MAX_EDGES, ExactBspLimits, ExactSilhouetteBsp, IndexedPolyhedron, PointCoding,
    SilhouetteBsp, SilhouetteTriangulation, TriangulationLimits, star_centre,
};
use crate::shading::cost_model::{MeshCostClass, TreeBudget, tree_budget};
use crate::shading::tree_cache::{CachedTree, TreeCache, tree_key};
use crate::shading::tree_library::LibraryEntry;
use glam::{DAffine3, DVec3};
use rayon::prelude::*;
use std::sync::Arc;

/// Non-convex meshes whose tree would have more leaves than this keep computing their exact
/// silhouette on the fly.
pub const MAX_EXACT_BSP_LEAVES: usize = 200_000;

/// The same bound for an open mesh's tree, whose leaves cost more to build (stage 2 has more
/// pairs, and every cell is validated at its corners and at its faces' and edges' middles):
/// a tree that does not fit stays unbuilt, so that a failed attempt costs milliseconds of a
/// cold start, where the closed meshes' bound lets two small open meshes' failing attempts
/// take tens of seconds (docs/silhouettes.md, "Trees of open meshes").
pub(crate) const MAX_OPEN_BSP_LEAVES: usize = 2_000;

/// Convex meshes whose face planes cut the scene into more cells than this keep computing
/// their silhouette on the fly (the count grows with the cube of the face count).
pub const MAX_BSP_CELLS: usize = 50_000;

/// The trees one mesh (or group of instances) reads: its tree of precomputed silhouettes, if
/// it got one, and, for a light that is neither convex nor star-shaped, the per-cell
/// triangulations of its silhouettes.
#[derive(Clone, Debug, Default)]
pub struct MeshTrees {
    pub tree: Option<BuiltTree>,
    pub triangulation: Option<Arc<SilhouetteTriangulation>>,
    /// How many of these were built rather than read from the disk cache.
    pub built: u32,
}

/// Builds (or reads from `cache`) the trees of `poly` over the box `lo..hi`: a convex mesh's
/// tree of face planes, a closed non-convex mesh's exact-silhouette tree, each within its size
/// limit, and the triangulations when `triangulate` and the exact tree exists.
pub fn build_mesh_trees(
    poly: &IndexedPolyhedron,
    (lo, hi): (DVec3, DVec3),
    triangulate: bool,
    (max_cells, max_leaves): (usize, usize),
    budget: usize,
    cache: Option<&TreeCache>,
) -> MeshTrees {
    let d = poly.diagnostics;
    let mut built = 0;
    let limit = if d.convex {
        max_cells
    } else if d.closed_manifold {
        max_leaves
    } else {
        max_leaves.min(MAX_OPEN_BSP_LEAVES)
    };
    let budget = budget.min(limit);
    // The key names the mesh, the box and the hard limit (not the budget, which follows the
    // render's size): a tree shared by other instances (another union of boxes) is another
    // file. A tree found there is used whatever the budget: reading it costs nothing.
    let key = tree_key(poly, lo, hi, limit, d.convex);
    let tree = match cache.and_then(|c| c.load(key, poly)) {
        Some(CachedTree::OverLimit { tried }) if tried >= budget => CachedTree::OverLimit { tried },
        Some(t @ (CachedTree::Convex(_) | CachedTree::Exact(_))) => t,
        _ => {
            built += 1;
            let over = CachedTree::OverLimit { tried: budget };
            let tree = if budget == 0 {
                over // the cost model wants no tree (`cost_model::tree_budget`)
            } else if d.convex {
                SilhouetteBsp::build_convex_limited(poly, lo, hi, budget)
                    .map_or(over, |(t, _)| CachedTree::Convex(t))
            } else if PointCoding::for_mesh(poly).is_none() {
                CachedTree::OverLimit { tried: usize::MAX }
            } else if face_planes_exceed(poly, lo, hi, budget) {
                // The quick trial: the leaves refine the face planes' cells.
                over
            } else {
                let limits = ExactBspLimits {
                    max_leaves: budget,
                    ..ExactBspLimits::default()
                };
                ExactSilhouetteBsp::build(poly, lo, hi, limits)
                    .map_or(over, |(t, _)| CachedTree::Exact(t))
            };
            if let Some(c) = cache {
                c.store(key, &tree);
            }
            tree
        }
    };
    let triangulation = match &tree {
        // Triangulations keep the thesis' coding of points: meshes of at most 256 vertices.
        CachedTree::Exact(exact) if triangulate && exact.coding == PointCoding::Vertices8 => {
            let key = key ^ TRIANGULATION_KEY;
            match cache.and_then(|c| c.load(key, poly)) {
                Some(CachedTree::Triangulation(t)) => Some(t),
                _ => {
                    built += 1;
                    let (t, _) =
                        SilhouetteTriangulation::build(poly, exact, TriangulationLimits::default());
                    if let Some(c) = cache {
                        c.store(key, &CachedTree::Triangulation(t.clone()));
                    }
                    Some(t)
                }
            }
        }
        _ => None,
    };
    let tree = match tree {
        CachedTree::Convex(t) if d.convex => Some(BuiltTree::Convex(Arc::new(t))),
        CachedTree::Exact(t) if !d.convex => Some(BuiltTree::Exact(Arc::new(t))),
        _ => None,
    };
    MeshTrees {
        tree,
        triangulation: triangulation.map(Arc::new),
        built,
    }
}

/// The tree of precomputed silhouettes of every group of instances of a convex or closed mesh
/// (one task per group), built for the first member over `bounds` and each member's own
/// bounding box, all mapped into the first member's frame (the box of the 8 mapped corners of
/// each); meshes over the limits get none. Every member holds the same `Arc`. A group whose
/// mesh is an affine image of a mesh of `library` reads that tree instead, in its frame.
/// Each group's build gets the budget of the cost model (`cost_model`) for
/// `options.expected_rays` camera rays. Returns how many trees were built, and each group's
/// budget (`None` for a group that borrowed its tree or built none).
pub(super) fn build_silhouette_trees(
    objects: &mut [PreparedObject],
    groups: &[Vec<u32>],
    lights: &[u32],
    bounds: (DVec3, DVec3),
    limits: (usize, usize),
    cache: Option<&TreeCache>,
    options: &PrepareOptions,
) -> (u32, Vec<Option<TreeBudget>>) {
    let (library, build) = (options.library, options.build_trees);
    let borrowed: Vec<Option<(&LibraryEntry, DAffine3)>> = groups
        .iter()
        .map(|g| library.and_then(|l| l.find(&objects[g[0] as usize].poly)))
        .collect();
    objects.par_iter_mut().for_each(|o| {
        o.set_tree(None);
        o.triangulation = None;
        o.star_centre = None;
    });
    // A borrowed tree's frame is the library mesh's: each member maps its points there
    // through its own map into the first member's frame, then the first member's into the
    // library's; the star centre comes back the other way.
    for (g, b) in groups.iter().zip(&borrowed) {
        let Some((entry, base_to_library)) = b else {
            continue;
        };
        for &m in g {
            let o = &mut objects[m as usize];
            let to_library = match o.to_tree {
                Some(to_base) => *base_to_library * to_base,
                None => *base_to_library,
            };
            o.to_tree = Some(to_library);
            o.star_centre = entry
                .star_centre
                .map(|c| to_library.inverse().transform_point3(c));
        }
    }
    let own_tree: Vec<bool> = {
        let mut v = vec![false; objects.len()];
        for (g, b) in groups.iter().zip(&borrowed) {
            if b.is_none() {
                for &m in g {
                    v[m as usize] = true;
                }
            }
        }
        v
    };
    objects
        .par_iter_mut()
        .zip(own_tree.par_iter())
        .for_each(|(o, &own)| {
            let d = o.poly.diagnostics;
            // For the sampler (as the triangulations): not for scenes that build no trees.
            if own && build && !d.convex && d.closed_manifold {
                o.star_centre = star_centre(&o.poly);
            }
        });
    let objs = &*objects;
    let budgets: Vec<Option<TreeBudget>> = groups
        .iter()
        .zip(&borrowed)
        .map(|(g, b)| {
            if b.is_some() || !build {
                return None;
            }
            let base = &objs[g[0] as usize];
            let d = base.poly.diagnostics;
            let light = g.iter().any(|m| lights.contains(m));
            let class = MeshCostClass {
                faces: base.poly.face_count(),
                convex: d.convex,
                light,
                windowed: base.poly.face_count() >= WINDOWED_MIN_FACES
                    && base.poly.index.face_bvh.is_some(),
                environment: options.environment,
            };
            let limit = if d.convex { limits.0 } else { limits.1 };
            // Every instance of the group is queried.
            Some(tree_budget(
                class,
                options.expected_rays.saturating_mul(g.len() as u64),
                limit,
            ))
        })
        .collect();
    let trees: Vec<MeshTrees> = groups
        .par_iter()
        .zip(&borrowed)
        .zip(&budgets)
        .map(|((g, b), budget)| {
            if let Some((entry, _)) = b {
                return MeshTrees {
                    built: 0,
                    ..entry.trees.clone()
                };
            }
            let Some(budget) = budget else {
                return MeshTrees::default();
            };
            let base = &objs[g[0] as usize];
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &m in g {
                let o = &objs[m as usize];
                let (a, b) = (
                    bounds.0.min(o.poly.center - o.poly.radius),
                    bounds.1.max(o.poly.center + o.poly.radius),
                );
                for k in 0..8 {
                    let c = DVec3::new(
                        if k & 1 == 0 { a.x } else { b.x },
                        if k & 2 == 0 { a.y } else { b.y },
                        if k & 4 == 0 { a.z } else { b.z },
                    );
                    let c = o.tree_point(c);
                    (lo, hi) = (lo.min(c), hi.max(c));
                }
            }
            // A light that is not star-shaped is sampled through triangulated silhouettes.
            let is_light = g.iter().any(|m| lights.contains(m));
            let triangulate = is_light && base.star_centre.is_none();
            build_mesh_trees(
                &base.poly,
                (lo, hi),
                triangulate,
                limits,
                budget.units,
                cache,
            )
        })
        .collect();
    let mut built = 0;
    for (g, t) in groups.iter().zip(trees) {
        built += t.built;
        for &m in g {
            let o = &mut objects[m as usize];
            o.set_tree(t.tree.clone());
            o.triangulation = t.triangulation.clone();
        }
    }
    (built, budgets)
}

/// Distinguishes the cache key of a mesh's triangulations from that of its silhouette tree.
const TRIANGULATION_KEY: u64 = 0x7472_6961_6e67_6c65;

/// What a group's tree (or its absence) is worth telling, if anything: `attempted` when the
/// scene builds trees or a library lends this group one.
pub(super) fn tree_note(
    objects: &[PreparedObject],
    group: &[u32],
    budget: &Option<TreeBudget>,
    attempted: bool,
) -> Option<PrepareNote> {
    let o = &objects[group[0] as usize];
    let d = &o.poly.diagnostics;
    let names = || super::names(objects, group);
    if !attempted {
        Some(PrepareNote::NoTreesBuilt { objects: names() })
    } else if d.convex && o.convex_tree().is_none() {
        Some(PrepareNote::ConvexTreeOverBudget {
            objects: names(),
            budget: *budget,
            limit: MAX_BSP_CELLS,
        })
    } else if !d.convex && o.exact_tree().is_none() {
        let why = if PointCoding::for_mesh(&o.poly).is_none() {
            NoExactTree::TooManyEdges {
                max_edges: EDGE_PAIRS_MAX_EDGES,
            }
        } else if budget.is_some_and(|b| b.saving_seconds == 0.0) {
            NoExactTree::WindowCheaper
        } else {
            NoExactTree::OverBudget {
                budget: *budget,
                limit: MAX_EXACT_BSP_LEAVES,
            }
        };
        Some(PrepareNote::NoExactTree {
            objects: names(),
            why,
        })
    } else if group.len() > 1 {
        Some(PrepareNote::SharedTree { objects: names() })
    } else {
        None
    }
}
