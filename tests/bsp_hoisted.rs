//! Silhouette edges stored as high in the tree as they stay valid (001 Sect. 8,
//! `geometry::trees::bsp_hoisted`), against two oracles at thousands of random points per Table 7.1
//! polyhedron: the leaf-stored tree it was made from (the same loops as cyclic sequences of
//! points) and the silhouette computed on the fly.

use glam::DVec3;
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::LOOP_END;
use penumbra::geometry::loop_runs;
use penumbra::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, ExactSilhouetteScratch, HoistedSilhouetteBsp, Sidedness,
    SilhouetteBsp, SilhouetteScratch, SphericalPolygon, exact_silhouette, silhouette,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};

use crate::silhouette_common;
use silhouette_common::{is_inside, same_loops, triangles};

/// Loops as lists of point codes, each rotated to start at its smallest code, sorted: equal
/// for two silhouettes with the same cyclic sequences.
fn canonical(mut loops: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    for l in &mut loops {
        if let Some(k) = (0..l.len()).min_by_key(|&k| l[k]) {
            l.rotate_left(k);
        }
    }
    loops.sort();
    loops
}

#[test]
fn hoisted_trees_give_the_leaf_stored_and_the_on_the_fly_silhouettes() {
    let mut rng = Pcg32::new(21, 5);
    let frame = Frame::from_z(DVec3::new(-0.4, 0.2, 0.89).normalize());
    let (mut a, mut b) = (SphericalPolygon::new(), SphericalPolygon::new());
    let mut convex_scratch = SilhouetteScratch::default();
    let mut exact_scratch = ExactSilhouetteScratch::default();
    for row in &TABLE_7_1 {
        let m = thesis_polyhedron(row.name).unwrap();
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let (lo, hi) = (
            poly.center - DVec3::splat(3.0 * poly.radius),
            poly.center + DVec3::splat(3.0 * poly.radius),
        );
        let (convex, exact) = if row.convex {
            (
                SilhouetteBsp::build_convex(&poly, lo, hi).map(|t| t.0),
                None,
            )
        } else {
            let t = ExactSilhouetteBsp::build(&poly, lo, hi, ExactBspLimits::default());
            (None, t.map(|t| t.0))
        };
        let hoisted = match (&convex, &exact) {
            (Some(t), _) => HoistedSilhouetteBsp::from_convex(t),
            (_, Some(t)) => HoistedSilhouetteBsp::from_exact(t),
            _ => panic!("{}: no tree", row.name),
        }
        .unwrap();
        let leaf_bytes = convex.as_ref().map_or_else(
            || exact.as_ref().unwrap().stored_bytes(),
            |t| t.stored_bytes(),
        );
        eprintln!(
            "{}: {} edges hoisted, {} B vs {} B in the leaves",
            row.name,
            hoisted.edges.len(),
            hoisted.stored_bytes(),
            leaf_bytes
        );
        let mut buf = hoisted.scratch();
        let capacity = buf.capacity();
        let (mut checked, mut compared) = (0, 0);
        let mesh = triangles(&poly);
        while checked < 3000 {
            let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            if is_inside(&mesh, x) {
                continue;
            }
            checked += 1;
            // The leaf-stored loops, as point codes.
            let leaf: Option<Vec<Vec<u32>>> = match (&convex, &exact) {
                (Some(t), _) => t.lookup(x).map(|d| {
                    d.split(|&v| v == LOOP_END)
                        .filter(|l| !l.is_empty())
                        .map(<[u32]>::to_vec)
                        .collect()
                }),
                (_, Some(t)) => t.leaf_points(&poly, x).is_some().then(|| {
                    let mut loops = Vec::new();
                    let mut cur = Vec::new();
                    // Rebuild the loop structure from the silhouette read the ordinary way.
                    let ok = t.silhouette(&poly, x, &frame, &mut a);
                    assert!(ok);
                    let mut pts = t.leaf_points(&poly, x).unwrap();
                    for lp in a.loops() {
                        for _ in 0..lp.len() {
                            cur.push(pts.next().unwrap().pack().unwrap());
                        }
                        loops.push(std::mem::take(&mut cur));
                    }
                    assert!(
                        pts.next().is_none(),
                        "{}: a point without direction",
                        row.name
                    );
                    loops
                }),
                _ => unreachable!(),
            };
            let got = hoisted.loops(x, &mut buf);
            assert_eq!(
                buf.capacity(),
                capacity,
                "{}: the lookup allocated",
                row.name
            );
            assert_eq!(got, leaf.is_some(), "{} at {x}", row.name);
            let Some(leaf) = leaf else {
                continue;
            };
            let mine: Vec<Vec<u32>> = loop_runs(&buf)
                .map(|run| run.iter().map(|e| e[0]).collect())
                .collect();
            assert_eq!(canonical(mine), canonical(leaf), "{} at {x}", row.name);
            // Against the silhouette on the fly.
            assert!(hoisted.silhouette_at(&poly, x, x, &frame, &mut a, &mut buf));
            let fly_ok = if row.convex {
                silhouette(
                    &poly,
                    x,
                    &frame,
                    Sidedness::FrontOnly,
                    &mut b,
                    &mut convex_scratch,
                );
                true
            } else {
                exact_silhouette(&poly, x, &frame, &mut b, &mut exact_scratch).is_ok()
            };
            if fly_ok {
                compared += 1;
                assert!(same_loops(&a, &b, 1e-9), "{} at {x}", row.name);
            }
        }
        eprintln!(
            "{}: {compared} of {checked} compared with the silhouette on the fly",
            row.name
        );
        assert!(compared * 10 >= checked * 9, "{}", row.name);
    }
}

