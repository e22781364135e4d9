//! The scene as the shading stages need it, computed once per scene: polyhedra with adjacency,
//! which path each mesh takes ([`MeshPath`], with its tree or hull), separating planes of
//! light/occluder pairs, the LTC table, and a report of what preparation found
//! ([`PrepareReport`]).
//!
//! | file | concept |
//! |---|---|
//! | `mesh_path` | the path a mesh takes and the data it reads, decided in one function |
//! | `mesh_forms` | the triangles rays see of a bent mesh, the hull standing in for a nearly convex one |
//! | `instances` | meshes that are affine images of one another share one tree (001 Sect. 5.4) |
//! | `trees` | the trees of precomputed silhouettes, built within the cost model's budget |
//! | `moved` | the prepared scene after one object moved, its trees kept |
//! | `report` | the facts preparation found, and their words |

mod instances;
mod mesh_forms;
mod mesh_path;
mod moved;
mod report;
mod trees;

use instances::instance_groups;
use trees::{build_silhouette_trees, tree_note};

pub use instances::instance_map;
pub use mesh_forms::{FanMesh, StandIn};
pub use mesh_path::{BuiltTree, MeshPath, PathKind, PathTree};
pub use moved::MoveReuse;
pub use report::{NoExactTree, PrepareNote, PrepareReport};
pub use trees::{MAX_BSP_CELLS, MAX_EXACT_BSP_LEAVES, MeshTrees, build_mesh_trees};

use super::cost_model::DEFAULT_EXPECTED_RAYS;
use super::face_sides::{FaceSides, light_face_cut};
use super::tree_cache::{CacheVars, TreeCache};
use super::tree_library::TreeLibrary;
use crate::geometry::{
    ExactSilhouetteBsp, HoistedSilhouetteBsp, IndexedPolyhedron, Plane, SilhouetteBsp,
    SilhouetteTree, SilhouetteTriangulation, separating_plane,
};
use crate::ltc::LtcTable;
use crate::scene::{Material, Scene, SceneObject};
use glam::{DAffine3, DVec3};
use std::ffi::OsStr;
use std::sync::Arc;

/// A light or occluder mesh.
#[derive(Clone, Debug)]
pub struct PreparedObject {
    /// Index of the object in the scene.
    pub object: u32,
    pub name: String,
    /// The mesh as its path reads it: the convex hull when one stands in for the mesh
    /// (`MeshPath::hull`; `PreparedObject::faces` is the mesh's own faces).
    pub poly: IndexedPolyhedron,
    /// How the analytic method finds its spherical polygon, with the tree or hull that path
    /// reads: decided by `MeshPath::decide` whenever the mesh or its trees change.
    pub path: MeshPath,
    /// Maps a world point into the frame of the tree this object shares with its instances
    /// (the world frame of the group's first member); `None` when the tree is in this object's
    /// own frame, so that the lookup takes the point as it is.
    pub to_tree: Option<DAffine3>,
    /// A point strictly inside the kernel of a star-shaped non-convex mesh: its silhouettes
    /// are fanned from there for sampling (001 Sect. 6.1).
    pub star_centre: Option<DVec3>,
    /// Precomputed triangulations of the exact silhouettes of a light that is neither convex
    /// nor star-shaped, proved per cell (001 Sect. 6.2), for sampling; in the tree's frame.
    /// An affine map of positive determinant keeps every orientation sign, so instances share
    /// them with the tree.
    pub triangulation: Option<Arc<SilhouetteTriangulation>>,
    /// The mesh's faces as the triangles rays see, when some face is not planar to the
    /// polyhedron's tolerance (a quad bent by the rounding of its digits): the face-by-face
    /// paths go over these (`PreparedObject::face_pieces`).
    pub fan: Option<FanMesh>,
    /// A light that may go face by face (not convex): where its own mesh lies against each of
    /// its face pieces' cutting planes, so that lighting its own points does not count the
    /// mesh at every face (`face_sides`); `None` for other meshes and over the table's bound.
    pub face_sides: Option<FaceSides>,
}

