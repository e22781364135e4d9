//! When a tree of precomputed silhouettes pays for itself: a cost model measured on this
//! code (`cargo run --release --example cost_model`, which writes `out/cost_model.csv`;
//! docs/silhouettes.md, "Which path a mesh takes").
//!
//! A tree saves, at every query, the difference between computing the silhouette at the point
//! and reading it from the tree; it costs its build, in proportion to its cells (convex) or
//! leaves (not convex). Over the queries a render is expected to make, the largest tree worth
//! building is the one whose build takes `PAYBACK`⁻¹ of what it saves: that is the budget
//! the build is given. A build that outgrows its budget stops there, so a tree that does not
//! fit costs at most that share of the time it would have saved, and the mesh takes the path
//! computed at the point. For a mesh that is not convex, the cells of its face planes (which
//! the tree's leaves refine) are counted first, at a few microseconds each: a mesh whose
//! face planes alone exceed the budget is not built at all.
//!
//! The constants were measured with the release build on a 2-core machine; they are ratios
//! that matter, not seconds, so a faster machine moves every term together.

/// Microseconds saved per query by a convex mesh's tree, per face (measured 0.011–0.020 on
/// cylinders of 6–50 faces)...
const CONVEX_SAVING_US_PER_FACE: f64 = 0.015;
/// ...and at most (large convex meshes walk their contour instead of scanning it: the
/// 80-face icosphere saves 0.49 µs).
const CONVEX_SAVING_MAX_US: f64 = 0.6;
/// Microseconds to build one cell of a convex mesh's tree (measured 4.8–8.7).
const CONVEX_BUILD_US_PER_CELL: f64 = 5.6;
/// Microseconds per face of an exact silhouette computed at the point, the whole mesh
/// (measured 0.20 over meshes of 24–320 faces; a tree reads it in well under a microsecond).
const EXACT_QUERY_US_PER_FACE: f64 = 0.2;
/// Microseconds per leaf and per face to build a non-convex mesh's tree (measured 0.45).
const EXACT_BUILD_US_PER_LEAF_PER_FACE: f64 = 0.45;
/// Queries per camera ray: every ray asks each light above its horizon, and asks an occluder
/// only when the occluder lies between it and a light (in the real-world suite, 0.1–0.3 of
/// the rays per occluder).
const LIGHT_QUERIES_PER_RAY: f64 = 1.0;
const OCCLUDER_QUERIES_PER_RAY: f64 = 0.25;
/// Under an environment light each ray asks every occluder above its horizon: about half of
/// them in a scene of objects on a floor.
const ENVIRONMENT_QUERIES_PER_RAY: f64 = 0.5;
/// A tree is worth building if it saves this many times its build.
pub(crate) const PAYBACK: f64 = 2.0;

/// What a mesh is, as far as the model is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct MeshCostClass {
    pub faces: usize,
    pub convex: bool,
    /// It is a light (queried by every ray), not only an occluder.
    pub light: bool,
    /// Without a tree it would take its silhouette inside each light's window only.
    pub windowed: bool,
    /// An environment light lights the scene: every ray asks every occluder above its
    /// horizon once more (`shading::environment_occlusion`), and without a window.
    pub environment: bool,
}

/// The tree the model would build for one mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeBudget {
    /// Cells (convex) or leaves (not convex) at most.
    pub units: usize,
    /// Seconds the tree saves over the expected queries, per the model.
    pub saving_seconds: f64,
    /// Queries the model expects.
    pub queries: f64,
}

/// The budget of a mesh's tree for a render of `expected_rays` camera rays, capped at
/// `limit` (the size beyond which no tree is kept whatever it saves).
pub(crate) fn tree_budget(class: MeshCostClass, expected_rays: u64, limit: usize) -> TreeBudget {
    let f = class.faces as f64;
    let per_ray = if class.light {
        LIGHT_QUERIES_PER_RAY
    } else {
        OCCLUDER_QUERIES_PER_RAY
    };
    // The environment's queries take the whole silhouette (no window), so a tree serves them.
    let env_queries = if class.environment {
        expected_rays as f64 * ENVIRONMENT_QUERIES_PER_RAY
    } else {
        0.0
    };
    let queries = expected_rays as f64 * per_ray;
    let (saving_us, unit_us) = if class.convex {
        (
            (CONVEX_SAVING_US_PER_FACE * f).min(CONVEX_SAVING_MAX_US),
            CONVEX_BUILD_US_PER_CELL,
        )
    } else if class.windowed && !class.light && !class.environment {
        // A large occluder that finds its silhouette inside each light's window
        // (`ExactInWindow`, 0.03–0.05 µs per face) saves nothing with a tree: the tree hands
        // out the whole silhouette, and the set difference then pays for all of it where the
        // window gave only the part over the light. Measured on a voxel model exported face by
        // face (an L of 270 quads under a quad light, 256×256 at --aa 4), the render with the
        // tree took 2.3× the windowed one's CPU time (docs/silhouettes.md).
        (0.0, EXACT_BUILD_US_PER_LEAF_PER_FACE * f)
    } else {
        (
            EXACT_QUERY_US_PER_FACE * f,
            EXACT_BUILD_US_PER_LEAF_PER_FACE * f,
        )
    };
    let queries = queries + env_queries;
    let saving_seconds = queries * saving_us * 1e-6;
    let units = (queries * saving_us / (PAYBACK * unit_us)).floor();
    TreeBudget {
        units: (units.max(0.0) as usize).min(limit),
        saving_seconds,
        queries,
    }
}

/// The camera rays the model assumes when a caller does not say: 256×256 pixels at `--aa 4`.
pub(crate) const DEFAULT_EXPECTED_RAYS: u64 = 256 * 256 * 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_grow_with_the_render_and_stop_at_the_limit() {
        let class = MeshCostClass {
            faces: 36,
            convex: true,
            light: true,
            windowed: false,
            environment: false,
        };
        let small = tree_budget(class, 1 << 16, usize::MAX);
        let large = tree_budget(class, 1 << 22, usize::MAX);
        assert!(small.units < large.units);
        assert_eq!(tree_budget(class, 1 << 40, 50_000).units, 50_000);
        assert_eq!(tree_budget(class, 0, 50_000).units, 0);
    }

    #[test]
    fn an_occluder_inside_windows_gets_no_tree_a_light_does() {
        let occluder = MeshCostClass {
            faces: 252,
            convex: false,
            light: false,
            windowed: true,
            environment: false,
        };
        let light = MeshCostClass {
            light: true,
            ..occluder
        };
        let (a, b) = (
            tree_budget(occluder, DEFAULT_EXPECTED_RAYS, usize::MAX),
            tree_budget(light, DEFAULT_EXPECTED_RAYS, usize::MAX),
        );
        assert_eq!((a.units, a.saving_seconds), (0, 0.0));
        assert!(b.units > 0 && b.saving_seconds > 0.0);
    }
}
