//! The scene as the shading stages need it, computed once per scene: polyhedra with adjacency,
//! which path each mesh takes, separating planes of light/occluder pairs, the LTC table.
//!
//! Instances (001 Sect. 5.4: "multiple light sources can share the same buffers"): meshes with
//! the same faces whose vertices are one affine map (positive determinant) of another's share
//! one tree of precomputed silhouettes, built in the frame of the group's first member. Every
//! plane of the tree is a face plane, a three-endpoint plane or a validation split, and every
//! test it makes is the side of such a plane, i.e. the sign of det(a − x, b − x, c − x) for
//! points a, b, c of the mesh; an affine map `M` with det M > 0 multiplies that determinant by
//! det M, so `x` and `M x` fall in corresponding cells. What a leaf stores (vertex indices and
//! pairs of edges that appear to cross) is made of incidences and orientations, which `M`
//! preserves too, so it is the same for every instance: shading maps the point into the
//! tree's frame for the lookup and reads the silhouette off the instance's own vertices. This
//! covers rotations, uniform and non-uniform scales (a sheared or squashed copy has the same
//! silhouette structure from the corresponding point); mirror images (det M < 0) reverse the
//! orientations and are not shared.

use super::cost_model::{DEFAULT_EXPECTED_RAYS, MeshCostClass, TreeBudget, tree_budget};
use super::face_sides::{FaceSides, light_face_cut};
use super::tree_cache::{CachedTree, TreeCache, tree_key};
use super::tree_library::{LibraryEntry, TreeLibrary};
use crate::geometry::bsp::face_planes_exceed;
use crate::geometry::{
    EDGE_PAIRS_MAX_EDGES, ExactBspLimits, ExactSilhouetteBsp, HoistedSilhouetteBsp,
    IndexedPolyhedron, Plane, PointCoding, Polyhedron, SilhouetteBsp, SilhouetteTree,
    SilhouetteTriangulation, TriangulationLimits, convex_stand_in, flat_up_to_rounding,
    separating_plane, solid_angle_bound, star_centre,
};
use crate::ltc::LtcTable;
use crate::scene::{Material, Scene};
use glam::{DAffine3, DMat3, DVec3};
use rayon::prelude::*;
use std::sync::Arc;

/// A light or occluder mesh.
#[derive(Clone, Debug)]
pub struct PreparedObject {
    /// Index of the object in the scene.
    pub object: u32,
    pub name: String,
    pub poly: IndexedPolyhedron,
    /// Takes the silhouette path (convex closed or flat); otherwise per face.
    pub simple: bool,
    /// Precomputed silhouettes of a convex mesh over the scene's bounds (001 Sect. 5.1), in
    /// the frame `to_tree` maps into (shared by the instances of this mesh).
    pub bsp: Option<Arc<SilhouetteBsp>>,
    /// Precomputed exact silhouettes of a closed non-convex mesh (001 Sect. 5.2), likewise.
    pub exact_bsp: Option<Arc<ExactSilhouetteBsp>>,
    /// The same tree with each edge stored as high as it stays valid (001 Sect. 8,
    /// `geometry::bsp_hoisted`); when present, shading reads it instead of `bsp`/`exact_bsp`.
    /// Not the default (slower lookups, docs/silhouettes.md): [`PreparedScene::use_hoisted_trees`]
    /// or `PENUMBRA_HOISTED_TREES=1`.
    pub hoisted: Option<Arc<HoistedSilhouetteBsp>>,
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
    /// Set when `poly` is the convex hull standing in for a mesh that is convex up to the
    /// precision of its input (`geometry::near_convex`): how far the hull may be from it.
    pub stand_in: Option<StandIn>,
    /// The mesh's faces as the triangles rays see, when some face is not planar to the
    /// polyhedron's tolerance (a quad bent by the rounding of its digits): the face-by-face
    /// paths go over these ([`PreparedObject::face_pieces`]).
    pub fan: Option<FanMesh>,
    /// A light that may go face by face (not convex): where its own mesh lies against each of
    /// its face pieces' cutting planes, so that lighting its own points does not count the
    /// mesh at every face (`face_sides`); `None` for other meshes and over the table's bound.
    pub face_sides: Option<FaceSides>,
}

/// A mesh's faces as the triangles every ray sees (each face fanned from its first vertex,
/// `Mesh::triangles`, as the BVH and the ray-cast reference take them). The face-by-face paths
/// subtract and integrate these when some face of the mesh is bent, even only by the rounding
/// of its digits: seen nearly edge-on, a bent face's image folds into a bow tie, which the set
/// difference cannot take; a triangle's never does.
#[derive(Clone, Debug)]
pub struct FanMesh {
    pub poly: Arc<IndexedPolyhedron>,
    /// The face of the mesh each triangle comes from.
    pub face_of: Vec<u32>,
}

