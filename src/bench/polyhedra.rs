//! `penumbra bench --polyhedra`: the measurements of 001 Tables 7.2 and 7.4 on the nine
//! polyhedra of Table 7.1, with the thesis' figures beside ours.
//!
//! * Shading (Table 7.2): each polyhedron alone as a light above a glossy floor (Lambertian
//!   and GGX lobes, as the thesis shades), rendered analytically face by face (000 Sect. 4.4:
//!   each face a light, the others of the mesh subtracted from it), with silhouettes computed
//!   on the fly (001 Sect. 4.2, 4.3), and with silhouettes read from the BSP trees (Sect. 5).
//!   The thesis times a GPU shading pass at 1024×768; we time the whole CPU render of the
//!   image, so only the ratios compare.
//! * Precomputation (Table 7.4): build time (one core), nodes, silhouette vertices or edges,
//!   and the size at the thesis' 20 bytes per node and 4 bytes per vertex / 8 per edge.

use crate::geometry::{
    ExactBspLimits, ExactSilhouetteBsp, HoistedSilhouetteBsp, IndexedPolyhedron, Polyhedron,
    SilhouetteBsp, SilhouetteTriangulation, TriangulationLimits, TriangulationStats,
};
use crate::math::Pcg32;
use crate::render::{Image, RenderContext, RenderMethod, RenderSettings};
use crate::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};
use crate::scene::{Camera, Material, ObjectFlags, Scene, SceneObject, shapes};
use crate::shading::PrepareConfig;
use glam::{DAffine3, DVec3};
use web_time::Instant;

/// The thesis' figures for one polyhedron (Tables 7.2 and 7.4).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ThesisFigures {
    /// Shading times (ms): individual faces, silhouettes on the fly (`None`: not implemented
    /// for non-convex meshes), precomputed silhouettes.
    pub faces_ms: f64,
    pub on_the_fly_ms: Option<f64>,
    pub bsp_ms: f64,
    /// Table 7.3 (ms): triangulated faces, triangulated silhouettes.
    pub sample_faces_ms: f64,
    pub sample_silhouette_ms: f64,
    /// Precomputation: seconds, nodes, silhouette vertices (convex) or edges, kB.
    pub build_s: f64,
    pub nodes: usize,
    pub elements: usize,
    pub kb: f64,
}

const THESIS: [ThesisFigures; 9] = [
    fig([0.79, 0.38, 0.36], [0.89, 0.72], 0.0034, 53, 138, 1.6),
    fig([1.49, 0.64, 0.51], [1.34, 1.03], 0.025, 418, 1_838, 15.0),
    fig([2.23, 0.89, 0.70], [2.66, 1.28], 0.0016, 436, 2_674, 19.0),
    fig([1.85, 0.67, 0.46], [1.29, 0.86], 0.027, 1_828, 6_245, 62.0),
    fig(
        [7.16, 2.45, 0.80],
        [5.03, 1.46],
        3.7,
        147_660,
        947_142,
        6_700.0,
    ),
    fig(
        [1.18, f64::NAN, 0.89],
        [1.44, 0.99],
        0.023,
        332,
        1_165,
        16.0,
    ),
    fig(
        [3.47, f64::NAN, 1.93],
        [3.71, 2.04],
        0.92,
        5_232,
        44_569,
        460.0,
    ),
    fig(
        [1.42, f64::NAN, 1.00],
        [2.04, 1.58],
        0.022,
        414,
        1_215,
        18.0,
    ),
    fig([1.53, f64::NAN, 0.71], [1.57, 0.84], 0.010, 198, 407, 7.2),
];

/// Table 7.2's three times (NaN: not implemented in the thesis), Table 7.3's two, Table 7.4.
const fn fig(
    shading: [f64; 3],
    sampling: [f64; 2],
    build_s: f64,
    nodes: usize,
    elements: usize,
    kb: f64,
) -> ThesisFigures {
    ThesisFigures {
        faces_ms: shading[0],
        on_the_fly_ms: if shading[1].is_nan() {
            None
        } else {
            Some(shading[1])
        },
        bsp_ms: shading[2],
        sample_faces_ms: sampling[0],
        sample_silhouette_ms: sampling[1],
        build_s,
        nodes,
        elements,
        kb,
    }
}

