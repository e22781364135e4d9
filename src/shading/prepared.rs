//! The scene as the shading stages need it, computed once per scene: polyhedra with adjacency,
//! which path each mesh takes, separating planes of light/occluder pairs, the LTC table.

use crate::geometry::{Plane, Polyhedron, SilhouetteBsp, separating_plane};
use crate::ltc::LtcTable;
use crate::scene::{Material, Scene};
use glam::DVec3;

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
}

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
}

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
                    "its exact silhouette is computed at each point (face by face where that \
                     is degenerate)"
                } else {
                    "it is handled face by face"
                };
                notes.push(format!(
                    "object '{}' is not convex (closed manifold: {}, boundary edges: {}, non-manifold edges: {}): \
                     {how}",
                    obj.name, d.closed_manifold, d.boundary_edges, d.nonmanifold_edges
                ));
            }
            let bsp = poly
                .diagnostics
                .convex
                .then(|| {
                    let (lo, hi) = scene_box;
                    SilhouetteBsp::build_convex_limited(
                        &poly,
                        lo.min(poly.center - poly.radius),
                        hi.max(poly.center + poly.radius),
                        MAX_BSP_CELLS,
                    )
                    .map(|(t, _)| t)
                })
                .flatten();
            let id = objects.len() as u32;
            objects.push(PreparedObject {
                object: i as u32,
                name: obj.name.clone(),
                poly,
                simple,
                bsp,
            });
            if is_light {
                lights.push((id, obj.material.ke));
            }
            if obj.flags.occluder {
                occluders.push(id);
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
        }
    }

    /// The separating plane of light `l` and occluder `o` (indices into `lights`/`occluders`).
    #[inline]
    pub fn separation(&self, l: usize, o: usize) -> Option<&Plane> {
        self.separations[l * self.occluders.len() + o].as_ref()
    }
}