impl FanMesh {
    /// The fan of `mesh`; `None` when every face of it is planar to the polyhedron's tolerance
    /// (1e-9 of its bounding radius, as `Polyhedron::new` judges; the faces are then their own
    /// pieces).
    pub fn of(mesh: &crate::scene::Mesh) -> Option<FanMesh> {
        let p = |i: u32| mesh.positions[i as usize];
        let (_, radius) = mesh.bounding_sphere();
        let tol = 1e-9 * radius.max(f64::MIN_POSITIVE);
        let bent = mesh.faces.iter().any(|f| {
            f.len() > 3 && {
                let pts: Vec<DVec3> = f.iter().map(|&i| p(i)).collect();
                crate::scene::precision::plane_deviation(&pts) > tol
            }
        });
        if !bent {
            return None;
        }
        let mut faces = Vec::new();
        let mut face_of = Vec::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            for k in 1..face.len().saturating_sub(1) {
                let t = [face[0], face[k], face[k + 1]];
                if crate::accel::is_degenerate(p(t[0]), p(t[1]), p(t[2])) {
                    continue;
                }
                faces.push(t.to_vec());
                face_of.push(f as u32);
            }
        }
        let fan = IndexedPolyhedron::new(&mesh.positions, &faces);
        (fan.face_count() == face_of.len()).then(|| FanMesh {
            poly: Arc::new(fan),
            face_of,
        })
    }
}

/// What replacing a mesh by its convex hull changes (`geometry::near_convex`).
#[derive(Clone, Debug)]
pub struct StandIn {
    /// The mesh itself: the face-by-face paths (the per-triangle method) go over its faces.
    pub mesh: Arc<IndexedPolyhedron>,
    /// Every point of the hull is within this distance of the mesh.
    pub deviation: f64,
    /// The farthest a vertex of the mesh lies outside the plane of one of its faces.
    pub outside: f64,
    /// The mesh's own vertex and face counts.
    pub mesh_vertices: usize,
    pub mesh_faces: usize,
}

impl StandIn {
    /// The polyhedron to prepare for `mesh`: its convex hull when the mesh is convex up to
    /// `rounding` (with the stand-in's record), else the mesh itself. The one place that
    /// decides it, for a first preparation and after a move alike.
    ///
    /// A mesh flat up to `rounding` (`geometry::near_convex::flat_up_to_rounding`) is
    /// classified planar instead, with no stand-in: it keeps its own vertices, and its faces
    /// tile its outline's image exactly.
    pub fn of(mut mesh: IndexedPolyhedron, rounding: f64) -> (IndexedPolyhedron, Option<StandIn>) {
        if flat_up_to_rounding(&mesh, rounding).is_some() {
            mesh.mesh.diagnostics.planar = true;
            return (mesh, None);
        }
        match convex_stand_in(&mesh, rounding) {
            Some(s) => {
                let stand_in = StandIn {
                    mesh_vertices: mesh.vertices.len(),
                    mesh_faces: mesh.face_count(),
                    mesh: Arc::new(mesh),
                    deviation: s.deviation,
                    outside: s.outside,
                };
                (s.hull.into(), Some(stand_in))
            }
            None => (mesh, None),
        }
    }

    /// The largest change of solid angle from a point at `distance` from the hull.
    pub fn solid_angle_bound(&self, distance: f64) -> f64 {
        solid_angle_bound(self.deviation, distance)
    }
}

/// Closed non-convex meshes without a tree and with at least this many faces compute their
/// silhouette as occluders inside each light's window only.
pub const WINDOWED_MIN_FACES: usize = 64;

/// Non-convex meshes whose tree would have more leaves than this keep computing their exact
/// silhouette on the fly.
pub const MAX_EXACT_BSP_LEAVES: usize = 200_000;

/// The same bound for an open mesh's tree, whose leaves cost more to build (stage 2 has more
/// pairs, and every cell is validated at its corners and at its faces' and edges' middles):
/// a tree that does not fit stays unbuilt, so that a failed attempt costs milliseconds of a
/// cold start. Measured on a fuzzed scene with a 27-face and a 92-face open mesh: the
/// preparation took 0.00 s without open trees, 37.6 s with the closed meshes' bound of
/// 200,000 leaves (both attempts failing), 12.5 s at 20,000 and 0.01 s at this bound.
pub const MAX_OPEN_BSP_LEAVES: usize = 2_000;

/// Convex meshes whose face planes cut the scene into more cells than this keep computing
/// their silhouette on the fly (the count grows with the cube of the face count).
pub const MAX_BSP_CELLS: usize = 50_000;

/// Relative tolerance (of the mesh's radius) within which an instance's vertices must be the
/// affine image of the first member's: far below the trees' own tolerances (1e-9 · radius),
/// far above the rounding of a scene file's scale, rotate and translate.
pub const INSTANCE_TOLERANCE: f64 = 1e-10;