/// Our measurements for one polyhedron.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PolyhedronRow {
    pub name: String,
    pub convex: bool,
    /// Render times (s) of the whole image, best of the repeats.
    pub faces_s: f64,
    pub on_the_fly_s: f64,
    pub bsp_s: f64,
    /// 001 Table 7.3: time per shading point to triangulate the light and draw one sample by
    /// solid angle (no ray traced), face by face and from the silhouette (ns).
    pub sample_faces_ns: f64,
    pub sample_silhouette_ns: f64,
    /// Triangles per shading point, face by face and from the silhouette.
    pub triangles_faces: f64,
    pub triangles_silhouette: f64,
    /// Largest difference of the BSP image from the face-by-face one (relative to the image's
    /// largest value): the same integral by two paths.
    pub bsp_vs_faces_max_rel: f64,
    /// The tree over the box of ±`box_radii` radii around the mesh.
    pub build_s: f64,
    pub nodes: usize,
    pub leaves: usize,
    pub elements: usize,
    pub bytes: usize,
    /// 001 Sect. 8: silhouette edges in the leaves, and stored as high as they stay valid.
    pub leaf_edges: usize,
    pub hoisted_edges: usize,
    /// Triangulated silhouettes over the same box (non-convex meshes; 001 Table 7.4).
    pub triangulation: Option<TriangulationStats>,
    /// Non-convex meshes: the build time without the validation of each leaf at its cell's
    /// corners, which the thesis does not do (best of three).
    pub unvalidated_s: Option<f64>,
    /// The real storage of both forms (bytes of planes, nodes and leaf or node data in
    /// memory), and the time of one lookup at random points of the box, the loops gathered
    /// (ns; the hoisted form also chains them): `geometry::trees::bsp_hoisted`.
    pub leaf_stored_bytes: usize,
    pub hoisted_stored_bytes: usize,
    pub leaf_lookup_ns: f64,
    pub hoisted_lookup_ns: f64,
    pub thesis: ThesisFigures,
}

/// 001 Table 7.4, "Triangulated silhouettes": seconds, nodes, triangles, kB.
const THESIS_TRIANGULATIONS: [(&str, f64, usize, usize, f64); 4] = [
    ("corner", 0.15, 332, 853, 17.0),
    ("extruded_cube", 14.0, 5_232, 40_027, 580.0),
    ("hole", 0.23, 414, 1_022, 21.0),
    ("bowl", 0.073, 198, 271, 7.2),
];

#[derive(Clone, Debug, serde::Serialize)]
pub struct PolyhedraReport {
    pub width: u32,
    pub height: u32,
    pub repeats: u32,
    pub box_radii: f64,
    pub rows: Vec<PolyhedronRow>,
}

/// Box (in mesh radii around the mesh's centre) of the trees of the precomputation table.
pub(crate) const BOX_RADII: f64 = 4.0;

/// The polyhedron `name` as the only light, 0.5 m across, 0.6 m above a 4 m glossy floor.
pub fn light_scene(name: &str) -> Option<Scene> {
    let mesh = thesis_polyhedron(name)?.transformed(
        &(DAffine3::from_translation(DVec3::new(0.0, 0.85, 0.0))
            * DAffine3::from_rotation_y(0.4)
            * DAffine3::from_rotation_x(0.3)
            * DAffine3::from_scale(DVec3::splat(0.5))),
    );
    let floor = SceneObject {
        name: "floor".into(),
        mesh: shapes::quad(
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(2.0, 0.0, 0.0),
        ),
        material: Material {
            name: "floor".into(),
            kd: DVec3::splat(0.5),
            ks: DVec3::splat(0.5),
            alpha: 0.3,
            ke: DVec3::ZERO,
        },
        flags: ObjectFlags {
            light: false,
            occluder: false,
            receiver: true,
            is_static: false,
        },
    };
    let light = SceneObject {
        name: name.into(),
        mesh,
        material: Material {
            name: "emitter".into(),
            kd: DVec3::ZERO,
            ks: DVec3::ZERO,
            alpha: 1.0,
            ke: DVec3::splat(3.0),
        },
        flags: ObjectFlags {
            light: true,
            occluder: true,
            receiver: false,
            is_static: false,
        },
    };
    Some(Scene {
        objects: vec![floor, light],
        camera: Some(Camera {
            eye: DVec3::new(0.0, 2.2, 2.4),
            target: DVec3::new(0.0, 0.2, 0.0),
            up: DVec3::Y,
            fov_deg: 50.0,
            aspect: None,
        }),
        ..Scene::default()
    })
}