/// Hoisting saves edges: every edge is stored once per subtree it is common to, so the hoisted
/// form never holds more edges than the leaves, and an edge common to the whole tree is stored
/// once.
#[test]
fn hoisting_never_stores_more_edges_than_the_leaves() {
    for row in TABLE_7_1.iter().filter(|r| r.convex) {
        let m = thesis_polyhedron(row.name).unwrap();
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let r = 3.0 * poly.radius;
        let (t, _) = SilhouetteBsp::build_convex(&poly, poly.center - r, poly.center + r).unwrap();
        let h = HoistedSilhouetteBsp::from_convex(&t).unwrap();
        let (in_leaves, hoisted) = t.hoisted_edge_counts();
        assert_eq!(h.edges.len(), hoisted, "{}", row.name);
        assert!(hoisted <= in_leaves, "{}", row.name);
    }
}

/// The renderer on the hoisted trees (`PreparedScene::use_hoisted_trees`, selectable with
/// `PENUMBRA_HOISTED_TREES=1`) renders the image of the leaf-stored trees: the same loops, read
/// off the same vertices (a loop may start elsewhere: rounding only).
#[test]
fn the_renderer_on_hoisted_trees_renders_the_same_image() {
    use penumbra::render::{RenderContext, RenderSettings};
    use penumbra::scene::scene_file;
    for name in ["polyhedra", "instances"] {
        let scene = scene_file::load_embedded(name).unwrap();
        let leaf = RenderContext::new(&scene);
        let mut hoisted = RenderContext::new(&scene);
        hoisted.prepared.use_hoisted_trees();
        let n = hoisted
            .prepared
            .objects
            .iter()
            .filter(|o| o.hoisted_tree().is_some())
            .count();
        assert!(n >= 5, "{name}: {n} hoisted trees");
        let cam = scene.camera.unwrap();
        let settings = RenderSettings {
            width: 64,
            height: 48,
            ..RenderSettings::default()
        };
        let a = leaf.render(&cam, &settings, None).unwrap().0.pixels;
        let b = hoisted.render(&cam, &settings, None).unwrap().0.pixels;
        let peak = a.iter().map(|p| p.max_element()).fold(0.0, f64::max);
        let worst = a
            .iter()
            .zip(&b)
            .map(|(p, q)| (*p - *q).abs().max_element())
            .fold(0.0, f64::max)
            / peak;
        eprintln!("{name}: max difference hoisted vs leaf-stored {worst:.2e} of the peak");
        assert!(worst < 1e-12, "{name}: {worst:.2e}");
    }
}
