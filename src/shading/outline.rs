//! `SphPolySilhouette` of 000 Alg. 1 (lines 2 and 9) for any prepared mesh: the one place that
//! decides how a mesh's spherical polygon at a shading point is found.
//!
//! A prepared object answers "my spherical polygon at this point" with
//! [`PreparedObject::spherical_polygon`]; the shading stages, the stochastic light sampler and
//! the recorder only see the answer ([`Outline`]). Which path a mesh can take was decided when
//! the scene was prepared ([`MeshPath`]: a tree or not, a hull standing in or not); what is left
//! for the point is what depends on it: the method (per-triangle goes face by face everywhere),
//! whether the point lies on the mesh (its own face is in the tangent plane there), and
//! degenerate points of the exact silhouette (which fall back to the faces).
//!
//! | path | polygon | where |
//! |---|---|---|
//! | convex or flat (also a hull standing in) | one loop, read from the BSP tree of face planes, else chained from the contour edges (001 Sect. 4.2, 5.1) | `SilhouetteBsp::silhouette_at`, `geometry::silhouettes::silhouette` |
//! | closed, not convex | loops with holes, read from the exact-silhouette tree, else computed (001 Sect. 4.3, 5.2) | `ExactSilhouetteBsp::silhouette_at`, `geometry::silhouettes::exact_silhouette` |
//! | open, oriented manifold, as an occluder | loops with holes from its contour and boundary edges, computed (docs/silhouettes.md, "Open meshes") | `geometry::silhouettes::exact_silhouette` |
//! | non-manifold, open light, per-triangle, degenerate | none: the caller goes face by face (`geometry::face_polygon`) | — |

use super::{MeshPath, Method, PreparedObject};
use crate::geometry::{
    Degenerate, ExactSilhouetteScratch, Sidedness, SilhouetteScratch, SphericalPolygon,
    WindowScratch, exact_silhouette, exact_silhouette_in_window, silhouette,
};
use crate::math::Frame;
use glam::DVec3;

/// What a mesh is at the shading point, for the stage that asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outline {
    /// The mesh as a whole: its spherical polygon is in the output buffer. `exact` for the
    /// exact silhouette of a non-convex mesh (several loops and holes possible), `from_tree`
    /// when it was read from a tree of precomputed silhouettes.
    Whole { exact: bool, from_tree: bool },
    /// A convex or flat light seen from a point on itself: it lights nothing there.
    Nothing,
    /// The caller goes face by face over `PreparedObject::faces`.
    Faces,
}

/// What the mesh is to the stage asking: a light emits from the front of its faces only; an
/// occluder blocks from both sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Light,
    Occluder,
}

/// Per-thread buffers of the silhouette stage.
#[derive(Default)]
pub struct OutlineScratch {
    pub silhouette: SilhouetteScratch,
    pub exact: ExactSilhouetteScratch,
    pub window: WindowScratch,
    /// The fallbacks taken since the shading point began.
    pub fallbacks: Fallbacks,
}

/// How often a path gave up at a point and a slower path that is exact there took over: at a
/// degenerate configuration (the fallbacks of 001's exact silhouette and of the window), or
/// because a walk crossed the bound its input sets ([`Degenerate::BoundCrossed`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Fallbacks {
    pub degenerate: u32,
    pub bounds_crossed: u32,
}

impl Fallbacks {
    /// Counts one fallback for `why`, if any.
    #[inline]
    pub(crate) fn count(&mut self, why: Option<Degenerate>) {
        match why {
            None => {}
            Some(Degenerate::BoundCrossed) => self.bounds_crossed += 1,
            Some(_) => self.degenerate += 1,
        }
    }

    /// Component-wise sum.
    pub(crate) fn add(&mut self, o: &Fallbacks) {
        self.degenerate += o.degenerate;
        self.bounds_crossed += o.bounds_crossed;
    }
}