impl PreparedObject {
    /// The kind of path this mesh takes under the analytic method.
    #[inline]
    pub fn kind(&self) -> PathKind {
        self.path.kind()
    }

    /// Decides the path again for `tree` (or none), keeping the hull that stands in.
    fn set_tree(&mut self, tree: Option<BuiltTree>) {
        let hull = self.path.hull().cloned();
        self.path = MeshPath::decide(&self.poly, hull, tree.map(PathTree::new));
    }

    /// Scene object `index` prepared alone (no tree yet), with what it is noted in `report`;
    /// `None` when it has no usable face.
    fn of(
        index: u32,
        obj: &SceneObject,
        options: &PrepareOptions,
        report: &mut PrepareReport,
    ) -> Option<PreparedObject> {
        let name = || obj.name.clone();
        let mesh = IndexedPolyhedron::new(&obj.mesh.positions, &obj.mesh.faces);
        if mesh.face_count() == 0 {
            report.push(PrepareNote::NoUsableFace { object: name() });
            return None;
        }
        let fan = FanMesh::of(&obj.mesh);
        // Convex as meant but not as written (rounded coordinates): the hull stands in;
        // flat as meant: planar, with its own vertices.
        let planar_as_stored = mesh.diagnostics.planar;
        let rounding = obj.mesh.rounding;
        let (poly, stand_in) = StandIn::of(mesh, rounding);
        if poly.diagnostics.planar && !planar_as_stored {
            report.push(PrepareNote::FlatUpToRounding {
                object: name(),
                rounding,
            });
        }
        // A mesh that takes its exact silhouette (or outline) takes it over the triangles
        // rays see when some face is bent, the very surface its face-by-face path and the
        // ray-cast reference see.
        let mut poly = match &fan {
            Some(f) if stand_in.is_none() && !poly.has_simple_silhouette() => (*f.poly).clone(),
            _ => poly,
        };
        if options.one_ray_per_piece {
            without_vertex_rule(&mut poly);
        }
        if let Some(st) = &stand_in {
            report.push(PrepareNote::ConvexUpToRounding {
                object: name(),
                outside: st.outside,
                rounding,
                hull_faces: poly.face_count(),
                deviation: st.deviation,
            });
        }
        if !poly.has_simple_silhouette() {
            let d = &poly.diagnostics;
            report.push(PrepareNote::NotConvex {
                object: name(),
                closed_manifold: d.closed_manifold,
                boundary_edges: d.boundary_edges,
                nonmanifold_edges: d.nonmanifold_edges,
            });
        }
        Some(PreparedObject {
            object: index,
            name: name(),
            path: MeshPath::decide(&poly, stand_in, None),
            poly,
            to_tree: None,
            star_centre: None,
            triangulation: None,
            fan,
            face_sides: None,
        })
    }

    /// The convex hull standing in for this mesh, if one does.
    #[inline]
    pub fn stand_in(&self) -> Option<&StandIn> {
        self.path.hull()
    }

    /// The tree of face planes of a convex (or flat) mesh, if it reads one.
    pub fn convex_tree(&self) -> Option<&Arc<SilhouetteBsp>> {
        match self.path.tree().map(|t| &t.built) {
            Some(BuiltTree::Convex(t)) => Some(t),
            _ => None,
        }
    }

    /// The tree of exact silhouettes of a non-convex mesh, if it reads one.
    pub fn exact_tree(&self) -> Option<&Arc<ExactSilhouetteBsp>> {
        match self.path.tree().map(|t| &t.built) {
            Some(BuiltTree::Exact(t)) => Some(t),
            _ => None,
        }
    }

    /// The hoisted form of its tree, when shading reads that instead.
    pub fn hoisted_tree(&self) -> Option<&Arc<HoistedSilhouetteBsp>> {
        self.path.tree().and_then(|t| t.hoisted.as_ref())
    }

