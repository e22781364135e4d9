//! The scene as the shading stages need it, computed once per scene: polyhedra with adjacency,
//! which path each mesh takes, separating planes of light/occluder pairs, the LTC table.

use super::tree_cache::{self, CachedTree, tree_key};
use crate::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, Plane, Polyhedron, SilhouetteBsp, SilhouetteTriangulation,
    TriangulationLimits, separating_plane, star_centre,
};
use crate::ltc::LtcTable;
use crate::scene::{Material, Scene};
use glam::DVec3;
use rayon::prelude::*;

/// A light or occluder mesh.
#[derive(Clone, Debug)]
pub struct PreparedObject {
    /// Index of the object in the scene.
    pub object: u32,
    pub name: String,
    pub poly: Polyhedron,
    /// Takes the silhouette path (convex closed or flat); otherwise per face.
    pub simple: bool,
    /// Precomputed silhouettes of a convex mesh over the scene's bounds (001 Sect. 5.1).
    pub bsp: Option<SilhouetteBsp>,
    /// Precomputed exact silhouettes of a closed non-convex mesh (001 Sect. 5.2).
    pub exact_bsp: Option<ExactSilhouetteBsp>,
    /// A point strictly inside the kernel of a star-shaped non-convex mesh: its silhouettes
    /// are fanned from there for sampling (001 Sect. 6.1).
    pub star_centre: Option<DVec3>,
    /// Precomputed triangulations of the exact silhouettes of a light that is neither convex
    /// nor star-shaped, proved per cell (001 Sect. 6.2), for sampling.
    pub triangulation: Option<SilhouetteTriangulation>,
}

/// Non-convex meshes whose tree would have more leaves than this keep computing their exact
/// silhouette on the fly.
pub const MAX_EXACT_BSP_LEAVES: usize = 20_000;

/// Convex meshes whose face planes cut the scene into more cells than this keep computing
/// their silhouette on the fly (the count grows with the cube of the face count).
pub const MAX_BSP_CELLS: usize = 50_000;

/// Everything the shading stages read, shared by all threads.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub objects: Vec<PreparedObject>,
    /// Indices into `objects` of the lights, and their radiance.
    pub lights: Vec<(u32, DVec3)>,
    /// Indices into `objects` of the occluders.
    pub occluders: Vec<u32>,
    /// Materials of the scene objects, by scene object index.
    pub materials: Vec<Material>,
    /// For light `l` and occluder `o`, at `l * occluders.len() + o`: a plane with the occluder on
    /// its positive side and the light on its negative side, if one exists.
    separations: Vec<Option<Plane>>,
    pub ltc: &'static LtcTable,
    /// Notes for the user (meshes that fell back to the per-face path, intersecting pairs).
    pub notes: Vec<String>,
    /// The scene's bounds with a margin: the box the silhouette trees partition.
    pub bounds: (DVec3, DVec3),
}

/// The trees of precomputed silhouettes of every convex or closed mesh, over `bounds` (and
/// the mesh's own), one mesh per task; meshes over the limits get none.
fn build_silhouette_trees(
    objects: &mut [PreparedObject],
    lights: &[u32],
    bounds: (DVec3, DVec3),
    max_cells: usize,
    max_leaves: usize,
) {
    objects.par_iter_mut().for_each(|o| {
        let (lo, hi) = (
            bounds.0.min(o.poly.center - o.poly.radius),
            bounds.1.max(o.poly.center + o.poly.radius),
        );
        o.bsp = None;
        o.exact_bsp = None;
        o.triangulation = None;
        let d = o.poly.diagnostics;
        if !d.convex && !d.closed_manifold {
            return;
        }
        if !d.convex {
            o.star_centre = star_centre(&o.poly);
        }
        let limit = if d.convex { max_cells } else { max_leaves };
        let key = tree_key(&o.poly, lo, hi, limit, d.convex);
        let tree = tree_cache::load(key, &o.poly).unwrap_or_else(|| {
            let tree = if d.convex {
                SilhouetteBsp::build_convex_limited(&o.poly, lo, hi, max_cells)
                    .map_or(CachedTree::OverLimit, |(t, _)| CachedTree::Convex(t))
            } else {
                let limits = ExactBspLimits {
                    max_leaves,
                    ..ExactBspLimits::default()
                };
                ExactSilhouetteBsp::build(&o.poly, lo, hi, limits)
                    .map_or(CachedTree::OverLimit, |(t, _)| CachedTree::Exact(t))
            };
            tree_cache::store(key, &tree);
            tree
        });
        match tree {
            CachedTree::Convex(t) if d.convex => o.bsp = Some(t),
            CachedTree::Exact(t) if !d.convex => o.exact_bsp = Some(t),
            _ => {}
        }
        // A light that is not star-shaped is sampled through triangulated silhouettes.
        if let (Some(exact), None, true) = (&o.exact_bsp, o.star_centre, lights.contains(&o.object)) {
            let key = key ^ TRIANGULATION_KEY;
            let cached = match tree_cache::load(key, &o.poly) {
                Some(CachedTree::Triangulation(t)) => Some(t),
                _ => None,
            };
            let t = cached.unwrap_or_else(|| {
                let (t, _) =
                    SilhouetteTriangulation::build(&o.poly, exact, TriangulationLimits::default());
                tree_cache::store(key, &CachedTree::Triangulation(t.clone()));
                t
            });
            o.triangulation = Some(t);
        }
    });
}

