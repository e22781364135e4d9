//! BSP trees of precomputed silhouettes (001 Sect. 5) against closed forms (the cells of the
//! cube's and the tetrahedron's face planes, 001 Fig. 5.1) and against the silhouette computed
//! on the fly at thousands of random points of every cell.

use glam::DVec3;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    Sidedness, SilhouetteBsp, SilhouetteScratch, SphericalPolygon, silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};

fn polyhedron(name: &str) -> IndexedPolyhedron {
    let m = thesis_polyhedron(name).unwrap();
    IndexedPolyhedron::new(&m.positions, &m.faces)
}

fn boxed(p: &IndexedPolyhedron, k: f64) -> (DVec3, DVec3) {
    (
        p.center - DVec3::splat(k * p.radius),
        p.center + DVec3::splat(k * p.radius),
    )
}

/// 001 Fig. 5.1: the face planes of a cube cut space into 27 cells, those of a tetrahedron
/// into 15 (one of them the solid itself); a balanced tree over n leaves has 2n − 1 nodes.
#[test]
fn cells_of_the_cube_and_the_tetrahedron() {
    let cube = polyhedron("cube");
    let (lo, hi) = boxed(&cube, 8.0);
    let (_, stats) = SilhouetteBsp::build_convex(&cube, lo, hi).unwrap();
    assert_eq!(stats.leaves, 27);
    assert_eq!(stats.nodes, 2 * 27 - 1);
    let v = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    let faces = vec![vec![0, 1, 2], vec![0, 3, 1], vec![0, 2, 3], vec![1, 3, 2]];
    let mut tet = IndexedPolyhedron::new(&v, &faces);
    if tet.signed_volume() < 0.0 {
        let flipped: Vec<Vec<u32>> = faces
            .iter()
            .map(|f| f.iter().rev().copied().collect())
            .collect();
        tet = IndexedPolyhedron::new(&v, &flipped);
    }
    assert!(tet.diagnostics.convex);
    let (lo, hi) = boxed(&tet, 40.0);
    let (_, stats) = SilhouetteBsp::build_convex(&tet, lo, hi).unwrap();
    assert_eq!(stats.leaves, 15);
}

/// Solid angle about the mean direction (the silhouettes here are smaller than a hemisphere).
fn solid_angle(p: &SphericalPolygon) -> f64 {
    p.signed_solid_angle()
}

