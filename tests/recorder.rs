//! The recording is the computation: what the stage recorder captured at a pixel adds up to the
//! value the renderer produced there, and recording does not change that value.

use penumbra::ltc::form_factor;
use penumbra::render::{RenderContext, RenderSettings, subpixel_rays};
use penumbra::scene::scene_file;
use penumbra::shading::{Lobe, Method, NoRecorder, ShadingScratch, Stage, StageRecording};
use std::f64::consts::TAU;

#[test]
fn recorded_stages_reproduce_the_rendered_pixels() {
    let scene = scene_file::load_embedded("default").unwrap();
    let ctx = RenderContext::new(&scene);
    let cam = scene.camera.unwrap();
    let basis = cam.basis().unwrap();
    let settings = RenderSettings {
        width: 24,
        height: 18,
        aa: 1,
        method: Method::Analytic.into(),
        ..Default::default()
    };
    let (img, _) = ctx.render(&cam, &settings, None).unwrap();
    let mut scratch = ShadingScratch::default();
    let mut checked = 0;
    for y in 0..settings.height {
        for x in 0..settings.width {
            let ray = subpixel_rays(&basis, x, y, 1, settings.width, settings.height)
                .next()
                .unwrap();
            let mut rec = StageRecording::new(true);
            let recorded = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut rec);
            let plain = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut NoRecorder);
            // Bit for bit: the recorder only observes.
            assert_eq!(recorded, plain);
            assert_eq!(plain, img.at(x, y));
            let Some(hit) = ctx.primary_hit(&ray) else {
                continue;
            };
            let sum = rec
                .lights
                .iter()
                .map(|l| l.diffuse + l.specular)
                .sum::<glam::DVec3>()
                + hit.emitted;
            assert!((sum - plain).abs().max_element() <= 1e-12 * plain.max_element().max(1.0));
            for l in &rec.lights {
                // The diffuse integral recorded is the form factor of the recorded visible polygon.
                if let Some((_, visible)) = l.polygons.iter().find(|(s, _)| *s == Stage::Visible) {
                    let (_, _, _, e) = l
                        .lobes
                        .iter()
                        .find(|(lobe, ..)| *lobe == Lobe::Diffuse)
                        .unwrap();
                    assert!((form_factor(visible.loops()).max(0.0) - e).abs() < 1e-15);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 50);
}

/// Calls `f` with the analytic recording of the centre of every pixel of a 16×12 image of the
/// `fig4` scene, as the renderer computes it.
fn for_each_fig4_recording(mut f: impl FnMut(&StageRecording)) {
    let scene = scene_file::load_embedded("fig4").unwrap();
    let ctx = RenderContext::new(&scene);
    let basis = scene.camera.unwrap().basis().unwrap();
    let (w, h) = (16, 12);
    let mut scratch = ShadingScratch::default();
    for y in 0..h {
        for x in 0..w {
            let ray = subpixel_rays(&basis, x, y, 1, w, h).next().unwrap();
            let mut rec = StageRecording::new(false);
            ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut rec);
            f(&rec);
        }
    }
}

/// The recorded edge terms of each lobe are the terms of the integral the stage computed: for
/// the diffuse lobe (the identity LTC) they sum to the recorded form factor, and each one is
/// the edge integral of its arc (000 Eq. 9) evaluated independently here.
#[test]
fn recorded_edge_terms_sum_to_the_recorded_integral() {
    use penumbra::ltc::edge_integral;
    let mut checked = 0;
    for_each_fig4_recording(|rec| {
        for l in &rec.lights {
            assert_eq!(l.lobes.len(), l.lobe_edge_terms.len());
            for ((lobe, _, clipped, integral), (lobe2, terms)) in
                l.lobes.iter().zip(&l.lobe_edge_terms)
            {
                assert_eq!(lobe, lobe2);
                for (lp, t) in clipped.loops().zip(terms) {
                    if lp.len() < 3 {
                        assert!(t.is_empty());
                        continue;
                    }
                    assert_eq!(t.len(), lp.len());
                    for k in 0..lp.len() {
                        let e = edge_integral(lp[k], lp[(k + 1) % lp.len()]) / TAU;
                        assert!((t[k] - e).abs() <= 1e-15, "{} vs {e}", t[k]);
                    }
                }
                if *lobe == Lobe::Diffuse {
                    let sum: f64 = terms.iter().flatten().sum();
                    assert!(
                        (sum.max(0.0) - integral).abs() <= 1e-12,
                        "{sum} vs {integral}"
                    );
                    checked += (*integral > 0.0) as usize;
                }
            }
        }
    });
    assert!(checked > 50, "{checked} lit diffuse lobes checked");
}

