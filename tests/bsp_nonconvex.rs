//! BSP trees of precomputed exact silhouettes of the non-convex Table 7.1 polyhedra (001 Sect.
//! 5.2) against the exact silhouette computed on the fly at random points: how often a random
//! point reads a wrong silhouette from its leaf (the failure rate the validation leaves).

use glam::DVec3;
use penumbra::accel::{Ray, intersect_triangle};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, ExactSilhouetteScratch, SphericalPolygon, exact_silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::TABLE_7_1;

use crate::silhouette_common;
use silhouette_common::{polyhedron, solid_angle, triangles};

#[test]
fn bsp_exact_silhouettes_equal_the_silhouette_on_the_fly() {
    let mut rng = Pcg32::new(5, 8);
    let frame = Frame::from_z(DVec3::new(0.2, 0.5, -0.84).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut scratch = ExactSilhouetteScratch::default();
    for row in TABLE_7_1.iter().filter(|r| !r.convex) {
        let poly = polyhedron(row.name);
        let tris = triangles(&poly);
        let (lo, hi) = (
            poly.center - DVec3::splat(3.0 * poly.radius),
            poly.center + DVec3::splat(3.0 * poly.radius),
        );
        let (bsp, stats) =
            ExactSilhouetteBsp::build(&poly, lo, hi, ExactBspLimits::default()).unwrap();
        eprintln!("{}: {stats:?}", row.name);
        let (mut checked, mut from_tree, mut wrong) = (0, 0, 0);
        while checked < 3000 {
            let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            let ray = Ray::new(x, DVec3::new(0.5773, 0.5774, 0.5775));
            let crossings = tris
                .iter()
                .filter(|t| {
                    intersect_triangle(&ray, t[0], t[1], t[2], 0.0, f64::INFINITY).is_some()
                })
                .count();
            if crossings % 2 == 1
                || exact_silhouette(&poly, x, &frame, &mut b, &mut scratch).is_err()
            {
                continue;
            }
            checked += 1;
            if bsp.silhouette(&poly, x, &frame, &mut a) {
                from_tree += 1;
                if (solid_angle(&a) - solid_angle(&b)).abs() > 1e-9 {
                    wrong += 1;
                }
            }
        }
        eprintln!(
            "{}: {from_tree} of {checked} points read from the tree, {wrong} wrong",
            row.name
        );
        assert!(
            from_tree * 10 >= checked * 9,
            "{}: the tree answers too rarely",
            row.name
        );
        assert_eq!(wrong, 0, "{}: wrong silhouettes from the tree", row.name);
    }
}

/// The 32-bit point encoding of 001 Sect. 5.4: every vertex and every crossing of four
/// distinct indices below 256 decodes to itself; an index of 256 or more has no code (larger
/// meshes take `PointCoding::EdgePairs`, tested below).
#[test]
fn silhouette_points_pack_into_32_bits() {
    use penumbra::geometry::SilhouettePoint;
    let mut rng = Pcg32::new(1, 1);
    for v in 0..256 {
        let p = SilhouettePoint::Vertex(v);
        assert_eq!(SilhouettePoint::unpack(p.pack().unwrap()), p);
    }
    for _ in 0..10_000 {
        let mut i = [0u32; 4];
        for k in 0..4 {
            i[k] = loop {
                let c = rng.below(256);
                if !i[..k].contains(&c) {
                    break c;
                }
            };
        }
        let p = SilhouettePoint::Crossing([i[0], i[1]], [i[2], i[3]]);
        assert_eq!(SilhouettePoint::unpack(p.pack().unwrap()), p);
    }
    assert!(SilhouettePoint::Vertex(256).pack().is_none());
    assert!(SilhouettePoint::Crossing([0, 1], [2, 300]).pack().is_none());
}

/// A voxel model exported face by face, as voxel editors write it: an L of `n`×`n`×`h` unit
/// cubes with arms `arm` wide, every boundary face of every cube a quad of its own (so many
/// vertices on few planes).
fn voxel_l(n: i32, h: i32, arm: i32) -> IndexedPolyhedron {
    let filled = |i: i32, j: i32, k: i32| {
        (0..n).contains(&i) && (0..n).contains(&j) && (0..h).contains(&k) && (i < arm || j < arm)
    };
    let mut ids = std::collections::HashMap::new();
    let (mut positions, mut faces) = (Vec::new(), Vec::new());
    let sides: [([i32; 3], [[i32; 3]; 4]); 6] = [
        ([1, 0, 0], [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]]),
        ([-1, 0, 0], [[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0]]),
        ([0, 1, 0], [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]]),
        ([0, -1, 0], [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]),
        ([0, 0, 1], [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]),
        ([0, 0, -1], [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]]),
    ];
    for i in 0..n {
        for j in 0..n {
            for k in 0..h {
                if !filled(i, j, k) {
                    continue;
                }
                for (d, quad) in &sides {
                    if filled(i + d[0], j + d[1], k + d[2]) {
                        continue;
                    }
                    let face = quad.map(|c| {
                        let p = [i + c[0], j + c[1], k + c[2]];
                        *ids.entry(p).or_insert_with(|| {
                            positions
                                .push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * 0.25);
                            positions.len() as u32 - 1
                        })
                    });
                    faces.push(face.to_vec());
                }
            }
        }
    }
    IndexedPolyhedron::new(&positions, &faces)
}