fn best_render(
    ctx: &RenderContext,
    cam: &Camera,
    settings: &RenderSettings,
    repeats: u32,
) -> crate::Result<(Image, f64)> {
    let mut best = f64::INFINITY;
    let mut img = None;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let (i, _) = ctx.render(cam, settings, None)?;
        best = best.min(t.elapsed().as_secs_f64());
        img = Some(i);
    }
    Ok((img.expect("at least one render"), best))
}

/// Table 7.3: at the floor points seen by a 64×48 grid of camera rays, the time to triangulate
/// the light (`LightSet::build_with`) and draw one sample direction by solid angle, best of
/// three passes; and the triangles per point. No ray is traced, as in the thesis.
fn sampling_cost(ctx: &RenderContext, faces_only: bool) -> (f64, f64) {
    use crate::math::Frame;
    use crate::stochastic::LightSet;
    let Some(cam) = ctx.scene.camera else {
        return (0.0, 0.0);
    };
    let Ok(basis) = cam.basis() else {
        return (0.0, 0.0);
    };
    let mut points = Vec::new();
    for y in 0..48 {
        for x in 0..64 {
            let ray = crate::accel::Ray {
                origin: basis.eye,
                dir: basis.direction(x as f64 + 0.5, y as f64 + 0.5, 64, 48),
            };
            if let Some(h) = ctx.primary_hit(&ray)
                && h.receiver
            {
                points.push(h.point);
            }
        }
    }
    let mut set = LightSet::default();
    let (mut best, mut tris, mut sink) = (f64::INFINITY, 0usize, 0.0);
    for _ in 0..3 {
        tris = 0;
        let t = Instant::now();
        for (i, sp) in points.iter().enumerate() {
            let frame = Frame::from_normal_and_view(sp.normal, sp.view);
            set.build_with(&ctx.prepared, sp, &frame, faces_only);
            tris += set.tris.len();
            if let Some(r) = set.pick_run(0.5) {
                let u = (i as f64 * 0.618_033_988_75).fract();
                sink += set.sample(r, u, 0.5, 0.25).0.z;
            }
        }
        best = best.min(t.elapsed().as_secs_f64());
    }
    std::hint::black_box(sink);
    let n = points.len().max(1) as f64;
    (best / n * 1e9, tris as f64 / n)
}

/// Bytes of the leaf-stored and the hoisted form, and ns per lookup of each (`leaf` reads a
/// leaf's loops and sums its point codes; the hoisted form gathers and chains its edges and
/// sums their starts), at the same random points of the hoisted tree's box, in one run.
fn hoisting_costs(
    poly: &Polyhedron,
    hoisted: &HoistedSilhouetteBsp,
    leaf_bytes: usize,
    leaf: &dyn Fn(DVec3) -> u32,
) -> (usize, usize, f64, f64) {
    let mut rng = Pcg32::new(7, 11);
    let (lo, hi) = (hoisted.lo, hoisted.hi);
    let points: Vec<DVec3> = (0..20_000)
        .map(|_| lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
        .filter(|x| poly.face_planes.iter().any(|p| p.eval(*x) > 0.0))
        .collect();
    let mut buf = hoisted.scratch();
    let time = |f: &mut dyn FnMut(DVec3) -> u32| {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let start = Instant::now();
            let mut sum = 0u32;
            for &x in &points {
                sum = sum.wrapping_add(f(x));
            }
            std::hint::black_box(sum);
            best = best.min(start.elapsed().as_secs_f64() * 1e9 / points.len().max(1) as f64);
        }
        best
    };
    let leaf_ns = time(&mut |x| leaf(x));
    let hoisted_ns = time(&mut |x| {
        hoisted.loops(x, &mut buf);
        buf.iter().fold(0u32, |a, e| a.wrapping_add(e[0]))
    });
    (leaf_bytes, hoisted.stored_bytes(), leaf_ns, hoisted_ns)
}

