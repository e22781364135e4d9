//! The silhouette of a large closed mesh inside a light's window (`geometry::silhouettes::windowed_silhouette`)
//! against the whole exact silhouette (a second algorithm, tested against ray casting in
//! `exact_silhouette.rs`): shading through one equals shading through the other, at floor
//! points under the Stanford bunny and around a displaced icosphere, for quad lights of many
//! sizes and places; and the windowed path does run (it is not always falling back).

use glam::DVec3;
use penumbra::geometry::{
    ExactSilhouetteScratch, SphericalPolygon, WindowScratch, exact_silhouette,
    exact_silhouette_in_window,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::shapes::quad;
use penumbra::scene::{Material, ObjectFlags, Scene, SceneObject};
use penumbra::shading::{
    Method, NoRecorder, PathKind, PrepareOptions, PreparedScene, ShadingPoint, ShadingScratch,
    shade,
};

fn object(name: &str, mesh: penumbra::scene::Mesh, light: bool) -> SceneObject {
    SceneObject {
        name: name.into(),
        mesh,
        material: Material {
            ke: if light { DVec3::ONE } else { DVec3::ZERO },
            ..Material::default()
        },
        flags: ObjectFlags {
            light,
            occluder: !light,
            receiver: true,
            is_static: false,
        },
    }
}

fn bunny() -> penumbra::scene::Mesh {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/bunny.obj");
    let scene = penumbra::scene::obj::load_obj(&path).expect("assets/meshes/bunny.obj");
    // Standing on y = 0, as in assets/scenes/bunny.toml.
    let lowest = scene.objects[0]
        .mesh
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    scene.objects[0]
        .mesh
        .translated(DVec3::new(0.0, -lowest, 0.0))
}

/// Shading with the windowed silhouette and with the whole one (the mesh's face-to-edge map
/// removed, which the windowed path needs), at `points`; returns the largest difference
/// relative to the unoccluded value and how often the windowed path succeeded.
fn compare(scene: &Scene, points: &[ShadingPoint]) -> (f64, usize) {
    compare_object(scene, "mesh", points)
}

/// [`compare`] for the occluder called `name`.
fn compare_object(scene: &Scene, name: &str, points: &[ShadingPoint]) -> (f64, usize) {
    let options = PrepareOptions {
        ..PrepareOptions::default()
    };
    let windowed = PreparedScene::prepare(scene, options);
    let occ = windowed
        .objects
        .iter()
        .find(|o| o.name == name)
        .expect("the occluder");
    assert!(matches!(
        occ.kind(),
        PathKind::ExactInWindow | PathKind::OpenInWindow
    ));
    let mut whole = windowed.clone();
    for o in &mut whole.objects {
        o.poly.index.face_edges = None;
    }
    let mut unshadowed = windowed.clone();
    unshadowed.occluders.clear();
    let material = Material {
        kd: DVec3::ONE,
        ks: DVec3::splat(0.5),
        alpha: 0.3,
        ..Material::default()
    };
    let mut scratch = ShadingScratch::default();
    let mut worst = 0.0f64;
    let (light_id, _) = windowed.lights[0];
    let light = &windowed.objects[light_id as usize];
    let mut window_scratch = WindowScratch::default();
    let (mut sph, mut light_sph) = (SphericalPolygon::default(), SphericalPolygon::default());
    let mut exact = ExactSilhouetteScratch::default();
    let mut succeeded = 0;
    for sp in points {
        let a = shade(
            &windowed,
            sp,
            &material,
            Method::Analytic,
            &mut scratch,
            &mut NoRecorder,
        )
        .x;
        let b = shade(
            &whole,
            sp,
            &material,
            Method::Analytic,
            &mut scratch,
            &mut NoRecorder,
        )
        .x;
        let u = shade(
            &unshadowed,
            sp,
            &material,
            Method::Analytic,
            &mut scratch,
            &mut NoRecorder,
        )
        .x;
        assert!(a.is_finite() && b.is_finite());
        worst = worst.max((a - b).abs() / u.max(1e-12));
        // Does the window itself (the light's outline from the point) take the windowed path?
        let frame = Frame::from_normal_and_view(sp.normal, sp.view);
        if light
            .exact_silhouette(sp.position, &frame, &mut light_sph, &mut exact)
            .is_err()
        {
            penumbra::geometry::silhouette(
                &light.poly,
                sp.position,
                &frame,
                penumbra::geometry::Sidedness::FrontOnly,
                &mut light_sph,
                &mut Default::default(),
            );
        }
        if light_sph.loop_count() == 1
            && exact_silhouette_in_window(
                &occ.poly,
                sp.position,
                &frame,
                light_sph.loop_at(0),
                false,
                &mut sph,
                &mut window_scratch,
            )
            .is_ok()
        {
            succeeded += 1;
            // The sweep over the clipped arcs finds the crossings all pairs find, bit for bit.
            let mut all_pairs = WindowScratch::default();
            all_pairs.all_pairs = true;
            let mut reference = SphericalPolygon::new();
            assert!(
                exact_silhouette_in_window(
                    &occ.poly,
                    sp.position,
                    &frame,
                    light_sph.loop_at(0),
                    false,
                    &mut reference,
                    &mut all_pairs,
                )
                .is_ok()
            );
            assert_eq!(sph, reference, "at {}", sp.position);
        }
        // The whole silhouette exists too (the point is outside the mesh).
        let _ = exact_silhouette(&occ.poly, sp.position, &frame, &mut sph, &mut exact);
    }
    (worst, succeeded)
}

#[test]
fn windowed_silhouette_shades_like_the_whole_one_under_the_bunny() {
    let mut rng = Pcg32::new(5, 1);
    let mut worst = 0.0f64;
    let (mut points_total, mut windowed_total) = (0, 0);
    // The bunny stands on y = 0, about 10 across and 10 high.
    for trial in 0..6 {
        let size = [0.5, 2.0, 6.0, 1.0, 4.0, 0.2][trial];
        let centre = DVec3::new(
            rng.range(-4.0, 4.0),
            rng.range(11.0, 16.0),
            rng.range(-4.0, 4.0),
        );
        // u × v = X × Z = −Y: facing down, toward the bunny and the floor.
        let light = quad(centre, DVec3::X * size, DVec3::Z * size * 0.7);
        let scene = Scene {
            objects: vec![object("light", light, true), object("mesh", bunny(), false)],
            camera: None,
            warnings: Vec::new(),
            environment: None,
        };
        let points: Vec<ShadingPoint> = (0..40)
            .map(|_| {
                let p = DVec3::new(rng.range(-9.0, 9.0), -1e-3, rng.range(-9.0, 9.0));
                ShadingPoint {
                    position: p,
                    normal: DVec3::Y,
                    view: DVec3::new(0.1, 1.0, 0.3).normalize(),
                    object: None,
                    face: None,
                }
            })
            .collect();
        let (w, n) = compare(&scene, &points);
        worst = worst.max(w);
        points_total += points.len();
        windowed_total += n;
    }
    assert!(worst < 1e-9, "largest relative difference {worst:e}");
    assert!(
        windowed_total * 2 > points_total,
        "the windowed path ran at {windowed_total} of {points_total} points"
    );
}

/// The word "penumbra" as Blender writes it (`tests/data/blender/penumbra_text.obj`: keyhole
/// n-gon caps, open seams), at the floor points where two kept pieces of the outline start at
/// one point. Walking the chains again by "the first piece that starts here" instead of the
/// recorded walk went round a cycle for ever (memory without bound). Found rendering the file
/// at 256×256 `--aa 4` from eye (0, 4, 4.8) looking at (0, 0.3, −0.2): the two sub-pixel
/// positions below. Oracle: the whole exact silhouette (a second algorithm).
#[test]
fn windowed_silhouette_of_the_penumbra_text_ends_where_two_pieces_start_at_one_point() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/blender/penumbra_text.toml");
    let scene = penumbra::scene::scene_file::load_scene(&path).expect("penumbra_text.toml");
    let eye = DVec3::new(0.0, 4.0, 4.8);
    let points: Vec<ShadingPoint> = [
        DVec3::new(0.9323569164728023, 0.0, 0.00889625057715615),
        DVec3::new(0.9367861654821743, 0.0, 0.008896250577156373),
    ]
    .into_iter()
    .map(|p| ShadingPoint {
        position: p,
        normal: DVec3::Y,
        view: (eye - p).normalize(),
        object: None,
        face: None,
    })
    .collect();
    let (worst, windowed) = compare_object(&scene, "Text", &points);
    assert!(worst < 1e-9, "largest relative difference {worst:e}");
    assert_eq!(
        windowed,
        points.len(),
        "the windowed path ran at every point"
    );
}

