//! Candidate edges shared by the shading points of a tile (`geometry::silhouettes::tile_candidates`)
//! against each point on its own, whose window query of the edge hierarchy is a second
//! enumeration of the same edges: at every camera sample of an image of Blender's monkey,
//! shading with the point's region shared gives the radiance of shading it alone, bit for bit,
//! for regions of 2 × 2-pixel blocks (the renderer's) and of whole 16 × 16 tiles (far looser
//! lists); and the shared path does run.

use glam::DVec3;
use penumbra::geometry::TileRegion;
use penumbra::render::request::RenderRequest;
use penumbra::render::{RenderContext, RenderMethod, RenderSettings, subpixel_rays};
use penumbra::scene::scene_file::load_scene;
use penumbra::shading::{Method, NoRecorder, ShadingScratch};
use std::path::Path;

/// Shades every sample of a `w` × `h` image (`aa` × `aa` samples a pixel) of `file` with and
/// without sharing within regions of `block` × `block` pixels (per object) of each 16 × 16
/// tile; panics where they differ (by more than `rel` relative; 0: in any bit). Returns the
/// windowed queries that shared a list and the lists built.
fn compare(file: &str, (w, h, aa): (u32, u32, u32), block: u32, rel: f64) -> (u64, u64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/blender")
        .join(file);
    let scene = load_scene(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
    let camera = scene.camera.expect("a camera");
    let settings = RenderSettings {
        width: w,
        height: h,
        aa,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let ctx = RenderContext::for_render(&scene, &RenderRequest::with_settings(settings));
    let basis = camera.basis().unwrap();
    let (mut shared, mut alone) = (ShadingScratch::default(), ShadingScratch::default());
    for ty in (0..h).step_by(16) {
        for tx in (0..w).step_by(16) {
            // The tile's hits, and the box of each (object, block).
            let mut hits = Vec::new();
            let mut boxes: Vec<((u32, u32), DVec3, DVec3)> = Vec::new();
            for y in ty..(ty + 16).min(h) {
                for x in tx..(tx + 16).min(w) {
                    for ray in subpixel_rays(&basis, x, y, aa, w, h) {
                        let Some(hit) = ctx.primary_hit(&ray) else {
                            continue;
                        };
                        let key = (
                            hit.point.object.unwrap(),
                            ((y - ty) / block) * 16 + (x - tx) / block,
                        );
                        let p = hit.point.position;
                        let i = match boxes.iter().position(|b| b.0 == key) {
                            Some(i) => i,
                            None => {
                                boxes.push((key, p, p));
                                boxes.len() - 1
                            }
                        };
                        boxes[i].1 = boxes[i].1.min(p);
                        boxes[i].2 = boxes[i].2.max(p);
                        hits.push((hit, i));
                    }
                }
            }
            let regions: Vec<TileRegion> = boxes
                .iter()
                .map(|&(_, lo, hi)| TileRegion::around(lo, hi))
                .collect();
            for (hit, i) in &hits {
                shared.share_with_tile(Some(regions[*i]));
                let a = ctx.radiance_at(hit, Method::Analytic, &mut shared, &mut NoRecorder);
                let b = ctx.radiance_at(hit, Method::Analytic, &mut alone, &mut NoRecorder);
                // Bit for bit where the point alone queries the same hierarchy (the same
                // edges in the same order); within 1e-12 relative where it queries the faces'
                // hierarchy instead (the same edges in another order: sums in another order).
                let close = match rel {
                    0.0 => a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits),
                    r => (a - b).abs().max_element() <= r * a.abs().max_element(),
                };
                assert!(
                    close,
                    "{file} at {} (region {:?}): {a} shared, {b} alone",
                    hit.point.position, regions[*i]
                );
            }
        }
    }
    let (built, used) = shared.tile_sharing();
    assert_eq!(alone.tile_sharing(), (0, 0));
    (used, built)
}

/// The "penumbra" text's hierarchy does not pay for single points, which query the faces'
/// hierarchy instead; its regions share lists from it all the same.
#[test]
fn the_texts_points_sharing_their_tiles_candidates_shade_as_alone() {
    let (used, built) = compare("penumbra_text.toml", (64, 48, 2), 2, 1e-12);
    assert!(
        used > 100 && used > 2 * built,
        "{used} uses of {built} lists"
    );
}

#[test]
fn points_sharing_their_tiles_candidates_shade_as_alone() {
    for (block, size) in [(2, (64, 48, 2)), (16, (96, 64, 1))] {
        let (used, built) = compare("suzanne.toml", size, block, 0.0);
        // The monkey is in front of the light at many of these points: the lists are used,
        // each by several points.
        assert!(
            used > 500 && used > 3 * built,
            "block {block}: {used} uses of {built} lists"
        );
    }
}

/// The probe shades its pixel through its tile's region, as an `--aa 1` render does: the same
/// value, and a recording of what the region shared, which the stepper names.
#[test]
fn the_probe_records_what_its_tile_shared() {
    use penumbra::inspect::probe;
    use penumbra::views::stages::probe_steps;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender/suzanne.toml");
    let scene = load_scene(&path).unwrap();
    let camera = scene.camera.unwrap();
    let size = (128, 128);
    let settings = RenderSettings {
        width: size.0,
        height: size.1,
        aa: 1,
        method: RenderMethod::Analytic,
        ..RenderSettings::default()
    };
    let ctx = RenderContext::for_render(&scene, &RenderRequest::with_settings(settings));
    let image = ctx.render(&camera, &settings, None).unwrap().0;
    let mut recorded = 0;
    // Floor points in the monkey's penumbra and shadow, and points on the monkey.
    for (x, y) in [
        (60, 100),
        (72, 100),
        (80, 96),
        (40, 110),
        (64, 64),
        (70, 60),
    ] {
        let p = probe(
            &ctx,
            "suzanne",
            &camera,
            size,
            (x as f64, y as f64),
            Method::Analytic,
            false,
        )
        .unwrap();
        let pixel = image.pixels[(y * size.0 + x) as usize];
        assert_eq!(p.radiance, pixel, "pixel ({x}, {y})");
        let shares: Vec<_> = p
            .recording
            .lights
            .iter()
            .flat_map(|l| &l.tile_shares)
            .collect();
        for t in &shares {
            if let Some(n) = t.shared_edges {
                assert!(n < t.mesh_edges && t.radius > 0.0, "({x}, {y}): {t:?}");
                recorded += 1;
                let label = format!("the {n} of {} edges its tile's region", t.mesh_edges);
                assert!(
                    probe_steps(&p).iter().any(|s| s.label.contains(&label)),
                    "({x}, {y}): no step names {label:?}"
                );
            }
        }
    }
    assert!(recorded >= 3, "{recorded} probes shared their tile's edges");
}
