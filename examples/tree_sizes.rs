//! Leaves of the exact-silhouette trees of the closed non-convex meshes of a scene, over the
//! scene's bounds, without size limits (to choose `MAX_EXACT_BSP_LEAVES`).
//!
//!     cargo run --release --example tree_sizes [SCENE]
use penumbra::geometry::{ExactBspLimits, ExactSilhouetteBsp};
use penumbra::render::RenderContext;
use penumbra::scene::scene_file;

fn main() {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "polyhedra".into());
    let scene = scene_file::load_embedded(&name).expect("an embedded scene");
    let ctx = RenderContext::new(&scene);
    let (lo, hi) = ctx.prepared.bounds;
    for o in &ctx.prepared.objects {
        let d = &o.poly.diagnostics;
        if d.convex || !d.closed_manifold {
            continue;
        }
        let limits = ExactBspLimits {
            max_leaves: usize::MAX,
            ..ExactBspLimits::default()
        };
        let lo = lo.min(o.poly.center - o.poly.radius);
        let hi = hi.max(o.poly.center + o.poly.radius);
        if let Some((_, s)) = ExactSilhouetteBsp::build(&o.poly, lo, hi, limits) {
            println!("{}: {} leaves, {:.2} s", o.name, s.leaves, s.seconds);
        }
    }
}