/// How the analytic method finds a mesh's spherical polygon at a shading point, decided once
/// when the scene is prepared (docs/silhouettes.md, "Which path a mesh takes").
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MeshPath {
    /// Convex or flat: one silhouette loop, read from the mesh's tree of face planes.
    ConvexTree,
    /// Convex up to the rounding of its coordinates: its convex hull stands in for it.
    HullTree,
    /// As `HullTree`, over the tree's size limit: the hull's silhouette chained at each point.
    HullAtPoint,
    /// Convex or flat, over the tree's size limit: the silhouette chained at each point.
    ConvexAtPoint,
    /// Closed, not convex: the exact silhouette, read from its tree.
    ExactTree,
    /// Closed, not convex, over the tree's size limit: the exact silhouette at each point.
    ExactAtPoint,
    /// As `ExactAtPoint` for a large mesh (at least [`WINDOWED_MIN_FACES`] faces): as an
    /// occluder, only the part of its exact silhouette inside the light's polygon is computed
    /// (`geometry::windowed_silhouette`), from the faces the light's cone meets.
    ExactInWindow,
    /// Open (boundary edges) but an oriented manifold: as an occluder, the exact outline of its
    /// image from its contour and boundary edges at each point (docs/silhouettes.md, "Open
    /// meshes"); as a light, face by face, since it emits from the front of its faces only and
    /// its outline also covers back faces seen through its opening.
    OpenAtPoint,
    /// As `OpenAtPoint` for a large mesh (at least [`WINDOWED_MIN_FACES`] faces): as an
    /// occluder, only the part of its outline inside the light's polygon is computed.
    OpenInWindow,
    /// As `OpenAtPoint`, the outline read from its tree (the exact-silhouette tree, whose
    /// leaves hold the outline of contour and boundary edges, 001 Sect. 5.2).
    OpenTree,
    /// Non-manifold: face by face.
    PerFace,
}

impl MeshPath {
    /// As an occluder, the outline is computed inside each light's polygon only.
    pub fn is_windowed(self) -> bool {
        matches!(self, MeshPath::ExactInWindow | MeshPath::OpenInWindow)
    }

    /// An open mesh: as a light, face by face.
    pub fn is_open(self) -> bool {
        matches!(
            self,
            MeshPath::OpenAtPoint | MeshPath::OpenInWindow | MeshPath::OpenTree
        )
    }

    /// A few words for a table.
    pub fn label(self) -> &'static str {
        match self {
            MeshPath::ConvexTree => "convex, BSP",
            MeshPath::ConvexAtPoint => "convex",
            MeshPath::HullTree => "hull, BSP",
            MeshPath::HullAtPoint => "hull",
            MeshPath::ExactTree => "non-convex, BSP",
            MeshPath::ExactAtPoint => "non-convex (exact)",
            MeshPath::ExactInWindow => "non-convex, large (exact, windowed)",
            MeshPath::OpenAtPoint => "open (exact outline)",
            MeshPath::OpenInWindow => "open, large (exact outline, windowed)",
            MeshPath::OpenTree => "open, BSP (exact outline)",
            MeshPath::PerFace => "non-manifold (per face)",
        }
    }

    /// The path in the words of the scene notes.
    pub fn describe(self) -> &'static str {
        match self {
            MeshPath::ConvexTree => "convex: silhouette from its BSP tree",
            MeshPath::ConvexAtPoint => "convex: silhouette chained at each point",
            MeshPath::HullTree => "convex up to rounding: its hull's silhouette from a BSP tree",
            MeshPath::HullAtPoint => {
                "convex up to rounding: its hull's silhouette chained at each point"
            }
            MeshPath::ExactTree => "not convex: exact silhouette from its BSP tree",
            MeshPath::ExactAtPoint => "not convex: exact silhouette computed at each point",
            MeshPath::ExactInWindow => {
                "not convex, large: exact silhouette computed at each point, as an occluder only \
                 inside each light's polygon"
            }
            MeshPath::OpenAtPoint => {
                "open: as an occluder, the exact outline of contour and boundary edges computed \
                 at each point; as a light, face by face"
            }
            MeshPath::OpenInWindow => {
                "open, large: as an occluder, the exact outline of contour and boundary edges \
                 computed at each point, only inside each light's polygon; as a light, face by \
                 face"
            }
            MeshPath::OpenTree => {
                "open: as an occluder, the exact outline of contour and boundary edges from its \
                 BSP tree; as a light, face by face"
            }
            MeshPath::PerFace => "non-manifold: face by face",
        }
    }
}

impl PreparedObject {
    /// The path this mesh takes under the analytic method.
    pub fn path(&self) -> MeshPath {
        let has_tree = self.bsp.is_some() || self.exact_bsp.is_some() || self.hoisted.is_some();
        match (self.simple, self.poly.diagnostics.closed_manifold, has_tree) {
            (true, _, true) if self.stand_in.is_some() => MeshPath::HullTree,
            (true, _, false) if self.stand_in.is_some() => MeshPath::HullAtPoint,
            (true, _, true) => MeshPath::ConvexTree,
            (true, _, false) => MeshPath::ConvexAtPoint,
            (false, true, true) => MeshPath::ExactTree,
            (false, true, false)
                if self.poly.face_count() >= WINDOWED_MIN_FACES
                    && self.poly.index.face_bvh.is_some() =>
            {
                MeshPath::ExactInWindow
            }
            (false, true, false) => MeshPath::ExactAtPoint,
            (false, false, true) if self.poly.diagnostics.nonmanifold_edges == 0 => {
                MeshPath::OpenTree
            }
            (false, false, _) if self.poly.diagnostics.nonmanifold_edges == 0 => {
                if self.poly.face_count() >= WINDOWED_MIN_FACES
                    && self.poly.index.face_bvh.is_some()
                {
                    MeshPath::OpenInWindow
                } else {
                    MeshPath::OpenAtPoint
                }
            }
            (false, false, _) => MeshPath::PerFace,
        }
    }

