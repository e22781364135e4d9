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

/// `mesh` without the faces whose centroid lies above `z`: an open mesh (an oriented manifold
/// with boundary edges).
fn cut_above(mesh: &penumbra::scene::Mesh, z: f64) -> IndexedPolyhedron {
    let faces: Vec<Vec<u32>> = mesh
        .faces
        .iter()
        .filter(|f| {
            let c: f64 =
                f.iter().map(|&i| mesh.positions[i as usize].z).sum::<f64>() / f.len() as f64;
            c <= z
        })
        .cloned()
        .collect();
    IndexedPolyhedron::new(&mesh.positions, &faces)
}

/// Trees of open meshes: the leaves hold the outline of contour *and* boundary
/// edges, and at random points of the box it equals the outline computed on the fly (the
/// same `exact_silhouette`, an open mesh's oracle tested against face-by-face shading in
/// `tests/blender_exports.rs`): an open box, a bowl, a tube and a folded sheet, seen from
/// everywhere around and inside them.
#[test]
fn bsp_outlines_of_open_meshes_equal_the_outline_on_the_fly() {
    use penumbra::scene::shapes::{icosphere, uv_ellipsoid};
    let mut rng = Pcg32::new(7, 26);
    let frame = Frame::from_z(DVec3::new(-0.3, 0.4, 0.87).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut scratch = ExactSilhouetteScratch::default();
    let cube = {
        let p: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
            .collect();
        // The unit cube without its top face (z = 1), outward-facing.
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![0, 1, 5, 4],
            vec![1, 3, 7, 5],
            vec![3, 2, 6, 7],
            vec![2, 0, 4, 6],
        ];
        IndexedPolyhedron::new(&p, &faces)
    };
    // A sheet folded like a W and extruded: non-convex, its folds cross each other's images.
    let folded = {
        let profile = [(0.0, 1.0), (0.5, 0.0), (1.0, 0.8), (1.5, 0.0), (2.0, 1.0)];
        let mut p = Vec::new();
        for &(x, z) in &profile {
            p.push(DVec3::new(x, 0.0, z));
            p.push(DVec3::new(x, 1.5, z));
        }
        let faces: Vec<Vec<u32>> = (0..profile.len() as u32 - 1)
            .map(|k| vec![2 * k, 2 * k + 2, 2 * k + 3, 2 * k + 1])
            .collect();
        IndexedPolyhedron::new(&p, &faces)
    };
    let meshes = [
        ("open box", cube),
        ("bowl", cut_above(&icosphere(DVec3::ZERO, 1.0, 1), 0.3)),
        (
            "tube",
            cut_above(
                &uv_ellipsoid(DVec3::ZERO, DVec3::new(0.5, 0.5, 1.0), 8, 6),
                0.7,
            ),
        ),
        ("folded sheet", folded),
    ];
    for (name, poly) in meshes {
        assert!(!poly.diagnostics.closed_manifold && poly.diagnostics.boundary_edges > 0);
        let (lo, hi) = (
            poly.center - DVec3::splat(3.0 * poly.radius),
            poly.center + DVec3::splat(3.0 * poly.radius),
        );
        let (bsp, stats) = ExactSilhouetteBsp::build(&poly, lo, hi, ExactBspLimits::default())
            .unwrap_or_else(|| panic!("{name}: no tree"));
        let (mut checked, mut from_tree, mut wrong) = (0, 0, 0);
        while checked < 2000 {
            let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            if exact_silhouette(&poly, x, &frame, &mut b, &mut scratch).is_err() {
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
            "{name}: {} leaves, {from_tree} of {checked} points read from the tree, {wrong} wrong",
            stats.leaves
        );
        // No inside: every leaf answers, but for those the validation left to the fly.
        assert!(
            from_tree * 10 >= checked * 9,
            "{name}: the tree answers too rarely"
        );
        assert_eq!(wrong, 0, "{name}: wrong outlines from the tree");
    }
}

/// The renderer reads an open occluder's outline from its tree (`MeshPath::OpenTree`), and the
/// image equals the face-by-face one (a second algorithm: every face subtracted on its own) to
/// 1e-9 of the brightest pixel, and no pixel is brighter than unshadowed: an open box and a
/// folded sheet over a floor, under a quad light.
#[test]
fn open_occluders_shade_from_their_trees_as_face_by_face() {
    use penumbra::render::request::RenderRequest;
    use penumbra::render::{RenderContext, RenderMethod, RenderSettings};
    use penumbra::scene::Camera;
    use penumbra::shading::PathKind;
    let obj = "\
o floor
v -3 0 -3
v 3 0 -3
v 3 0 3
v -3 0 3
usemtl grey
f 1 4 3 2
o box
v -0.5 0.6 -0.5
v 0.5 0.6 -0.5
v -0.5 0.6 0.5
v 0.5 0.6 0.5
v -0.5 1.4 -0.5
v 0.5 1.4 -0.5
v -0.5 1.4 0.5
v 0.5 1.4 0.5
usemtl grey
f 5 6 8 7
f 5 9 10 6
f 6 10 12 8
f 8 12 11 7
f 7 11 9 5
o sheet
v -2.0 0.5 1.0
v -2.0 0.5 2.2
v -1.5 0.9 1.0
v -1.5 0.9 2.2
v -1.0 0.55 1.0
v -1.0 0.55 2.2
v -0.5 0.9 1.0
v -0.5 0.9 2.2
usemtl grey
f 13 15 16 14
f 15 17 18 16
f 17 19 20 18
o light
v -0.6 2.5 -0.4
v 0.6 2.5 -0.4
v 0.6 2.5 0.4
v -0.6 2.5 0.4
usemtl light
f 21 22 23 24
";
    let mtl = "newmtl grey\nKd 0.7 0.7 0.7\nnewmtl light\nKd 0 0 0\nKe 5 5 5\n";
    let mut scene =
        penumbra::scene::obj::load_obj_str(obj, Some(mtl), "open_occluders.obj").unwrap();
    scene.camera = Some(Camera {
        eye: DVec3::new(0.5, 4.0, 5.0),
        target: DVec3::new(-0.3, 0.4, 0.3),
        up: DVec3::Y,
        fov_deg: 45.0,
        aspect: None,
    });
    let settings = |method| RenderSettings {
        width: 64,
        height: 48,
        aa: 1,
        method,
        ..RenderSettings::default()
    };
    let ctx = RenderContext::for_render(
        &scene,
        &RenderRequest::with_settings(settings(RenderMethod::Analytic)),
    );
    // The box's tree pays at this size; the sheet's does not (the cost model), and it
    // computes its outline at each point.
    let path = |name: &str| {
        let o = ctx
            .prepared
            .objects
            .iter()
            .find(|o| o.name == name)
            .unwrap();
        o.kind()
    };
    assert_eq!(
        path("box"),
        PathKind::OpenTree,
        "{:?}",
        ctx.prepared.report.lines()
    );
    assert!(matches!(
        path("sheet"),
        PathKind::OpenTree | PathKind::OpenAtPoint
    ));
    let camera = scene.camera.unwrap();
    let render = |m| ctx.render_full(&camera, &settings(m), None).unwrap();
    let analytic = render(RenderMethod::Analytic);
    let faces = render(RenderMethod::PerTriangle);
    let unshadowed = render(RenderMethod::Unshadowed);
    assert_eq!(analytic.stats.violations, 0);
    let brightest = unshadowed
        .image
        .pixels
        .iter()
        .map(|p| p.max_element())
        .fold(0.0, f64::max);
    let mut shadowed = 0;
    for ((a, t), u) in analytic
        .image
        .pixels
        .iter()
        .zip(&faces.image.pixels)
        .zip(&unshadowed.image.pixels)
    {
        assert!(
            (*a - *t).abs().max_element() <= 1e-9 * brightest,
            "{a} vs {t}"
        );
        assert!(a.cmple(*u * (1.0 + 1e-9) + 1e-12).all(), "{a} above {u}");
        shadowed += (a.x < 0.9 * u.x) as usize;
    }
    assert!(shadowed > 100, "{shadowed} pixels in shadow");
}