    /// As a light, where its own mesh lies against each face piece's cutting plane
    /// ([`PreparedObject::face_sides`]); `None` for a convex or flat light, which never goes
    /// face by face against itself.
    fn light_face_sides(&self) -> Option<FaceSides> {
        if self.path.is_simple() {
            return None;
        }
        let pieces = self.face_pieces();
        FaceSides::of(pieces, |f| light_face_cut(pieces, f).front_plane())
    }

    /// The mesh's own faces, also when a hull stands in for it on the silhouette path.
    #[inline]
    pub(crate) fn faces(&self) -> &IndexedPolyhedron {
        self.path.hull().map_or(&self.poly, |s| &s.mesh)
    }

    /// What the face-by-face paths subtract and integrate one by one: the mesh's triangles as
    /// rays see them when some face is bent ([`FanMesh`]), else its faces.
    #[inline]
    pub(crate) fn face_pieces(&self) -> &IndexedPolyhedron {
        self.fan.as_ref().map_or_else(|| self.faces(), |f| &f.poly)
    }

    /// The face of the mesh (`ShadingPoint::face`'s numbering) that piece `g` of
    /// [`PreparedObject::face_pieces`] belongs to.
    #[inline]
    pub(crate) fn piece_face(&self, g: usize) -> u32 {
        self.fan.as_ref().map_or(g as u32, |f| f.face_of[g])
    }

    /// The tree shading reads this mesh's silhouettes from: the hoisted form when present, else
    /// the convex or the exact tree; `None` when the silhouettes are computed at each point.
    /// The debugger draws the tree this names (and the recording says what a lookup in it
    /// found), so that it never shows a tree the renderer did not use.
    #[inline]
    pub fn silhouette_tree(&self) -> Option<&dyn SilhouetteTree> {
        self.path.tree().map(PathTree::lookup)
    }

    /// The point at which to look up this object's tree for the shading point `x`.
    #[inline]
    pub fn tree_point(&self, x: DVec3) -> DVec3 {
        match &self.to_tree {
            None => x,
            Some(t) => t.transform_point3(x),
        }
    }
}

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
    /// What preparation found: each mesh's path and why, trees not built, pairs no plane
    /// separates.
    pub report: PrepareReport,
    /// The scene's bounds with a margin: the box the silhouette trees partition.
    pub bounds: (DVec3, DVec3),
    /// Indices into `objects` of the meshes that share one silhouette tree, one group each
    /// (the first member's frame is the tree's; a mesh without instances is a group of one).
    pub tree_groups: Vec<Vec<u32>>,
    /// How many trees (and sets of triangulations) were built rather than read from the disk
    /// cache or a library.
    pub trees_built: u32,
    /// The disk cache the trees were read from and written to, if any.
    pub cache: Option<TreeCache>,
    share_instances: bool,
    /// [`PrepareConfig::one_ray_per_piece`], kept for the meshes a move prepares again.
    one_ray_per_piece: bool,
}

/// Every shading point lies on a surface of the scene: its bounds, with a margin.
fn scene_box(scene: &Scene) -> (DVec3, DVec3) {
    let scene_box = scene.objects.iter().filter_map(|o| o.mesh.bounds()).fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
    );
    let margin = 1e-3 * (scene_box.1 - scene_box.0).max_element().max(1e-9);
    (scene_box.0 - margin, scene_box.1 + margin)
}

/// Quantitative invisibility off for `poly`: without its vertex stars, its exact silhouettes
/// cast one ray per contour piece (`geometry::silhouettes::contour_pieces`).
fn without_vertex_rule(poly: &mut IndexedPolyhedron) {
    poly.index.vertex_stars = None;
}