    /// As a light, where its own mesh lies against each face piece's cutting plane
    /// ([`PreparedObject::face_sides`]); `None` for a convex or flat light, which never goes
    /// face by face against itself.
    fn light_face_sides(&self) -> Option<FaceSides> {
        if self.simple {
            return None;
        }
        let pieces = self.face_pieces();
        FaceSides::of(pieces, |f| light_face_cut(pieces, f))
    }

    /// The mesh's own faces, also when a hull stands in for it on the silhouette path.
    #[inline]
    pub fn faces(&self) -> &IndexedPolyhedron {
        self.stand_in.as_ref().map_or(&self.poly, |s| &s.mesh)
    }

    /// What the face-by-face paths subtract and integrate one by one: the mesh's triangles as
    /// rays see them when some face is bent ([`FanMesh`]), else its faces.
    #[inline]
    pub fn face_pieces(&self) -> &IndexedPolyhedron {
        self.fan.as_ref().map_or_else(|| self.faces(), |f| &f.poly)
    }

    /// The face of the mesh (`ShadingPoint::face`'s numbering) that piece `g` of
    /// [`PreparedObject::face_pieces`] belongs to.
    #[inline]
    pub fn piece_face(&self, g: usize) -> u32 {
        self.fan.as_ref().map_or(g as u32, |f| f.face_of[g])
    }