/// Runs the measurements; `progress` receives a line per step.
pub fn run_polyhedra(
    width: u32,
    height: u32,
    repeats: u32,
    prepare: &PrepareConfig,
    progress: impl Fn(&str),
) -> crate::Result<PolyhedraReport> {
    let mut rows = Vec::new();
    for (row, thesis) in TABLE_7_1.iter().zip(THESIS) {
        progress(&format!("{}: rendering", row.name));
        let scene = light_scene(row.name).ok_or("unknown polyhedron")?;
        let cam = scene.camera.ok_or("no camera")?;
        // The trees whatever their size (the renderer's limits would leave the larger ones to
        // the on-the-fly path, which the middle column measures).
        let scene = std::sync::Arc::new(scene);
        let mut with_trees = RenderContext::configured(scene.clone(), prepare);
        with_trees
            .prepared
            .rebuild_silhouette_trees(usize::MAX, usize::MAX);
        let mut on_the_fly = RenderContext::configured(scene.clone(), prepare);
        on_the_fly.prepared.drop_silhouette_trees();
        let settings = |method: RenderMethod| RenderSettings {
            width,
            height,
            method,
            ..RenderSettings::default()
        };
        let (faces_img, faces_s) = best_render(
            &with_trees,
            &cam,
            &settings(RenderMethod::PerTriangle),
            repeats,
        )?;
        let (_, on_the_fly_s) = best_render(
            &on_the_fly,
            &cam,
            &settings(RenderMethod::Analytic),
            repeats,
        )?;
        let (bsp_img, bsp_s) = best_render(
            &with_trees,
            &cam,
            &settings(RenderMethod::Analytic),
            repeats,
        )?;
        let peak = faces_img
            .pixels
            .iter()
            .map(|p| p.max_element())
            .fold(0.0, f64::max)
            .max(1e-12);
        let bsp_vs_faces_max_rel = bsp_img
            .pixels
            .iter()
            .zip(&faces_img.pixels)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0, f64::max)
            / peak;

        progress(&format!("{}: sampling", row.name));
        let (sample_faces_ns, triangles_faces) = sampling_cost(&with_trees, true);
        let (sample_silhouette_ns, triangles_silhouette) = sampling_cost(&with_trees, false);

        progress(&format!("{}: building the tree", row.name));
        let m = thesis_polyhedron(row.name).ok_or("unknown polyhedron")?;
        let poly = IndexedPolyhedron::new(&m.positions, &m.faces);
        let (lo, hi) = (
            poly.center - DVec3::splat(BOX_RADII * poly.radius),
            poly.center + DVec3::splat(BOX_RADII * poly.radius),
        );
        let mut triangulation = None;
        let mut unvalidated_s = None;
        let stored;
        let (build_s, nodes, leaves, elements, bytes, (leaf_edges, hoisted_edges)) = if row.convex {
            let (t, mut s) = SilhouetteBsp::build_convex(&poly, lo, hi).ok_or("not convex")?;
            // Best of three: the build is deterministic, its time is not.
            for _ in 0..2 {
                if let Some((_, again)) = SilhouetteBsp::build_convex(&poly, lo, hi) {
                    s.seconds = s.seconds.min(again.seconds);
                }
            }
            let h = t.hoisted_edge_counts();
            let hoisted = HoistedSilhouetteBsp::from_convex(&t)?;
            stored = hoisting_costs(&poly, &hoisted, t.stored_bytes(), &|x| {
                t.lookup(x)
                    .map_or(0, |d| d.iter().fold(0u32, |a, &v| a.wrapping_add(v)))
            });
            (
                s.seconds,
                s.nodes,
                s.leaves,
                s.silhouette_vertices,
                s.table_7_4_bytes,
                h,
            )
        } else {
            let limits = ExactBspLimits {
                max_leaves: usize::MAX,
                ..ExactBspLimits::default()
            };
            let (t, mut s) =
                ExactSilhouetteBsp::build(&poly, lo, hi, limits).ok_or("tree over the limits")?;
            let best = |limits: ExactBspLimits, runs: usize| {
                (0..runs)
                    .filter_map(|_| ExactSilhouetteBsp::build(&poly, lo, hi, limits))
                    .map(|(_, s)| s.seconds)
                    .fold(f64::INFINITY, f64::min)
            };
            s.seconds = s.seconds.min(best(limits, 2));
            // As the thesis builds it: no validation of the leaves at their cells' corners.
            unvalidated_s = Some(best(
                ExactBspLimits {
                    validation_corners: 0,
                    ..limits
                },
                3,
            ));
            let h = t.hoisted_edge_counts();
            progress(&format!("{}: triangulating the silhouettes", row.name));
            triangulation =
                Some(SilhouetteTriangulation::build(&poly, &t, TriangulationLimits::default()).1);
            let hoisted = HoistedSilhouetteBsp::from_exact(&t)?;
            stored = hoisting_costs(&poly, &hoisted, t.stored_bytes(), &|x| {
                t.leaf_points(&poly, x).map_or(0, |p| {
                    p.fold(0u32, |a, p| a.wrapping_add(p.pack().unwrap_or(0)))
                })
            });
            (
                s.seconds,
                s.nodes,
                s.leaves,
                s.silhouette_edges,
                s.table_7_4_bytes,
                h,
            )
        };
        rows.push(PolyhedronRow {
            name: row.name.into(),
            convex: row.convex,
            faces_s,
            on_the_fly_s,
            bsp_s,
            bsp_vs_faces_max_rel,
            sample_faces_ns,
            sample_silhouette_ns,
            triangles_faces,
            triangles_silhouette,
            build_s,
            nodes,
            leaves,
            elements,
            bytes,
            leaf_edges,
            hoisted_edges,
            leaf_stored_bytes: stored.0,
            hoisted_stored_bytes: stored.1,
            leaf_lookup_ns: stored.2,
            hoisted_lookup_ns: stored.3,
            triangulation,
            unvalidated_s,
            thesis,
        });
    }
    Ok(PolyhedraReport {
        width,
        height,
        repeats,
        box_radii: BOX_RADII,
        rows,
    })
}