impl PreparedObject {
    /// The spherical polygon of this mesh seen from `x` (in `frame`), written to `out` when the
    /// answer is [`Outline::Whole`]. `on_it`: the shading point lies on this mesh. `window`:
    /// for an occluder, the one loop of the light polygon it is subtracted from (in `frame`);
    /// a large non-convex mesh ([`MeshPath::ExactInWindow`]) then writes only loops that agree
    /// with its silhouette inside that window, which is all the set difference sees.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn spherical_polygon(
        &self,
        x: DVec3,
        frame: &Frame,
        role: Role,
        method: Method,
        on_it: bool,
        window: Option<&[DVec3]>,
        out: &mut SphericalPolygon,
        scratch: &mut OutlineScratch,
    ) -> Outline {
        if method == Method::PerTriangle {
            return Outline::Faces;
        }
        match &self.path {
            MeshPath::ConvexTree(_)
            | MeshPath::ConvexAtPoint
            | MeshPath::HullTree { .. }
            | MeshPath::HullAtPoint { .. } => {
                // A convex or flat light does not light points on itself.
                if on_it && role == Role::Light {
                    return Outline::Nothing;
                }
                let sidedness = match role {
                    Role::Light => Sidedness::FrontOnly,
                    Role::Occluder => Sidedness::TwoSided,
                };
                let from_tree =
                    self.silhouette_from_tree(x, frame, out, &mut scratch.silhouette.hoisted);
                if !from_tree {
                    silhouette(
                        &self.poly,
                        x,
                        frame,
                        sidedness,
                        out,
                        &mut scratch.silhouette,
                    );
                }
                Outline::Whole {
                    exact: false,
                    from_tree,
                }
            }
            // Also at points on the mesh itself: the faces through the point are left out
            // there, which the window (strictly above the horizon) makes exact.
            MeshPath::ExactInWindow | MeshPath::OpenInWindow
                if role == Role::Occluder
                    && window.is_some_and(|w| {
                        let found = exact_silhouette_in_window(
                            &self.poly,
                            x,
                            frame,
                            w,
                            on_it,
                            out,
                            &mut scratch.window,
                        );
                        scratch.fallbacks.count(found.err());
                        found.is_ok()
                    }) =>
            {
                Outline::Whole {
                    exact: true,
                    from_tree: false,
                }
            }
            // At points on the mesh itself its own face lies in the tangent plane: the
            // face-by-face path skips that face exactly. An open light goes face by face.
            path @ (MeshPath::ExactTree(_)
            | MeshPath::ExactAtPoint
            | MeshPath::ExactInWindow
            | MeshPath::OpenTree(_)
            | MeshPath::OpenAtPoint
            | MeshPath::OpenInWindow)
                if !on_it && (role == Role::Occluder || !path.kind().is_open()) =>
            {
                match self.exact_silhouette(x, frame, out, &mut scratch.exact) {
                    Ok(from_tree) => Outline::Whole {
                        exact: true,
                        from_tree,
                    },
                    Err(why) => {
                        scratch.fallbacks.count(Some(why));
                        Outline::Faces
                    }
                }
            }
            MeshPath::ExactTree(_)
            | MeshPath::ExactAtPoint
            | MeshPath::ExactInWindow
            | MeshPath::OpenTree(_)
            | MeshPath::OpenAtPoint
            | MeshPath::OpenInWindow
            | MeshPath::PerFace => Outline::Faces,
        }
    }

    /// The exact silhouette of a non-convex mesh: read from its BSP tree where it has one
    /// (001 Sect. 5.2), else computed at the point (001 Sect. 4.3). `Ok(true)` when read
    /// from the tree, the reason at degenerate points.
    #[inline]
    pub fn exact_silhouette(
        &self,
        x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
        scratch: &mut ExactSilhouetteScratch,
    ) -> Result<bool, Degenerate> {
        if self.silhouette_from_tree(x, frame, out, &mut scratch.hoisted) {
            return Ok(true);
        }
        exact_silhouette(&self.poly, x, frame, out, scratch).map(|_| false)
    }

    /// The silhouette from `x` read from this mesh's tree (the hoisted form when present),
    /// looked up at the point in the tree's frame; `false` without a tree, outside its box, or
    /// in a leaf left to the on-the-fly path.
    #[inline]
    fn silhouette_from_tree(
        &self,
        x: DVec3,
        frame: &Frame,
        out: &mut SphericalPolygon,
        hoisted_buf: &mut Vec<[u32; 2]>,
    ) -> bool {
        match self.silhouette_tree() {
            Some(t) => t.silhouette_at(&self.poly, x, self.tree_point(x), frame, out, hoisted_buf),
            None => false,
        }
    }
}
