//! How large the stress run's shared trees of the Table 7.1 polyhedra are, and how long they
//! take to build, for cubes of several sizes.
use glam::DVec3;
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};
use penumbra::shading::BuiltTree;
use penumbra::shading::TreeLibrary;

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let factor = args.first().copied().unwrap_or(1.0) as usize;
    for &b in args
        .get(1..)
        .filter(|a| !a.is_empty())
        .unwrap_or(&[2.0, 6.0, 20.0])
    {
        for p in TABLE_7_1 {
            let m = thesis_polyhedron(p.name).unwrap();
            let t = std::time::Instant::now();
            let lib = TreeLibrary::build(&[m], (DVec3::splat(-b), DVec3::splat(b)), factor);
            let e = &lib.entries[0];
            let nodes = e.trees.tree.as_ref().map(|t| match t {
                BuiltTree::Convex(t) => t.nodes.len(),
                BuiltTree::Exact(t) => t.nodes.len(),
            });
            println!(
                "B {b:5} {:14} {:8.3} s nodes {:?} tri {}",
                p.name,
                t.elapsed().as_secs_f64(),
                nodes,
                e.trees.triangulation.is_some()
            );
        }
    }
}