/// The names of the objects of a group.
fn names(objects: &[PreparedObject], group: &[u32]) -> Vec<String> {
    group
        .iter()
        .map(|&m| objects[m as usize].name.clone())
        .collect()
}

/// For each light and each occluder, in that order: a plane with the occluder on its positive
/// side and the light on its negative side, if one exists (none for a light and itself).
fn separations(
    objects: &[PreparedObject],
    lights: &[(u32, DVec3)],
    occluders: &[u32],
) -> Vec<Option<Plane>> {
    let mut planes = Vec::with_capacity(lights.len() * occluders.len());
    for &(l, _) in lights {
        for &o in occluders {
            planes.push(
                (l != o)
                    .then(|| separating_plane(&objects[o as usize].poly, &objects[l as usize].poly))
                    .flatten(),
            );
        }
    }
    planes
}

/// The (light, occluder) pairs, other than a light and itself, that no plane separates.
fn unseparated<'a>(
    lights: &'a [(u32, DVec3)],
    occluders: &'a [u32],
    separations: &'a [Option<Plane>],
) -> impl Iterator<Item = (u32, u32)> + 'a {
    let n = occluders.len();
    lights.iter().enumerate().flat_map(move |(li, &(l, _))| {
        occluders
            .iter()
            .enumerate()
            .filter(move |&(oi, &o)| l != o && separations[li * n + oi].is_none())
            .map(move |(_, &o)| (l, o))
    })
}

/// The caller's choices about preparing scenes, for a whole session: where trees are cached,
/// and two switches for measuring. The command line, Python and the workbench's launch read
/// them from their environment (`PENUMBRA_CACHE_DIR`, `PENUMBRA_CACHE_MAX`,
/// `PENUMBRA_HOISTED_TREES`, `PENUMBRA_QI`); the library reads none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PrepareConfig {
    /// The disk cache of trees (`tree_cache`); none by default.
    pub tree_cache: Option<TreeCache>,
    /// Shading reads the hoisted form of every tree (001 Sect. 8; slower lookups, the same
    /// silhouettes), for comparing the two.
    pub hoisted_trees: bool,
    /// Exact silhouettes cast one ray per contour piece instead of carrying counts from piece
    /// to piece (quantitative invisibility off), for measuring what the propagation saves.
    pub one_ray_per_piece: bool,
}

impl PrepareConfig {
    /// The choices the caller's environment names, from the values it read (`None`: unset):
    /// the tree cache `cache` configures, hoisted trees when `hoisted_trees` is `1`, one ray
    /// per piece when `qi` is `off`. A cache bound that is not a size leaves the cache off and
    /// says why (the second value).
    pub fn from_vars(
        cache: &CacheVars,
        hoisted_trees: Option<&OsStr>,
        qi: Option<&OsStr>,
    ) -> (PrepareConfig, Option<String>) {
        let (tree_cache, warning) = match TreeCache::configured(cache) {
            Ok(c) => (c, None),
            Err(e) => (None, Some(format!("the tree cache is not used: {e}"))),
        };
        let config = PrepareConfig {
            tree_cache,
            hoisted_trees: hoisted_trees.is_some_and(|v| v == "1"),
            one_ray_per_piece: qi.is_some_and(|v| v == "off"),
        };
        (config, warning)
    }

    /// The options of a scene prepared with these choices, the rest as
    /// [`PrepareOptions::default`] says.
    pub(crate) fn options(&self) -> PrepareOptions<'_> {
        PrepareOptions {
            cache: self.tree_cache.as_ref(),
            hoisted_trees: self.hoisted_trees,
            one_ray_per_piece: self.one_ray_per_piece,
            ..PrepareOptions::default()
        }
    }
}