/// Distinguishes the cache key of a mesh's triangulations from that of its silhouette tree.
const TRIANGULATION_KEY: u64 = 0x7472_6961_6e67_6c65;

impl PreparedScene {
    pub fn new(scene: &Scene) -> Self {
        Self::with_ltc(scene, LtcTable::embedded())
    }

    pub fn with_ltc(scene: &Scene, ltc: &'static LtcTable) -> Self {
        let mut objects = Vec::new();
        let mut lights = Vec::new();
        let mut occluders = Vec::new();
        let mut notes = Vec::new();
        // Every shading point lies on a surface of the scene: its bounds, with a margin.
        let scene_box = scene.objects.iter().filter_map(|o| o.mesh.bounds()).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
        let margin = 1e-3 * (scene_box.1 - scene_box.0).max_element().max(1e-9);
        let scene_box = (scene_box.0 - margin, scene_box.1 + margin);
        for (i, obj) in scene.objects.iter().enumerate() {
            let is_light = obj.flags.light && obj.material.is_emissive();
            if !is_light && !obj.flags.occluder {
                continue;
            }
            let poly = Polyhedron::new(&obj.mesh.positions, &obj.mesh.faces);
            if poly.face_count() == 0 {
                notes.push(format!(
                    "object '{}' has no usable face and is ignored",
                    obj.name
                ));
                continue;
            }
            let simple = poly.has_simple_silhouette();
            if !simple {
                let d = &poly.diagnostics;
                let how = if d.closed_manifold {
                    "it takes its exact silhouette (read from a BSP tree, else computed at the point; \
                     face by face where that is degenerate)"
                } else {
                    "it is handled face by face"
                };
                notes.push(format!(
                    "object '{}' is not convex (closed manifold: {}, boundary edges: {}, non-manifold edges: {}): \
                     {how}",
                    obj.name, d.closed_manifold, d.boundary_edges, d.nonmanifold_edges
                ));
            }
            let id = objects.len() as u32;
            objects.push(PreparedObject {
                object: i as u32,
                name: obj.name.clone(),
                poly,
                simple,
                bsp: None,
                exact_bsp: None,
                star_centre: None,
                triangulation: None,
            });
            if is_light {
                lights.push((id, obj.material.ke));
            }
            if obj.flags.occluder {
                occluders.push(id);
            }
        }
        let light_objects: Vec<u32> = lights.iter().map(|&(l, _)| objects[l as usize].object).collect();
        build_silhouette_trees(
            &mut objects,
            &light_objects,
            scene_box,
            MAX_BSP_CELLS,
            MAX_EXACT_BSP_LEAVES,
        );
        for o in &objects {
            let d = &o.poly.diagnostics;
            if d.convex && o.bsp.is_none() {
                notes.push(format!(
                    "object '{}': its face planes cut the scene into more than {MAX_BSP_CELLS} \
                     cells; its silhouette is computed at each point instead of read from a tree",
                    o.name
                ));
            } else if !d.convex && d.closed_manifold && o.exact_bsp.is_none() {
                notes.push(format!(
                    "object '{}': its tree of precomputed silhouettes would have more than \
                     {MAX_EXACT_BSP_LEAVES} leaves; its exact silhouette is computed at each point",
                    o.name
                ));
            }
        }
        let mut separations = Vec::with_capacity(lights.len() * occluders.len());
        for &(l, _) in &lights {
            for &o in &occluders {
                let plane = if l == o {
                    None
                } else {
                    let p = separating_plane(&objects[o as usize].poly, &objects[l as usize].poly);
                    if p.is_none() {
                        notes.push(format!(
                            "light '{}' and occluder '{}' are not separated by a plane: the occluder is \
                             treated as lying in front of the light",
                            objects[l as usize].name, objects[o as usize].name
                        ));
                    }
                    p
                };
                separations.push(plane);
            }
        }
        let materials = scene.objects.iter().map(|o| o.material.clone()).collect();
        PreparedScene {
            objects,
            lights,
            occluders,
            materials,
            separations,
            ltc,
            notes,
            bounds: scene_box,
        }
    }

    /// Builds the trees of precomputed silhouettes again with other size limits (benchmarks).
    pub fn rebuild_silhouette_trees(&mut self, max_cells: usize, max_leaves: usize) {
        let lights: Vec<u32> = self
            .lights
            .iter()
            .map(|&(l, _)| self.objects[l as usize].object)
            .collect();
        build_silhouette_trees(&mut self.objects, &lights, self.bounds, max_cells, max_leaves);
    }

    /// Forgets the trees of precomputed silhouettes: every silhouette is then computed on the
    /// fly (for benchmarks comparing the two).
    pub fn drop_silhouette_trees(&mut self) {
        for o in &mut self.objects {
            o.bsp = None;
            o.exact_bsp = None;
            o.triangulation = None;
        }
    }

    /// The separating plane of light `l` and occluder `o` (indices into `lights`/`occluders`).
    #[inline]
    pub fn separation(&self, l: usize, o: usize) -> Option<&Plane> {
        self.separations[l * self.occluders.len() + o].as_ref()
    }
}