/// The two tables in Markdown, the thesis' figures beside ours.
pub fn polyhedra_markdown(r: &PolyhedraReport) -> String {
    let mut s = format!(
        "Shading (001 Table 7.2): one light, {}×{} CPU render (best of {}), analytic, \
         s; the thesis: GPU shading pass at 1024×768, ms. Ratios are to the face-by-face time.\n\n\
         | polyhedron | faces | on the fly | BSP | on the fly / faces | BSP / faces | thesis faces | thesis on the fly | thesis BSP | thesis BSP / faces | BSP − faces (max rel.) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        r.width, r.height, r.repeats
    );
    for row in &r.rows {
        let t = &row.thesis;
        s += &format!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | {} | {:.2} | {:.2} | {:.1e} |\n",
            row.name,
            row.faces_s,
            row.on_the_fly_s,
            row.bsp_s,
            row.on_the_fly_s / row.faces_s,
            row.bsp_s / row.faces_s,
            t.faces_ms,
            t.on_the_fly_ms.map_or("–".into(), |v| format!("{v:.2}")),
            t.bsp_ms,
            t.bsp_ms / t.faces_ms,
            row.bsp_vs_faces_max_rel,
        );
    }
    s += &format!(
        "\nPrecomputation (001 Table 7.4): tree over ±{} radii, one core; the thesis: C# on one \
         core of a Ryzen 5 3600; times are the best of three builds. Elements: silhouette \
         vertices (convex) or edges (non-convex). Non-convex trees validate each leaf at six \
         corners of its cell, which the thesis does not; \"without validation\" is the same build \
         without it, as the thesis builds.\n\n\
         | polyhedron | time (s) | without validation (s) | nodes | leaves | elements | size (kB) | thesis time (s) | thesis nodes | thesis elements | thesis size (kB) | speed-up | speed-up without validation |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        r.box_radii
    );
    for row in &r.rows {
        let t = &row.thesis;
        let (unvalidated, speedup) = row.unvalidated_s.map_or(("–".into(), "–".into()), |u| {
            (
                format!("{u:.4}"),
                format!("{:.0}×", t.build_s / u.max(1e-9)),
            )
        });
        s += &format!(
            "| {} | {:.4} | {unvalidated} | {} | {} | {} | {:.1} | {} | {} | {} | {} | {:.0}× | {speedup} |\n",
            row.name,
            row.build_s,
            row.nodes,
            row.leaves,
            row.elements,
            row.bytes as f64 / 1000.0,
            t.build_s,
            t.nodes,
            t.elements,
            t.kb,
            t.build_s / row.build_s.max(1e-9),
        );
    }
    s += "\nTriangulated silhouettes (001 Table 7.4), over the same trees: every leaf cell's \
         triangulation is proved for the whole cell (docs/silhouettes.md), the cell split across \
         the plane where a triangle flips when that is needed; leaves left without a proof are \
         sampled by faces. Size at 20 bytes per node and 12 per triangle. The thesis validated \
         each cell at 256 random points.\n\n\
         | polyhedron | time (s) | nodes | leaves | triangles | size (kB) | cells split | unproved leaves | unproved volume | triangles with optional vertices | thesis time (s) | thesis nodes | thesis triangles | thesis size (kB) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for row in &r.rows {
        let Some(t) = &row.triangulation else {
            continue;
        };
        let th = THESIS_TRIANGULATIONS.iter().find(|x| x.0 == row.name);
        let thesis = th.map_or("| – | – | – | –".to_string(), |x| {
            format!("| {} | {} | {} | {}", x.1, x.2, x.3, x.4)
        });
        s += &format!(
            "| {} | {:.4} | {} | {} | {} | {:.1} | {} | {} | {:.3} % | {} {thesis} |\n",
            row.name,
            t.seconds,
            t.nodes,
            t.leaves,
            t.triangles,
            t.table_7_4_bytes as f64 / 1000.0,
            t.split_cells,
            t.unproved_leaves,
            100.0 * t.unproved_volume_fraction,
            t.triangles_with_optional_vertices,
        );
    }
    s += "\nSampling (001 Table 7.3): per floor point, triangulating the light and drawing one \
          sample by solid angle, no ray traced (ns); the thesis: GPU pass at 1024×768, 1 spp \
          (ms). Silhouettes: fans of the silhouette for the convex and star-shaped meshes, the \
          precomputed triangles of the point's cell for hole and bowl.\n\n\
          | polyhedron | faces (ns) | silhouette (ns) | silhouette / faces | triangles, faces | triangles, silhouette | thesis faces | thesis silhouette | thesis ratio |\n\
          |---|---|---|---|---|---|---|---|---|\n";
    for row in &r.rows {
        let t = &row.thesis;
        s += &format!(
            "| {} | {:.0} | {:.0} | {:.2} | {:.1} | {:.1} | {:.2} | {:.2} | {:.2} |\n",
            row.name,
            row.sample_faces_ns,
            row.sample_silhouette_ns,
            row.sample_silhouette_ns / row.sample_faces_ns.max(1e-9),
            row.triangles_faces,
            row.triangles_silhouette,
            t.sample_faces_ms,
            t.sample_silhouette_ms,
            t.sample_silhouette_ms / t.sample_faces_ms,
        );
    }
    s += "\nEdges stored as high in the tree as they stay valid (001 Sect. 8: an edge kept at the \
          highest node below which every leaf has it), against storing them in every leaf:\n\n\
          | polyhedron | edges in the leaves | edges stored as high as valid | reduction | leaf form (kB) | hoisted form (kB) | leaf lookup (ns) | hoisted lookup (ns) |\n\
          |---|---|---|---|---|---|---|---|\n";
    for row in &r.rows {
        s += &format!(
            "| {} | {} | {} | {:.0} % | {:.1} | {:.1} | {:.0} | {:.0} |\n",
            row.name,
            row.leaf_edges,
            row.hoisted_edges,
            100.0 * (1.0 - row.hoisted_edges as f64 / row.leaf_edges.max(1) as f64),
            row.leaf_stored_bytes as f64 / 1000.0,
            row.hoisted_stored_bytes as f64 / 1000.0,
            row.leaf_lookup_ns,
            row.hoisted_lookup_ns,
        );
    }
    s += "\nThe two forms' sizes are the real arrays in memory (planes 32 B, nodes 16 B; leaf \
          form: 4 B per loop point, plus 8 B per loop range for non-convex meshes; hoisted form: \
          8 B per directed edge, since edges from several nodes are chained by their ends). In the \
          hoisted form, leaves left to the on-the-fly path (or inside the solid) hold nothing \
          back from their ancestors.\n";
    s
}