/// How a scene is prepared.
#[derive(Clone, Copy, Debug)]
pub struct PrepareOptions<'a> {
    /// Instances of one mesh share one tree (off: each gets its own, in its world frame).
    pub share_instances: bool,
    /// The disk cache trees are read from and written to (`tree_cache`); none for scenes that
    /// are generated and thrown away, and by default.
    pub cache: Option<&'a TreeCache>,
    /// Trees built beforehand: a mesh that is an affine image of one of its meshes reads that
    /// tree instead of building its own.
    pub library: Option<&'a TreeLibrary>,
    /// Build the trees of the meshes the library does not lend (off for scenes shaded at one
    /// point and thrown away, where a tree could never pay for itself: those meshes take the
    /// silhouette computed at the point).
    pub build_trees: bool,
    /// Camera rays the scene is expected to be shaded for: the cost model gives each tree the
    /// budget that this many rays pay for (`cost_model::tree_budget`).
    pub expected_rays: u64,
    /// The scene is lit by an environment light too (more queries per occluder: the cost
    /// model gives its trees more).
    pub environment: bool,
    /// [`PrepareConfig::hoisted_trees`].
    pub hoisted_trees: bool,
    /// [`PrepareConfig::one_ray_per_piece`].
    pub one_ray_per_piece: bool,
    /// The LTC table shading reads (`--ltc-table`).
    pub ltc: &'static LtcTable,
}

impl Default for PrepareOptions<'_> {
    fn default() -> Self {
        PrepareOptions {
            share_instances: true,
            cache: None,
            library: None,
            build_trees: true,
            expected_rays: DEFAULT_EXPECTED_RAYS,
            environment: false,
            hoisted_trees: false,
            one_ray_per_piece: false,
            ltc: LtcTable::embedded(),
        }
    }
}

impl PreparedScene {
    /// `scene` prepared with the default options.
    pub fn new(scene: &Scene) -> Self {
        Self::prepare(scene, PrepareOptions::default())
    }

    /// `scene` prepared with `options`.
    pub fn prepare(scene: &Scene, options: PrepareOptions) -> Self {
        let mut objects = Vec::new();
        let mut lights = Vec::new();
        let mut occluders = Vec::new();
        let mut report = PrepareReport::default();
        let scene_box = scene_box(scene);
        for (i, obj) in scene.objects.iter().enumerate() {
            let is_light = obj.flags.light && obj.material.is_emissive();
            if !is_light && !obj.flags.occluder {
                continue;
            }
            let Some(mut o) = PreparedObject::of(i as u32, obj, &options, &mut report) else {
                continue;
            };
            let id = objects.len() as u32;
            if is_light {
                o.face_sides = o.light_face_sides();
                lights.push((id, obj.material.ke));
            }
            if obj.flags.occluder {
                occluders.push(id);
            }
            objects.push(o);
        }
        let tree_groups = instance_groups(&mut objects, options.share_instances);
        let light_ids: Vec<u32> = lights.iter().map(|&(l, _)| l).collect();
        let cache = options.cache.cloned();
        let (trees_built, budgets) = build_silhouette_trees(
            &mut objects,
            &tree_groups,
            &light_ids,
            scene_box,
            (MAX_BSP_CELLS, MAX_EXACT_BSP_LEAVES),
            cache.as_ref(),
            &options,
        );
        for (g, budget) in tree_groups.iter().zip(&budgets) {
            let attempted = options.build_trees
                || options
                    .library
                    .is_some_and(|l| l.lends_to(&objects[g[0] as usize]));
            if let Some(note) = tree_note(&objects, g, budget, attempted) {
                report.push(note);
            }
        }
        // Per mesh, the path it takes (the notes above say why where it is not the obvious one).
        for o in &objects {
            report.push(PrepareNote::Path {
                object: o.name.clone(),
                faces: o.faces().face_count(),
                path: o.kind(),
            });
        }
        let separations = separations(&objects, &lights, &occluders);
        for (l, o) in unseparated(&lights, &occluders, &separations) {
            report.push(PrepareNote::NotSeparated {
                light: objects[l as usize].name.clone(),
                occluder: objects[o as usize].name.clone(),
            });
        }
        let materials = scene.objects.iter().map(|o| o.material.clone()).collect();
        let mut prepared = PreparedScene {
            objects,
            lights,
            occluders,
            materials,
            separations,
            ltc: options.ltc,
            report,
            bounds: scene_box,
            tree_groups,
            trees_built,
            cache,
            share_instances: options.share_instances,
            one_ray_per_piece: options.one_ray_per_piece,
        };
        if options.hoisted_trees {
            prepared.use_hoisted_trees();
        }
        prepared
    }