    /// The tree shading reads this mesh's silhouettes from: the hoisted form when present, else
    /// the convex or the exact tree; `None` when the silhouettes are computed at each point.
    /// The debugger draws the tree this names (and the recording says what a lookup in it
    /// found), so that it never shows a tree the renderer did not use.
    #[inline]
    pub fn silhouette_tree(&self) -> Option<&dyn SilhouetteTree> {
        if let Some(h) = &self.hoisted {
            return Some(h.as_ref());
        }
        match (&self.bsp, &self.exact_bsp) {
            (Some(t), _) => Some(t.as_ref()),
            (None, Some(t)) => Some(t.as_ref()),
            (None, None) => None,
        }
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

/// The affine map `M` (det M > 0) with `other.vertices[k] = M(base.vertices[k])` for every `k`
/// within [`INSTANCE_TOLERANCE`], if `other` has the same faces (vertex indices) as `base`.
/// `M` is solved from four vertices of `base` spanning a tetrahedron of large volume and then
/// verified on all vertices; flat meshes (no such tetrahedron) are not matched.
pub fn instance_map(base: &Polyhedron, other: &Polyhedron) -> Option<DAffine3> {
    let same_faces = base.vertices.len() == other.vertices.len()
        && base.face_indices == other.face_indices
        && base.face_starts == other.face_starts
        && base.edges == other.edges
        && base.diagnostics.convex == other.diagnostics.convex
        && base.diagnostics.closed_manifold == other.diagnostics.closed_manifold;
    if !same_faces || base.vertices.is_empty() {
        return None;
    }
    let p = &base.vertices;
    let q = &other.vertices;
    let argmax =
        |f: &dyn Fn(DVec3) -> f64| (0..p.len()).max_by(|&a, &b| f(p[a]).total_cmp(&f(p[b])));
    let i0 = 0;
    let i1 = argmax(&|v| v.distance_squared(p[i0]))?;
    let u = p[i1] - p[i0];
    let i2 = argmax(&|v| u.cross(v - p[i0]).length_squared())?;
    let n = u.cross(p[i2] - p[i0]);
    let i3 = argmax(&|v| n.dot(v - p[i0]).abs())?;
    let pm = DMat3::from_cols(u, p[i2] - p[i0], p[i3] - p[i0]);
    let r = base.radius.max(f64::MIN_POSITIVE);
    // A tetrahedron this thin would amplify rounding in the solve beyond the tolerance.
    if pm.determinant().abs() <= 1e-6 * r * r * r {
        return None;
    }
    let qm = DMat3::from_cols(q[i1] - q[i0], q[i2] - q[i0], q[i3] - q[i0]);
    let a = qm * pm.inverse();
    if !a.is_finite() || a.determinant() <= 0.0 {
        return None;
    }
    let m = DAffine3::from_mat3_translation(a, q[i0] - a * p[i0]);
    let tol = INSTANCE_TOLERANCE * other.radius.max(f64::MIN_POSITIVE);
    p.iter()
        .zip(q)
        .all(|(&a, &b)| m.transform_point3(a).distance(b) <= tol)
        .then_some(m)
}

/// Groups of objects that share one tree: the first member's frame is the tree's; every other
/// member gets its `to_tree` map. Only objects that can have a tree (convex, or manifold:
/// closed or open) are grouped; with `share` false every such object is its own group.
fn instance_groups(objects: &mut [PreparedObject], share: bool) -> Vec<Vec<u32>> {
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for i in 0..objects.len() {
        objects[i].to_tree = None;
        let d = objects[i].poly.diagnostics;
        // Convex, closed, or open but manifold and not flat (a flat mesh chains its outline).
        let open_tree = d.nonmanifold_edges == 0 && !d.planar;
        if !d.convex && !d.closed_manifold && !open_tree {
            continue;
        }
        let found = share
            .then(|| {
                groups.iter().position(|g| {
                    let base = &objects[g[0] as usize].poly;
                    match instance_map(base, &objects[i].poly) {
                        Some(m) => {
                            objects[i].to_tree = Some(m.inverse());
                            true
                        }
                        None => false,
                    }
                })
            })
            .flatten();
        match found {
            Some(g) => groups[g].push(i as u32),
            None => groups.push(vec![i as u32]),
        }
    }
    groups
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
    /// Notes for the user (meshes that fell back to the per-face path, intersecting pairs).
    pub notes: Vec<String>,
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
}

/// The trees one mesh (or group of instances) reads: its tree of precomputed silhouettes, if
/// it got one, and, for a light that is neither convex nor star-shaped, the per-cell
/// triangulations of its silhouettes.
#[derive(Clone, Debug, Default)]
pub struct MeshTrees {
    pub bsp: Option<Arc<SilhouetteBsp>>,
    pub exact_bsp: Option<Arc<ExactSilhouetteBsp>>,
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
    let (bsp, exact_bsp) = match tree {
        CachedTree::Convex(t) if d.convex => (Some(Arc::new(t)), None),
        CachedTree::Exact(t) if !d.convex => (None, Some(Arc::new(t))),
        _ => (None, None),
    };
    MeshTrees {
        bsp,
        exact_bsp,
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
fn build_silhouette_trees(
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
        o.bsp = None;
        o.exact_bsp = None;
        o.hoisted = None;
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
            o.bsp = t.bsp.clone();
            o.exact_bsp = t.exact_bsp.clone();
            o.triangulation = t.triangulation.clone();
        }
    }
    (built, budgets)
}

/// Why a tree's budget is what it is, when the cost model (not the hard limit) set it.
fn budget_words(budget: &Option<TreeBudget>, limit: usize, units: &str) -> String {
    match budget {
        Some(b) if b.units < limit => format!(
            " (the cost model: at about {:.0} queries a tree saves about {:.2} s, which pays for \
             at most {} {units})",
            b.queries, b.saving_seconds, b.units
        ),
        _ => String::new(),
    }
}

/// Distinguishes the cache key of a mesh's triangulations from that of its silhouette tree.
const TRIANGULATION_KEY: u64 = 0x7472_6961_6e67_6c65;

/// `'a', 'b', 'c'`.
fn quoted_names(objects: &[PreparedObject], group: &[u32]) -> String {
    let names: Vec<String> = group
        .iter()
        .map(|&m| format!("'{}'", objects[m as usize].name))
        .collect();
    names.join(", ")
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

/// What [`PreparedScene::with_moved_object`] reused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MoveReuse {
    /// The object is neither a light nor an occluder: nothing of it is prepared.
    #[default]
    NotPrepared,
    /// Its trees (and hull, star centre, triangulations) were kept, under a new map into
    /// the trees' frame.
    Trees,
    /// It had no tree; its mesh data were prepared again (`Polyhedron::new`).
    NoTree,
    /// Its new vertices are not an affine image (positive determinant) of its old ones: it
    /// was prepared alone, without trees (its silhouette is computed at each point).
    Alone,
}

/// How a scene is prepared.
#[derive(Clone, Copy, Debug)]
pub struct PrepareOptions<'a> {
    /// Instances of one mesh share one tree (off: each gets its own, in its world frame).
    pub share_instances: bool,
    /// Trees are read from and written to the disk cache (`tree_cache`); off for scenes that
    /// are generated and thrown away.
    pub disk_cache: bool,
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
}

impl Default for PrepareOptions<'_> {
    fn default() -> Self {
        PrepareOptions {
            share_instances: true,
            disk_cache: true,
            library: None,
            build_trees: true,
            expected_rays: DEFAULT_EXPECTED_RAYS,
            environment: false,
        }
    }
}

impl PreparedScene {
    pub fn new(scene: &Scene) -> Self {
        Self::with_ltc(scene, LtcTable::embedded())
    }

    pub fn with_ltc(scene: &Scene, ltc: &'static LtcTable) -> Self {
        Self::prepare(scene, ltc, PrepareOptions::default())
    }

    /// [`PreparedScene::with_ltc`]; with `share_trees` false, instances of one mesh do not
    /// share a tree: each gets its own, built in its world frame (tests, benchmarks).
    pub fn with_options(scene: &Scene, ltc: &'static LtcTable, share_trees: bool) -> Self {
        let options = PrepareOptions {
            share_instances: share_trees,
            ..PrepareOptions::default()
        };
        Self::prepare(scene, ltc, options)
    }

