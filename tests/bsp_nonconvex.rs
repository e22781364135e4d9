//! BSP trees of precomputed exact silhouettes of the non-convex Table 7.1 polyhedra (001 Sect.
//! 5.2) against the exact silhouette computed on the fly at random points: how often a random
//! point reads a wrong silhouette from its leaf (the failure rate the validation leaves).

use glam::DVec3;
use penumbra::accel::{Ray, intersect_triangle};
use penumbra::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, ExactSilhouetteScratch, Polyhedron, SphericalPolygon,
    exact_silhouette,
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
/// distinct indices below 256 decodes to itself; an index of 256 or more has no code; a
/// 257-vertex mesh gets no tree.
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
    let big = penumbra::scene::shapes::uv_ellipsoid(DVec3::ZERO, DVec3::ONE, 20, 14);
    let big = Polyhedron::new(&big.positions, &big.faces);
    assert!(big.vertices.len() > 256);
    assert!(
        ExactSilhouetteBsp::build(
            &big,
            -DVec3::splat(3.0),
            DVec3::splat(3.0),
            ExactBspLimits::default()
        )
        .is_none()
    );
}