    /// Makes shading read the hoisted form of every tree (001 Sect. 8), one per group of
    /// instances; a tree that cannot be hoisted (a point starting two edges of one leaf)
    /// stays leaf-stored, with a note.
    pub fn use_hoisted_trees(&mut self) {
        for g in &self.tree_groups {
            let o = &self.objects[g[0] as usize];
            let hoisted = match o.path.tree().map(|t| &t.built) {
                Some(BuiltTree::Convex(t)) => HoistedSilhouetteBsp::from_convex(t),
                Some(BuiltTree::Exact(t)) => HoistedSilhouetteBsp::from_exact(t),
                None => continue,
            };
            let hoisted = match hoisted {
                Ok(h) => Some(Arc::new(h)),
                Err(e) => {
                    self.report.push(PrepareNote::NotHoisted {
                        objects: names(&self.objects, g),
                        error: e.to_string(),
                    });
                    None
                }
            };
            for &m in g {
                if let Some(t) = self.objects[m as usize].path.tree_mut() {
                    t.hoisted = hoisted.clone();
                }
            }
        }
    }

    /// Builds the trees of precomputed silhouettes again with other size limits (benchmarks).
    pub(crate) fn rebuild_silhouette_trees(&mut self, max_cells: usize, max_leaves: usize) {
        let light_ids: Vec<u32> = self.lights.iter().map(|&(l, _)| l).collect();
        // The maps into a library's frame are forgotten with the library.
        self.tree_groups = instance_groups(&mut self.objects, self.share_instances);
        // The limits asked for, not the cost model's budget.
        let options = PrepareOptions {
            expected_rays: u64::MAX,
            ..PrepareOptions::default()
        };
        (self.trees_built, _) = build_silhouette_trees(
            &mut self.objects,
            &self.tree_groups,
            &light_ids,
            self.bounds,
            (max_cells, max_leaves),
            self.cache.as_ref(),
            &options,
        );
    }

    /// Forgets the trees of precomputed silhouettes: every silhouette is then computed on the
    /// fly (for benchmarks comparing the two).
    pub fn drop_silhouette_trees(&mut self) {
        for o in &mut self.objects {
            o.set_tree(None);
            o.triangulation = None;
        }
    }

    /// Whether some occluder other than light `l` itself (index into `lights`) has no plane
    /// separating it from the light: the light is then shaded face by face.
    #[inline]
    pub(crate) fn light_is_crossed(&self, l: usize) -> bool {
        let n = self.occluders.len();
        let light = self.lights[l].0;
        (0..n).any(|o| self.occluders[o] != light && self.separations[l * n + o].is_none())
    }

    /// Whether the points of a tile can share work with `method`: some occluder's outline is
    /// found inside the light's window through an edge hierarchy (`geometry::silhouettes::tile_candidates`).
    pub(crate) fn tiles_share_candidates(&self, method: super::Method) -> bool {
        method == super::Method::Analytic
            && self.occluders.iter().any(|&o| {
                let obj = &self.objects[o as usize];
                obj.kind().is_windowed() && obj.poly.index.edge_hierarchy.is_some()
            })
    }

    /// The separating plane of light `l` and occluder `o` (indices into `lights`/`occluders`).
    #[inline]
    pub(crate) fn separation(&self, l: usize, o: usize) -> Option<&Plane> {
        self.separations[l * self.occluders.len() + o].as_ref()
    }
}