/// The recorded contour edges are what the silhouette stage chained: for every whole light (a
/// convex or flat mesh) there are as many contour edges as silhouette vertices, and every arc
/// of the recorded silhouette loops is one of the recorded edges, with the same orientation.
#[test]
fn recorded_contour_edges_chain_into_the_recorded_silhouette() {
    let mut checked = 0;
    for_each_fig4_recording(|rec| {
        // A light below the tangent plane is not looked at (no stage is recorded for it).
        for l in rec
            .lights
            .iter()
            .filter(|l| l.piece.is_none() && !l.polygons.is_empty())
        {
            let (_, edges) = l.contours.iter().find(|(o, _)| o.is_none()).unwrap();
            let (_, sil) = l
                .polygons
                .iter()
                .find(|(s, _)| *s == Stage::Silhouette)
                .unwrap();
            let verts: usize = sil.loops().map(|lp| lp.len()).sum();
            assert_eq!(edges.len(), verts);
            // Each silhouette arc (v_k, v_k+1) is one recorded contour edge.
            for lp in sil.loops() {
                for k in 0..lp.len() {
                    let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
                    assert!(
                        edges
                            .iter()
                            .any(|[p, q]| (*p - a).length() < 1e-12 && (*q - b).length() < 1e-12),
                        "silhouette arc {a} → {b} is not a contour edge"
                    );
                }
            }
            checked += 1;
        }
    });
    assert!(checked > 100, "{checked} light records checked");
}

/// Non-convex lights and occluders: recording changes no value (bit for bit), and it says how
/// each exact silhouette was found. With the trees the `nonconvex` scene reads them; with the
/// trees dropped the silhouettes are computed on the fly and the recording holds the contour
/// pieces the ray test rejected and the apparent intersections.
#[test]
fn exact_silhouettes_are_recorded_as_found() {
    let scene = scene_file::load_embedded("nonconvex").unwrap();
    let cam = scene.camera.unwrap();
    let basis = cam.basis().unwrap();
    let with_trees = RenderContext::new(&scene);
    let mut on_the_fly = RenderContext::new(&scene);
    on_the_fly.prepared.drop_silhouette_trees();
    let (w, h) = (24, 18);
    let mut scratch = ShadingScratch::default();
    let (mut from_tree, mut rejected, mut crossings) = (0, 0, 0);
    for (ctx, trees) in [(&with_trees, true), (&on_the_fly, false)] {
        for y in 0..h {
            for x in 0..w {
                let ray = subpixel_rays(&basis, x, y, 1, w, h).next().unwrap();
                let mut rec = StageRecording::new(false);
                let recorded = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut rec);
                let plain = ctx.radiance(&ray, Method::Analytic, &mut scratch, &mut NoRecorder);
                assert_eq!(recorded, plain);
                // Contour edges are recorded where the path computed them: never for an exact
                // silhouette read from a tree (the debugger draws only what was computed).
                for l in &rec.lights {
                    for e in &l.exact {
                        let recorded = l.contours.iter().any(|(o, _)| *o == e.occluder);
                        assert_eq!(recorded, !e.from_tree, "occluder {:?}", e.occluder);
                    }
                }
                for e in rec.lights.iter().flat_map(|l| &l.exact) {
                    assert_eq!(e.from_tree, trees);
                    from_tree += e.from_tree as usize;
                    rejected += e.rejected.len();
                    crossings += e.crossings.len();
                    assert!(e.crossings.iter().all(|c| (c.length() - 1.0).abs() < 1e-12));
                }
            }
        }
    }
    assert!(from_tree > 100, "{from_tree} silhouettes read from trees");
    assert!(
        rejected > 0 && crossings > 0,
        "{rejected} rejected pieces, {crossings} crossings"
    );
}