#[test]
fn windowed_silhouette_shades_like_the_whole_one_around_a_displaced_icosphere() {
    let mesh = penumbra::bench::realworld_scenes::displaced_icosphere(DVec3::ZERO, 1.0, 3, 0.15);
    let mut rng = Pcg32::new(9, 2);
    let mut worst = 0.0f64;
    let (mut points_total, mut windowed_total) = (0, 0);
    for _ in 0..8 {
        // A quad light on one side of the blob, points on the other, looking across it.
        let dir = rng.unit_vector();
        let frame = Frame::from_z(dir);
        let size = rng.range(0.05, 1.5);
        let centre = dir * rng.range(2.0, 5.0);
        // u × v = y × x = −dir: facing the blob.
        let light = quad(centre, frame.y * size * 0.6, frame.x * size);
        let scene = Scene {
            objects: vec![
                object("light", light, true),
                object("mesh", mesh.clone(), false),
            ],
            camera: None,
            warnings: Vec::new(),
            environment: None,
        };
        let points: Vec<ShadingPoint> = (0..30)
            .map(|_| {
                let p = -dir * rng.range(1.3, 3.0)
                    + (frame.x * rng.range(-1.0, 1.0) + frame.y * rng.range(-1.0, 1.0)) * 0.8;
                ShadingPoint {
                    position: p,
                    normal: dir,
                    view: dir,
                    object: None,
                    face: None,
                }
            })
            .collect();
        let (w, n) = compare(&scene, &points);
        worst = worst.max(w);
        points_total += points.len();
        windowed_total += n;
    }
    assert!(worst < 1e-9, "largest relative difference {worst:e}");
    assert!(
        windowed_total * 2 > points_total,
        "the windowed path ran at {windowed_total} of {points_total} points"
    );
}

