//! Which path a mesh takes under the analytic method, and the data that path reads: decided
//! once, when the scene is prepared and again when a mesh moves or its trees change
//! ([`MeshPath::decide`]; docs/silhouettes.md, "Which path a mesh takes"). A shading point
//! matches on the stored path ([`super::super::outline`]); nothing re-derives it.

use super::mesh_forms::StandIn;
use crate::geometry::{
    ExactSilhouetteBsp, HoistedSilhouetteBsp, IndexedPolyhedron, SilhouetteBsp, SilhouetteTree,
};
use std::sync::Arc;

/// Non-convex meshes without a tree and with at least this many faces (and a face hierarchy)
/// compute their outline as occluders inside each light's window only: below it, the whole
/// outline costs little.
pub(crate) const WINDOWED_MIN_FACES: usize = 64;

/// A tree of precomputed silhouettes, as built or as read from the disk cache or a library.
#[derive(Clone, Debug)]
pub enum BuiltTree {
    /// A convex (or flat) mesh's tree of face planes (001 Sect. 5.1).
    Convex(Arc<SilhouetteBsp>),
    /// A manifold non-convex mesh's tree of exact silhouettes (001 Sect. 5.2).
    Exact(Arc<ExactSilhouetteBsp>),
}

impl BuiltTree {
    /// The same tree (one allocation), not merely an equal one.
    pub(crate) fn is_same(&self, other: &BuiltTree) -> bool {
        match (self, other) {
            (BuiltTree::Convex(a), BuiltTree::Convex(b)) => Arc::ptr_eq(a, b),
            (BuiltTree::Exact(a), BuiltTree::Exact(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }

    fn as_tree(&self) -> &dyn SilhouetteTree {
        match self {
            BuiltTree::Convex(t) => t.as_ref(),
            BuiltTree::Exact(t) => t.as_ref(),
        }
    }
}

/// The tree a mesh's silhouettes are read from, in the frame of its group of instances: as
/// built, and its hoisted form (001 Sect. 8), which shading reads instead when present.
#[derive(Clone, Debug)]
pub struct PathTree {
    pub built: BuiltTree,
    /// Each edge stored as high as it stays valid (`geometry::trees::bsp_hoisted`). Not the default
    /// (slower lookups, docs/silhouettes.md): `PreparedScene::use_hoisted_trees`.
    pub hoisted: Option<Arc<HoistedSilhouetteBsp>>,
}

impl PathTree {
    pub fn new(built: BuiltTree) -> Self {
        PathTree {
            built,
            hoisted: None,
        }
    }

    /// The tree shading reads: the hoisted form when present, else the tree as built.
    #[inline]
    pub fn lookup(&self) -> &dyn SilhouetteTree {
        match &self.hoisted {
            Some(h) => h.as_ref(),
            None => self.built.as_tree(),
        }
    }
}

/// How the analytic method finds a mesh's spherical polygon at a shading point, with what
/// that path reads: its tree, or the convex hull that stands in for the mesh. The window's
/// data (the face hierarchy and the edges' normal cones) live in the mesh's index, which the
/// ray tests share.
#[derive(Clone, Debug)]
pub enum MeshPath {
    /// Convex or flat: one silhouette loop, read from the mesh's tree of face planes.
    ConvexTree(PathTree),
    /// Convex or flat, without a tree (over its size limit): the silhouette chained at each
    /// point.
    ConvexAtPoint,
    /// Convex up to the rounding of its coordinates: its convex hull stands in for it, and the
    /// hull's silhouette is read from its tree.
    HullTree { hull: StandIn, tree: PathTree },
    /// As `HullTree`, without a tree: the hull's silhouette chained at each point.
    HullAtPoint { hull: StandIn },
    /// Closed, not convex: the exact silhouette, read from its tree.
    ExactTree(PathTree),
    /// Closed, not convex, without a tree: the exact silhouette at each point.
    ExactAtPoint,
    /// As `ExactAtPoint` for a large mesh (at least `WINDOWED_MIN_FACES` faces): as an
    /// occluder, only the part of its exact silhouette inside the light's polygon is computed
    /// (`geometry::silhouettes::windowed_silhouette`), from the faces the light's cone meets.
    ExactInWindow,
    /// Open (boundary edges) but an oriented manifold: as an occluder, the exact outline of its
    /// image from its contour and boundary edges at each point (docs/silhouettes.md, "Open
    /// meshes"); as a light, face by face, since it emits from the front of its faces only and
    /// its outline also covers back faces seen through its opening.
    OpenAtPoint,
    /// As `OpenAtPoint` for a large mesh: as an occluder, only the part of its outline inside
    /// the light's polygon is computed.
    OpenInWindow,
    /// As `OpenAtPoint`, the outline read from its tree (the exact-silhouette tree, whose
    /// leaves hold the outline of contour and boundary edges, 001 Sect. 5.2).
    OpenTree(PathTree),
    /// Non-manifold: face by face.
    PerFace,
}

impl MeshPath {
    /// The one place a mesh's path is decided, from the mesh as prepared (`poly`: the hull
    /// when `hull` stands in for the mesh), the hull's record, and the tree built for it.
    ///
    /// | `poly` | tree | no tree |
    /// |---|---|---|
    /// | convex or flat | `ConvexTree`, `HullTree` | `ConvexAtPoint`, `HullAtPoint` |
    /// | closed | `ExactTree` | `ExactInWindow` (large, indexed), `ExactAtPoint` |
    /// | open, manifold | `OpenTree` | `OpenInWindow` (large, indexed), `OpenAtPoint` |
    /// | non-manifold | `PerFace` | `PerFace` |
    pub(crate) fn decide(
        poly: &IndexedPolyhedron,
        hull: Option<StandIn>,
        tree: Option<PathTree>,
    ) -> MeshPath {
        let d = poly.diagnostics;
        let large = poly.face_count() >= WINDOWED_MIN_FACES && poly.index.face_bvh.is_some();
        if poly.has_simple_silhouette() {
            return match (hull, tree) {
                (Some(hull), Some(tree)) => MeshPath::HullTree { hull, tree },
                (Some(hull), None) => MeshPath::HullAtPoint { hull },
                (None, Some(tree)) => MeshPath::ConvexTree(tree),
                (None, None) => MeshPath::ConvexAtPoint,
            };
        }
        match (d.closed_manifold, d.nonmanifold_edges == 0, tree) {
            (true, _, Some(tree)) => MeshPath::ExactTree(tree),
            (true, _, None) if large => MeshPath::ExactInWindow,
            (true, _, None) => MeshPath::ExactAtPoint,
            (false, true, Some(tree)) => MeshPath::OpenTree(tree),
            (false, true, None) if large => MeshPath::OpenInWindow,
            (false, true, None) => MeshPath::OpenAtPoint,
            (false, false, _) => MeshPath::PerFace,
        }
    }

    /// What kind of path it is, for labels, reports and tests.
    pub fn kind(&self) -> PathKind {
        match self {
            MeshPath::ConvexTree(_) => PathKind::ConvexTree,
            MeshPath::ConvexAtPoint => PathKind::ConvexAtPoint,
            MeshPath::HullTree { .. } => PathKind::HullTree,
            MeshPath::HullAtPoint { .. } => PathKind::HullAtPoint,
            MeshPath::ExactTree(_) => PathKind::ExactTree,
            MeshPath::ExactAtPoint => PathKind::ExactAtPoint,
            MeshPath::ExactInWindow => PathKind::ExactInWindow,
            MeshPath::OpenAtPoint => PathKind::OpenAtPoint,
            MeshPath::OpenInWindow => PathKind::OpenInWindow,
            MeshPath::OpenTree(_) => PathKind::OpenTree,
            MeshPath::PerFace => PathKind::PerFace,
        }
    }

    /// The tree this path reads, if it reads one.
    #[inline]
    pub fn tree(&self) -> Option<&PathTree> {
        match self {
            MeshPath::ConvexTree(t)
            | MeshPath::HullTree { tree: t, .. }
            | MeshPath::ExactTree(t)
            | MeshPath::OpenTree(t) => Some(t),
            _ => None,
        }
    }

    pub(crate) fn tree_mut(&mut self) -> Option<&mut PathTree> {
        match self {
            MeshPath::ConvexTree(t)
            | MeshPath::HullTree { tree: t, .. }
            | MeshPath::ExactTree(t)
            | MeshPath::OpenTree(t) => Some(t),
            _ => None,
        }
    }

    /// The convex hull standing in for the mesh, on the hull's paths.
    #[inline]
    pub(crate) fn hull(&self) -> Option<&StandIn> {
        match self {
            MeshPath::HullTree { hull, .. } | MeshPath::HullAtPoint { hull } => Some(hull),
            _ => None,
        }
    }

    /// One silhouette loop (convex or flat, or a hull standing in).
    #[inline]
    pub fn is_simple(&self) -> bool {
        matches!(
            self,
            MeshPath::ConvexTree(_)
                | MeshPath::ConvexAtPoint
                | MeshPath::HullTree { .. }
                | MeshPath::HullAtPoint { .. }
        )
    }
}

/// The kind of a [`MeshPath`], without its data: for labels, bench reports and tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PathKind {
    ConvexTree,
    HullTree,
    HullAtPoint,
    ConvexAtPoint,
    ExactTree,
    ExactAtPoint,
    ExactInWindow,
    OpenAtPoint,
    OpenInWindow,
    OpenTree,
    PerFace,
}

impl PathKind {
    /// As an occluder, the outline is computed inside each light's polygon only.
    pub(crate) fn is_windowed(self) -> bool {
        matches!(self, PathKind::ExactInWindow | PathKind::OpenInWindow)
    }

    /// An open mesh: as a light, face by face.
    pub(crate) fn is_open(self) -> bool {
        matches!(
            self,
            PathKind::OpenAtPoint | PathKind::OpenInWindow | PathKind::OpenTree
        )
    }

    /// A few words for a table.
    pub fn label(self) -> &'static str {
        match self {
            PathKind::ConvexTree => "convex, BSP",
            PathKind::ConvexAtPoint => "convex",
            PathKind::HullTree => "hull, BSP",
            PathKind::HullAtPoint => "hull",
            PathKind::ExactTree => "non-convex, BSP",
            PathKind::ExactAtPoint => "non-convex (exact)",
            PathKind::ExactInWindow => "non-convex, large (exact, windowed)",
            PathKind::OpenAtPoint => "open (exact outline)",
            PathKind::OpenInWindow => "open, large (exact outline, windowed)",
            PathKind::OpenTree => "open, BSP (exact outline)",
            PathKind::PerFace => "non-manifold (per face)",
        }
    }

    /// The path in the words of the scene notes.
    pub(crate) fn describe(self) -> &'static str {
        match self {
            PathKind::ConvexTree => "convex: silhouette from its BSP tree",
            PathKind::ConvexAtPoint => "convex: silhouette chained at each point",
            PathKind::HullTree => "convex up to rounding: its hull's silhouette from a BSP tree",
            PathKind::HullAtPoint => {
                "convex up to rounding: its hull's silhouette chained at each point"
            }
            PathKind::ExactTree => "not convex: exact silhouette from its BSP tree",
            PathKind::ExactAtPoint => "not convex: exact silhouette computed at each point",
            PathKind::ExactInWindow => {
                "not convex, large: exact silhouette computed at each point, as an occluder only \
                 inside each light's polygon"
            }
            PathKind::OpenAtPoint => {
                "open: as an occluder, the exact outline of contour and boundary edges computed \
                 at each point; as a light, face by face"
            }
            PathKind::OpenInWindow => {
                "open, large: as an occluder, the exact outline of contour and boundary edges \
                 computed at each point, only inside each light's polygon; as a light, face by \
                 face"
            }
            PathKind::OpenTree => {
                "open: as an occluder, the exact outline of contour and boundary edges from its \
                 BSP tree; as a light, face by face"
            }
            PathKind::PerFace => "non-manifold: face by face",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{IndexedPolyhedron, SilhouetteBsp};
    use crate::scene::{Mesh, shapes};
    use glam::DVec3;

    fn indexed(mesh: &Mesh) -> IndexedPolyhedron {
        IndexedPolyhedron::new(&mesh.positions, &mesh.faces)
    }

    /// A closed torus of `n × m` quads (major radius 1, minor 0.3), outward faces.
    fn torus(n: u32, m: u32) -> Mesh {
        let mut positions = Vec::new();
        for i in 0..n {
            let u = std::f64::consts::TAU * i as f64 / n as f64;
            for j in 0..m {
                let v = std::f64::consts::TAU * j as f64 / m as f64;
                let r = 1.0 + 0.3 * v.cos();
                positions.push(DVec3::new(r * u.cos(), r * u.sin(), 0.3 * v.sin()));
            }
        }
        let at = |i: u32, j: u32| (i % n) * m + (j % m);
        let faces = (0..n)
            .flat_map(|i| {
                (0..m).map(move |j| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
            })
            .collect();
        Mesh {
            positions,
            faces,
            rounding: 0.0,
        }
    }

    /// A cube is convex: with a tree it reads it, without one it chains its silhouette; the
    /// tree it carries is the one given.
    #[test]
    fn convex_mesh_reads_the_tree_it_was_given() {
        let cube = indexed(&shapes::cuboid(DVec3::ZERO, DVec3::splat(0.5)));
        assert_eq!(
            MeshPath::decide(&cube, None, None).kind(),
            PathKind::ConvexAtPoint
        );
        let (lo, hi) = (DVec3::splat(-3.0), DVec3::splat(3.0));
        let (tree, _) = SilhouetteBsp::build_convex_limited(&cube, lo, hi, usize::MAX)
            .expect("a cube's tree fits");
        let built = BuiltTree::Convex(Arc::new(tree));
        let path = MeshPath::decide(&cube, None, Some(PathTree::new(built.clone())));
        assert_eq!(path.kind(), PathKind::ConvexTree);
        assert!(path.tree().is_some_and(|t| t.built.is_same(&built)));
        assert!(path.is_simple() && path.hull().is_none());
    }

    /// A closed non-convex mesh takes the exact silhouette; a large one, as an occluder, only
    /// inside the window; one face taken away opens it.
    #[test]
    fn non_convex_meshes_by_size_and_closure() {
        let ring = torus(24, 12);
        let closed = indexed(&ring);
        assert!(closed.face_count() >= WINDOWED_MIN_FACES);
        assert_eq!(
            MeshPath::decide(&closed, None, None).kind(),
            PathKind::ExactInWindow
        );
        let small = indexed(&torus(6, 4));
        assert!(small.face_count() < WINDOWED_MIN_FACES);
        assert_eq!(
            MeshPath::decide(&small, None, None).kind(),
            PathKind::ExactAtPoint
        );
        let mut open = ring.clone();
        open.faces.pop();
        let open = indexed(&open);
        assert_eq!(
            MeshPath::decide(&open, None, None).kind(),
            PathKind::OpenInWindow
        );
        assert!(!MeshPath::decide(&open, None, None).is_simple());
    }

    /// Three faces on one edge: non-manifold, face by face whatever it is given.
    #[test]
    fn non_manifold_goes_face_by_face() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let faces = vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]];
        let poly = IndexedPolyhedron::new(&positions, &faces);
        assert!(poly.diagnostics.nonmanifold_edges > 0);
        assert_eq!(
            MeshPath::decide(&poly, None, None).kind(),
            PathKind::PerFace
        );
    }
}