#[test]
fn bsp_silhouettes_equal_the_silhouette_on_the_fly() {
    let mut rng = Pcg32::new(99, 2);
    let frame = Frame::from_z(DVec3::new(0.1, -0.3, 0.95).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut scratch = SilhouetteScratch::default();
    for row in TABLE_7_1.iter().filter(|r| r.convex) {
        let poly = polyhedron(row.name);
        let (lo, hi) = boxed(&poly, 6.0);
        let (bsp, stats) = SilhouetteBsp::build_convex(&poly, lo, hi).unwrap();
        eprintln!("{}: {stats:?}", row.name);
        let mut n = 0;
        while n < 4000 {
            let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            if poly.face_planes.iter().all(|p| p.eval(x) < 0.0) {
                continue;
            }
            assert!(bsp.silhouette(&poly, x, &frame, &mut a));
            silhouette(&poly, x, &frame, Sidedness::FrontOnly, &mut b, &mut scratch);
            assert_eq!(a.vertex_count(), b.vertex_count(), "{} at {x}", row.name);
            let (sa, sb) = (solid_angle(&a), solid_angle(&b));
            assert!((sa - sb).abs() < 1e-12, "{} at {x}: {sa} vs {sb}", row.name);
            n += 1;
        }
        // Outside its box the tree does not answer.
        assert!(!bsp.silhouette(&poly, hi * 2.0, &frame, &mut a));
    }
}

/// The cell a point falls in (the tree's box cut by the planes on its path) contains the point,
/// and the contour seen from anywhere in it is the contour seen from its centroid: the promise
/// a leaf's precomputed silhouette rests on (001 Sect. 5.1), checked on the cells themselves.
#[test]
fn the_cell_of_a_point_contains_it_and_keeps_its_contour() {
    use penumbra::geometry::{SilhouetteTree, bsp_cell, contour_edges};
    let mut rng = Pcg32::new(3, 4);
    for name in ["cone", "icosahedron"] {
        let poly = polyhedron(name);
        let (lo, hi) = boxed(&poly, 5.0);
        let (bsp, _) = SilhouetteBsp::build_convex(&poly, lo, hi).unwrap();
        for _ in 0..300 {
            let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            let path = bsp.path(x).unwrap();
            let cell = bsp_cell(&path, lo, hi, 1e-12);
            assert!(!cell.is_empty());
            for f in &cell.faces {
                let n = (f[1] - f[0]).cross(f[2] - f[0]).normalize();
                assert!(n.dot(x - f[0]) <= 1e-9, "{name}: {x} outside its cell");
            }
            let mut at_x: Vec<[u32; 2]> = contour_edges(&poly, x).collect();
            let mut at_c: Vec<[u32; 2]> = contour_edges(&poly, cell.centroid()).collect();
            at_x.sort();
            at_c.sort();
            assert_eq!(
                at_x, at_c,
                "{name}: the contour changes inside the cell of {x}"
            );
        }
    }
}

/// A tree read from disk is checked before use: out-of-range children, planes or vertex
/// indices, and children that point backwards (a cycle), make it ill-formed.
#[test]
fn ill_formed_trees_are_recognised() {
    use penumbra::geometry::BspNode;
    let poly = polyhedron("cone");
    let (lo, hi) = boxed(&poly, 4.0);
    let (tree, _) = SilhouetteBsp::build_convex(&poly, lo, hi).unwrap();
    assert!(tree.is_well_formed(poly.vertices.len()));
    assert!(
        !tree.is_well_formed(3),
        "vertex indices beyond a 3-vertex mesh"
    );
    let inner = tree
        .nodes
        .iter()
        .position(|n| matches!(n, BspNode::Inner { .. }))
        .unwrap();
    for bad in [
        BspNode::Inner {
            plane: 9999,
            back: 1,
            front: 2,
        },
        BspNode::Inner {
            plane: 0,
            back: 0,
            front: 2,
        },
        BspNode::Inner {
            plane: 0,
            back: 1,
            front: u32::MAX,
        },
        BspNode::Leaf {
            first: u32::MAX,
            count: 2,
        },
    ] {
        let mut t = tree.clone();
        t.nodes[inner] = bad;
        assert!(!t.is_well_formed(poly.vertices.len()), "{bad:?}");
    }
}

/// 001 Sect. 8, counted twice: the edges stored "as high as they stay valid" by
/// `hoisted_edge_counts` against a brute-force count over every node (the intersection of the
/// edge sets of all the leaves below it, minus what its parent already holds).
#[test]
fn hoisted_edge_counts_match_a_brute_force_count() {
    use penumbra::geometry::BspNode;
    use std::collections::BTreeSet;
    let poly = polyhedron("cone");
    let (lo, hi) = boxed(&poly, 4.0);
    let (tree, _) = SilhouetteBsp::build_convex(&poly, lo, hi).unwrap();
    let leaf_set = |first: u32, count: u32| -> BTreeSet<(u32, u32)> {
        let d = &tree.data[first as usize..(first + count) as usize];
        d.split(|&v| v == u32::MAX)
            .flat_map(|lp| (0..lp.len()).map(move |k| (lp[k], lp[(k + 1) % lp.len()])))
            .collect()
    };
    // Edge set common to the leaves below node n (brute force over the subtree).
    fn common(
        nodes: &[BspNode],
        n: usize,
        leaf: &dyn Fn(u32, u32) -> BTreeSet<(u32, u32)>,
    ) -> BTreeSet<(u32, u32)> {
        match nodes[n] {
            BspNode::Leaf { first, count } => leaf(first, count),
            BspNode::Inner { back, front, .. } => {
                let a = common(nodes, back as usize, leaf);
                let b = common(nodes, front as usize, leaf);
                a.intersection(&b).copied().collect()
            }
        }
    }
    let mut parent = vec![usize::MAX; tree.nodes.len()];
    for (i, n) in tree.nodes.iter().enumerate() {
        if let BspNode::Inner { back, front, .. } = n {
            parent[*back as usize] = i;
            parent[*front as usize] = i;
        }
    }
    let mut total = 0;
    let mut in_leaves = 0;
    for (n, &up) in parent.iter().enumerate() {
        let c = common(&tree.nodes, n, &leaf_set);
        if let BspNode::Leaf { .. } = tree.nodes[n] {
            in_leaves += c.len();
        }
        total += match up {
            usize::MAX => c.len(),
            p => c.difference(&common(&tree.nodes, p, &leaf_set)).count(),
        };
    }
    assert_eq!(tree.hoisted_edge_counts(), (in_leaves, total));
    assert!(total < in_leaves);
}