    pub fn prepare(scene: &Scene, ltc: &'static LtcTable, options: PrepareOptions) -> Self {
        let mut objects = Vec::new();
        let mut lights = Vec::new();
        let mut occluders = Vec::new();
        let mut notes = Vec::new();
        let scene_box = scene_box(scene);
        for (i, obj) in scene.objects.iter().enumerate() {
            let is_light = obj.flags.light && obj.material.is_emissive();
            if !is_light && !obj.flags.occluder {
                continue;
            }
            let mesh = IndexedPolyhedron::new(&obj.mesh.positions, &obj.mesh.faces);
            if mesh.face_count() == 0 {
                notes.push(format!(
                    "object '{}' has no usable face and is ignored",
                    obj.name
                ));
                continue;
            }
            let fan = FanMesh::of(&obj.mesh);
            // Convex as meant but not as written (rounded coordinates): the hull stands in;
            // flat as meant: planar, with its own vertices.
            let planar_as_stored = mesh.diagnostics.planar;
            let (poly, stand_in) = StandIn::of(mesh, obj.mesh.rounding);
            if poly.diagnostics.planar && !planar_as_stored {
                notes.push(format!(
                    "object '{}' is flat up to the rounding of its coordinates (rounding {:.2e}): \
                     its faces tile one polygon, whose outline it takes as a light and as an \
                     occluder",
                    obj.name, obj.mesh.rounding
                ));
            }
            // A mesh that takes its exact silhouette (or outline) takes it over the triangles
            // rays see when some face is bent, the very surface its face-by-face path and the
            // ray-cast reference see.
            let poly = match &fan {
                Some(f) if stand_in.is_none() && !poly.has_simple_silhouette() => (*f.poly).clone(),
                _ => poly,
            };
            if let Some(st) = &stand_in {
                notes.push(format!(
                    "object '{}' is convex up to the rounding of its coordinates (vertices at \
                         most {:.2e} outside its faces' planes, rounding {:.2e}): its convex hull \
                         ({} faces) stands in for it, within {:.2e} of it; the solid angle it \
                         subtends from a point at distance d changes by at most about 2π·{:.2e}/d",
                    obj.name,
                    st.outside,
                    obj.mesh.rounding,
                    poly.face_count(),
                    st.deviation,
                    st.deviation
                ));
            }
            let simple = poly.has_simple_silhouette();
            if !simple {
                let d = &poly.diagnostics;
                let how = if d.closed_manifold {
                    "it takes its exact silhouette (read from a BSP tree, else computed at the point; \
                     face by face where that is degenerate)"
                } else if d.nonmanifold_edges == 0 {
                    "as an occluder it takes the exact outline of its contour and boundary edges \
                     (read from a BSP tree, else computed at the point; face by face where that is degenerate), as a light \
                     it is handled face by face"
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
                to_tree: None,
                hoisted: None,
                star_centre: None,
                triangulation: None,
                stand_in,
                fan,
                face_sides: None,
            });
            if is_light {
                let o = objects.last_mut().expect("just pushed");
                o.face_sides = o.light_face_sides();
            }
            if is_light {
                lights.push((id, obj.material.ke));
            }
            if obj.flags.occluder {
                occluders.push(id);
            }
        }
        let tree_groups = instance_groups(&mut objects, options.share_instances);
        let light_ids: Vec<u32> = lights.iter().map(|&(l, _)| l).collect();
        let cache = if options.disk_cache {
            TreeCache::from_env().unwrap_or_else(|e| {
                notes.push(format!("the tree cache is not used: {e}"));
                None
            })
        } else {
            None
        };
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
            let o = &objects[g[0] as usize];
            let d = &o.poly.diagnostics;
            let names = quoted_names(&objects, g);
            let (subject, its) = if g.len() > 1 {
                (format!("objects {names}"), "their")
            } else {
                (format!("object {names}"), "its")
            };
            let attempted = options.build_trees || options.library.is_some_and(|l| l.lends_to(o));
            if !attempted {
                notes.push(format!(
                    "{subject}: no tree of precomputed silhouettes is built for this scene; \
                     {its} silhouette is computed at each point"
                ));
            } else if d.convex && o.bsp.is_none() {
                notes.push(format!(
                    "{subject}: {its} face planes cut the scene into more than {} cells; {its} \
                     silhouette is computed at each point instead of read from a tree{}",
                    budget.map_or(MAX_BSP_CELLS, |b| b.units),
                    budget_words(budget, MAX_BSP_CELLS, "cells")
                ));
            } else if !d.convex && o.exact_bsp.is_none() {
                let why = if PointCoding::for_mesh(&o.poly).is_none() {
                    format!(
                        "mesh has more than {EDGE_PAIRS_MAX_EDGES} edges, too many for a \
                         tree of precomputed silhouettes"
                    )
                } else if budget.is_some_and(|b| b.saving_seconds == 0.0) {
                    "silhouette inside each light's window costs less than reading the whole \
                     one from a tree of precomputed silhouettes (the cost model), so it gets \
                     no tree"
                        .to_string()
                } else {
                    format!(
                        "tree of precomputed silhouettes would have more than {} leaves{}",
                        budget.map_or(MAX_EXACT_BSP_LEAVES, |b| b.units),
                        budget_words(budget, MAX_EXACT_BSP_LEAVES, "leaves")
                    )
                };
                notes.push(format!(
                    "{subject}: {its} {why}; {its} exact silhouette is computed at each point"
                ));
            } else if g.len() > 1 {
                notes.push(format!(
                    "objects {names} are instances of one mesh and share one silhouette tree \
                     (built in the frame of '{}')",
                    o.name
                ));
            }
        }
        // Per mesh, the path it takes (the notes above say why where it is not the obvious one).
        for o in &objects {
            notes.push(format!(
                "object '{}' ({} faces): {}",
                o.name,
                o.faces().face_count(),
                o.path().describe()
            ));
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
                            "light '{}' and occluder '{}' are not separated by a plane: the light is \
                             taken face by face, each face cutting the occluder at its plane",
                            objects[l as usize].name, objects[o as usize].name
                        ));
                    }
                    p
                };
                separations.push(plane);
            }
        }
        let materials = scene.objects.iter().map(|o| o.material.clone()).collect();
        let mut prepared = PreparedScene {
            objects,
            lights,
            occluders,
            materials,
            separations,
            ltc,
            notes,
            bounds: scene_box,
            tree_groups,
            trees_built,
            cache,
            share_instances: options.share_instances,
        };
        if std::env::var_os("PENUMBRA_HOISTED_TREES").is_some_and(|v| v == "1") {
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
            let hoisted = match (&o.bsp, &o.exact_bsp) {
                (Some(t), _) => Some(HoistedSilhouetteBsp::from_convex(t)),
                (_, Some(t)) => Some(HoistedSilhouetteBsp::from_exact(t)),
                _ => None,
            };
            let hoisted = match hoisted {
                Some(Ok(h)) => Some(Arc::new(h)),
                Some(Err(e)) => {
                    let names = quoted_names(&self.objects, g);
                    self.notes
                        .push(format!("{names}: the tree stays leaf-stored: {e}"));
                    None
                }
                None => None,
            };
            for &m in g {
                self.objects[m as usize].hoisted = hoisted.clone();
            }
        }
    }

    /// Builds the trees of precomputed silhouettes again with other size limits (benchmarks).
    pub fn rebuild_silhouette_trees(&mut self, max_cells: usize, max_leaves: usize) {
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
            o.bsp = None;
            o.exact_bsp = None;
            o.hoisted = None;
            o.triangulation = None;
        }
    }

    /// The prepared scene of `scene`, a copy of the scene `self` was prepared from in which
    /// object `index` moved rigidly (any affine map of positive determinant will do), without
    /// preparing it again: every other object's data are copied (their trees, triangulations
    /// and mesh hierarchies are `Arc`-shared), and the moved object keeps its trees, which
    /// work in their own frame: its `to_tree` becomes the old map after the inverse motion
    /// (001 Sect. 5.4, as for instances), its star centre moves with it, and a convex hull
    /// standing in for it is moved, not recomputed. Only its `Polyhedron` (face planes,
    /// adjacency, face hierarchy: world-frame data) is built again from its new vertices,
    /// and the separating planes of its light–occluder pairs are found again.
    ///
    /// The trees stay valid wherever the moved object goes, but they cover the box they were
    /// built over (the old scene's bounds in the object's old frame): shading points outside
    /// it take the silhouette computed at the point (same result, slower). Re-prepare the
    /// scene ([`PreparedScene::prepare`]) when an edit is done to give it trees over its new
    /// bounds.
    ///
    /// Falls back to preparing the object alone, without trees, when its new vertices are
    /// not an affine image of its old ones (another mesh, a mirror image, or a flat mesh,
    /// which has no tree anyway). An error when `index` is out of range or the scene has
    /// another object count.
    pub fn with_moved_object(
        &self,
        scene: &Scene,
        index: usize,
    ) -> Result<(PreparedScene, MoveReuse), String> {
        let count = scene.objects.len();
        if index >= count {
            return Err(format!(
                "object index {index} is out of range: the scene has {count} objects"
            ));
        }
        if count != self.materials.len() {
            return Err(format!(
                "the scene has {count} objects, the prepared scene {}",
                self.materials.len()
            ));
        }
        let mut out = self.clone();
        out.materials = scene.objects.iter().map(|o| o.material.clone()).collect();
        out.bounds = scene_box(scene);
        out.trees_built = 0;
        let Some(p) = self.objects.iter().position(|o| o.object == index as u32) else {
            return Ok((out, MoveReuse::NotPrepared));
        };
        let obj = &scene.objects[index];
        let old = &self.objects[p];
        // The mesh's topology is kept when the move leaves it alone (the usual case).
        let mesh = old
            .faces()
            .moved(&obj.mesh.positions)
            .unwrap_or_else(|| IndexedPolyhedron::new(&obj.mesh.positions, &obj.mesh.faces));
        if mesh.face_count() == 0 {
            return Err(format!(
                "object '{}' has no usable face after the move",
                obj.name
            ));
        }
        let had_tree = old.bsp.is_some() || old.exact_bsp.is_some() || old.hoisted.is_some();
        let map = instance_map(old.faces(), &mesh);
        // The fan keeps its triangles under the move too (no new adjacency per drag frame).
        let fan = match &old.fan {
            Some(f) => f
                .poly
                .moved(&obj.mesh.positions)
                .map(|poly| FanMesh {
                    poly: Arc::new(poly),
                    face_of: f.face_of.clone(),
                })
                .or_else(|| FanMesh::of(&obj.mesh)),
            None => FanMesh::of(&obj.mesh),
        };
        let reuse;
        {
            let o = &mut out.objects[p];
            o.fan = fan;
            match map {
                Some(m) => {
                    o.poly = match &old.stand_in {
                        None => mesh,
                        Some(s) => {
                            let vertices: Vec<DVec3> = old
                                .poly
                                .vertices
                                .iter()
                                .map(|&v| m.transform_point3(v))
                                .collect();
                            let faces: Vec<Vec<u32>> = (0..old.poly.face_count())
                                .map(|f| old.poly.face(f).to_vec())
                                .collect();
                            o.stand_in = Some(StandIn {
                                mesh: Arc::new(mesh),
                                ..s.clone()
                            });
                            IndexedPolyhedron::new(&vertices, &faces)
                        }
                    };
                    let back = m.inverse();
                    o.to_tree = Some(match old.to_tree {
                        Some(t) => t * back,
                        None => back,
                    });
                    o.star_centre = old.star_centre.map(|c| m.transform_point3(c));
                    reuse = if had_tree {
                        MoveReuse::Trees
                    } else {
                        MoveReuse::NoTree
                    };
                }
                None => {
                    let (poly, stand_in) = StandIn::of(mesh, obj.mesh.rounding);
                    let d = poly.diagnostics;
                    o.star_centre = (old.star_centre.is_some() && !d.convex && d.closed_manifold)
                        .then(|| star_centre(&poly))
                        .flatten();
                    o.poly = poly;
                    o.stand_in = stand_in;
                    o.to_tree = None;
                    o.bsp = None;
                    o.exact_bsp = None;
                    o.hoisted = None;
                    o.triangulation = None;
                    reuse = MoveReuse::Alone;
                    if had_tree {
                        out.notes.push(format!(
                            "object '{}' moved by a map that is not an affine image of its former \
                             vertices: its silhouette trees are dropped",
                            o.name
                        ));
                    }
                }
            }
            o.simple = o.poly.has_simple_silhouette();
            if out.lights.iter().any(|&(l, _)| l as usize == p) {
                o.face_sides = o.light_face_sides();
            }
        }
        // The separating planes of the moved object's pairs, and the notes of every pair.
        let n_occ = out.occluders.len();
        for (li, &(l, _)) in out.lights.iter().enumerate() {
            for (oi, &oc) in out.occluders.iter().enumerate() {
                if (l as usize != p && oc as usize != p) || l == oc {
                    continue;
                }
                out.separations[li * n_occ + oi] = separating_plane(
                    &out.objects[oc as usize].poly,
                    &out.objects[l as usize].poly,
                );
            }
        }
        out.notes
            .retain(|n| !n.contains("are not separated by a plane"));
        for (li, &(l, _)) in out.lights.iter().enumerate() {
            for (oi, &oc) in out.occluders.iter().enumerate() {
                if l != oc && out.separations[li * n_occ + oi].is_none() {
                    out.notes.push(format!(
                        "light '{}' and occluder '{}' are not separated by a plane: the light is \
                         taken face by face, each face cutting the occluder at its plane",
                        out.objects[l as usize].name, out.objects[oc as usize].name
                    ));
                }
            }
        }
        Ok((out, reuse))
    }

    /// Whether some occluder other than light `l` itself (index into `lights`) has no plane
    /// separating it from the light: the light is then shaded face by face.
    #[inline]
    pub fn light_is_crossed(&self, l: usize) -> bool {
        let n = self.occluders.len();
        let light = self.lights[l].0;
        (0..n).any(|o| self.occluders[o] != light && self.separations[l * n + o].is_none())
    }

    /// Whether the points of a tile can share work with `method`: some occluder's outline is
    /// found inside the light's window through an edge hierarchy (`geometry::tile_candidates`).
    pub fn tiles_share_candidates(&self, method: super::Method) -> bool {
        method == super::Method::Analytic
            && self.occluders.iter().any(|&o| {
                let obj = &self.objects[o as usize];
                obj.path().is_windowed() && obj.poly.index.edge_hierarchy.is_some()
            })
    }

    /// The separating plane of light `l` and occluder `o` (indices into `lights`/`occluders`).
    #[inline]
    pub fn separation(&self, l: usize, o: usize) -> Option<&Plane> {
        self.separations[l * self.occluders.len() + o].as_ref()
    }
}