/// Past 256 vertices a tree codes its points by edge pairs (`PointCoding::EdgePairs`): a voxel
/// L of 272 vertices gets a tree, whose silhouettes equal those computed on the fly (the same
/// oracle as above: solid angle, at random points outside the mesh).
#[test]
fn trees_past_256_vertices_code_crossings_by_their_edges() {
    use penumbra::geometry::PointCoding;
    let poly = voxel_l(12, 3, 3);
    assert!(poly.vertices.len() > 256 && poly.diagnostics.closed_manifold);
    assert_eq!(PointCoding::for_mesh(&poly), Some(PointCoding::EdgePairs));
    let tris = triangles(&poly);
    let (lo, hi) = (
        poly.center - DVec3::splat(2.0 * poly.radius),
        poly.center + DVec3::splat(2.0 * poly.radius),
    );
    let (bsp, stats) = ExactSilhouetteBsp::build(&poly, lo, hi, ExactBspLimits::default())
        .expect("a tree within the default limits");
    eprintln!("voxel L: {stats:?}");
    assert_eq!(bsp.coding, PointCoding::EdgePairs);
    assert!(bsp.is_well_formed(poly.vertices.len(), poly.edges.len()));
    assert!(
        !bsp.is_well_formed(poly.vertices.len(), 10),
        "edge indices are checked"
    );
    let mut rng = Pcg32::new(9, 3);
    let frame = Frame::from_z(DVec3::new(0.2, 0.5, -0.84).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut scratch = ExactSilhouetteScratch::default();
    let (mut checked, mut from_tree, mut wrong, mut crossings_seen) = (0, 0, 0, 0);
    while checked < 2000 {
        let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let ray = Ray::new(x, DVec3::new(0.5773, 0.5774, 0.5775));
        let hits = tris
            .iter()
            .filter(|t| intersect_triangle(&ray, t[0], t[1], t[2], 0.0, f64::INFINITY).is_some())
            .count();
        if hits % 2 == 1 || exact_silhouette(&poly, x, &frame, &mut b, &mut scratch).is_err() {
            continue;
        }
        checked += 1;
        if bsp.silhouette(&poly, x, &frame, &mut a) {
            from_tree += 1;
            crossings_seen += bsp
                .leaf_points(&poly, x)
                .unwrap()
                .filter(|p| matches!(p, penumbra::geometry::SilhouettePoint::Crossing(..)))
                .count();
            if (solid_angle(&a) - solid_angle(&b)).abs() > 1e-9 {
                wrong += 1;
            }
        }
    }
    eprintln!(
        "voxel L: {from_tree} of {checked} from the tree, {wrong} wrong, {crossings_seen} crossings"
    );
    assert!(from_tree * 10 >= checked * 9, "the tree answers too rarely");
    assert!(
        crossings_seen > 0,
        "no crossing was read back from its edges"
    );
    assert_eq!(wrong, 0);
}