/// Is `p` inside the positively oriented convex loop `l`, by more than `eps` from its sides?
/// `Some(inside)`, or `None` within `eps` of a side.
fn in_convex_loop(l: &[DVec3], p: DVec3, eps: f64) -> Option<bool> {
    let mut inside = true;
    for i in 0..l.len() {
        let s = l[i].cross(l[(i + 1) % l.len()]).normalize().dot(p);
        if s.abs() <= eps {
            return None;
        }
        inside &= s > 0.0;
    }
    Some(inside)
}

/// A convex spherical polygon: `n` points around `centre` at angular radius about `r`, in
/// counter-clockwise order seen from outside (positive orientation).
fn convex_loop(rng: &mut Pcg32, centre: DVec3, r: f64, n: usize) -> Vec<DVec3> {
    let u = centre.any_orthonormal_vector();
    let v = centre.cross(u);
    let mut angles: Vec<f64> = (0..n)
        .map(|_| rng.range(0.0, std::f64::consts::TAU))
        .collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
    angles
        .iter()
        .map(|&t| (centre + r.tan() * (u * t.cos() + v * t.sin())).normalize())
        .collect()
}

/// `clip_to_window` keeps, of a convex outline, exactly what covers the window: at points of
/// the window's convex hull (random convex combinations of its corners), the clipped outline
/// and the whole one agree on what they cover. The windows are convex or not, small or up to
/// 55° across, the outlines larger or smaller than the windows, near them or not; a second
/// test is the point count (the clipped loop is never larger than the outline plus eight).
#[test]
fn clip_to_window_keeps_what_covers_the_window() {
    use penumbra::geometry::clip_to_window;
    let mut rng = Pcg32::new(12, 7);
    let (mut agreed, mut clipped_calls) = (0usize, 0usize);
    for case in 0..2000 {
        let wc = rng.unit_vector();
        let wr = [1e-4, 0.01, 0.2, 0.45][case % 4];
        let corners = 3 + rng.below(30) as usize;
        let mut window = convex_loop(&mut rng, wc, wr, corners);
        if case % 3 == 0 && window.len() > 4 {
            // Pull one corner toward the centre: a non-convex window.
            let k = rng.below(window.len() as u32) as usize;
            window[k] = (wc + (window[k] - wc) * 0.3).normalize();
        }
        if window.len() < 3 {
            continue;
        }
        let sc = (wc + rng.unit_vector() * wr * rng.range(0.0, 3.0)).normalize();
        let sr = wr * rng.range(0.3, 6.0);
        let vertices = 13 + rng.below(60) as usize;
        let subject_loop = convex_loop(&mut rng, sc, sr.min(1.2), vertices);
        if subject_loop.len() < 3 {
            continue;
        }
        let mut subject = SphericalPolygon::default();
        subject.push_loop(subject_loop.iter().copied());
        let mut clipped = SphericalPolygon::default();
        let mut bufs: [Vec<DVec3>; 3] = Default::default();
        if !clip_to_window(&subject, &window, &mut clipped, &mut bufs) {
            continue;
        }
        clipped_calls += 1;
        assert!(clipped.loop_count() <= 1);
        assert!(clipped.vertex_count() <= subject_loop.len() + 8);
        let clipped_loop: Vec<DVec3> = if clipped.loop_count() == 1 {
            clipped.loop_at(0).to_vec()
        } else {
            Vec::new()
        };
        for _ in 0..64 {
            // A point of the window's convex hull.
            let mut p = DVec3::ZERO;
            for &w in &window {
                p += w * rng.next_f64().powi(3);
            }
            let p = p.normalize();
            let eps = 1e-9;
            let Some(whole) = in_convex_loop(&subject_loop, p, eps) else {
                continue;
            };
            let part = if clipped_loop.len() >= 3 {
                match in_convex_loop(&clipped_loop, p, eps) {
                    Some(b) => b,
                    None => continue,
                }
            } else {
                false
            };
            assert_eq!(whole, part, "case {case}: point {p:?}");
            agreed += 1;
        }
    }
    assert!(clipped_calls > 1500, "{clipped_calls} windows clipped");
    assert!(agreed > 50_000, "{agreed} points compared");
}
