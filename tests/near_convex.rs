//! Meshes convex up to the rounding of their coordinates (`geometry::mesh::near_convex`): exporter
//! scenes take the hull stand-in, and the stand-in changes solid angles and shading by no more
//! than its stated bound, against the exact path (the mesh's own exact silhouette and faces,
//! what the same file takes when its rounding is taken as zero).

use glam::DVec3;
use penumbra::bench::realworld_scenes::{ExportedScene, blender_primitives, fig4_9g};
use penumbra::geometry::IndexedPolyhedron;
use penumbra::geometry::{
    ExactSilhouetteScratch, Polyhedron, Sidedness, SilhouetteScratch, SphericalPolygon,
    convex_stand_in, exact_silhouette, silhouette, solid_angle_bound,
};
use penumbra::math::{Frame, Pcg32};
use penumbra::scene::Scene;
use penumbra::scene::obj::load_obj_str;
use penumbra::shading::{
    Method, NoRecorder, PrepareOptions, PreparedScene, ShadingPoint, ShadingScratch, shade,
};
use std::f64::consts::PI;

fn load(s: &ExportedScene) -> Scene {
    load_obj_str(&s.obj(), Some(&s.mtl()), &format!("{}.obj", s.name)).expect("loads")
}

/// Distance from `x` to a convex polyhedron, from below: the largest signed plane distance.
fn distance_below(hull: &Polyhedron, x: DVec3) -> f64 {
    hull.face_planes
        .iter()
        .map(|p| p.eval(x))
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn exporter_meshes_that_were_convex_get_a_hull_within_the_bound() {
    let mut rng = Pcg32::new(11, 3);
    let mut checked = 0;
    let mut largest_ratio = 0.0f64;
    for exported in [blender_primitives(), fig4_9g()] {
        let scene = load(&exported);
        for obj in &scene.objects {
            let mesh = IndexedPolyhedron::new(&obj.mesh.positions, &obj.mesh.faces);
            let stand_in = convex_stand_in(&mesh, obj.mesh.rounding);
            let meant_convex = !matches!(obj.name.as_str(), "ellipsoid" | "floor" | "Plane")
                && obj.mesh.faces.len() > 1;
            // What was convex as generated and is not as written takes the hull; the dented
            // ellipsoid does not.
            if mesh.diagnostics.convex || !meant_convex {
                assert!(stand_in.is_none(), "{}", obj.name);
                continue;
            }
            let s = stand_in.unwrap_or_else(|| panic!("{} has no stand-in", obj.name));
            assert!(s.hull.diagnostics.convex);
            // What rounding explains is small against the mesh (the bound is checked below).
            assert!(
                s.deviation <= 1e-4 * mesh.radius,
                "{}: {}",
                obj.name,
                s.deviation
            );
            eprintln!(
                "{}: rounding {:.2e}, outside {:.2e}, deviation {:.2e}, hull {} faces",
                obj.name,
                obj.mesh.rounding,
                s.outside,
                s.deviation,
                s.hull.face_count()
            );
            // Solid angles from random points around the mesh: the hull's (convex silhouette)
            // against the mesh's own exact silhouette.
            let (mut hs, mut es) = (
                SilhouetteScratch::default(),
                ExactSilhouetteScratch::default(),
            );
            let (mut hp, mut ep) = (SphericalPolygon::new(), SphericalPolygon::new());
            let hull = IndexedPolyhedron::from(s.hull.clone());
            for _ in 0..400 {
                let dist = mesh.radius * (1.001 + 4.0 * rng.next_f64());
                let x = mesh.center + rng.unit_vector() * dist;
                let frame = Frame::from_z(rng.unit_vector());
                silhouette(&hull, x, &frame, Sidedness::TwoSided, &mut hp, &mut hs);
                if exact_silhouette(&mesh, x, &frame, &mut ep, &mut es).is_err() {
                    continue;
                }
                let d = distance_below(&s.hull, x);
                let bound = solid_angle_bound(s.deviation, d);
                let diff = (hp.signed_solid_angle() - ep.signed_solid_angle()).abs();
                assert!(
                    diff <= bound + 1e-12,
                    "{}: |ΔΩ| = {diff:e} > bound {bound:e} at distance {d}",
                    obj.name
                );
                largest_ratio = largest_ratio.max(diff / bound);
                checked += 1;
            }
        }
    }
    assert!(checked >= 1900, "{checked}");
    eprintln!("{checked} points; largest |ΔΩ| / bound = {largest_ratio:.3}");
}

#[test]
fn shading_with_stand_ins_is_within_the_bound_of_the_exact_path() {
    let exported = blender_primitives();
    let with_rounding = load(&exported);
    let mut exact = with_rounding.clone();
    for o in &mut exact.objects {
        o.mesh.rounding = 0.0;
    }
    let options = PrepareOptions {
        ..PrepareOptions::default()
    };
    let a = PreparedScene::prepare(&with_rounding, options);
    let b = PreparedScene::prepare(&exact, options);
    let stand_ins: Vec<&str> = a
        .objects
        .iter()
        .filter(|o| o.stand_in().is_some())
        .map(|o| o.name.as_str())
        .collect();
    assert!(
        stand_ins.contains(&"Sphere") && stand_ins.contains(&"Cylinder"),
        "{stand_ins:?}"
    );
    assert!(b.objects.iter().all(|o| o.stand_in().is_none()));
    let floor = with_rounding
        .objects
        .iter()
        .position(|o| o.name == "Plane")
        .unwrap();
    let material = &with_rounding.objects[floor].material;
    let (mut sa, mut sb) = (ShadingScratch::default(), ShadingScratch::default());
    let mut rng = Pcg32::new(5, 9);
    let mut differ = 0;
    for _ in 0..3000 {
        let x = DVec3::new(rng.range(-3.0, 3.0), 0.0, rng.range(-3.0, 3.0));
        let sp = ShadingPoint {
            position: x,
            normal: DVec3::Y,
            view: DVec3::new(0.1, 1.0, 0.3).normalize(),
            object: Some(floor as u32),
            face: Some(0),
        };
        let la = shade(
            &a,
            &sp,
            material,
            Method::Analytic,
            &mut sa,
            &mut NoRecorder,
        );
        let lb = shade(
            &b,
            &sp,
            material,
            Method::Analytic,
            &mut sb,
            &mut NoRecorder,
        );
        // Each stand-in changes the visible solid angle of each light by at most its bound, and
        // the diffuse radiance by kd · Le / π times that.
        let mut bound = 0.0;
        for o in a.objects.iter().filter(|o| o.stand_in().is_some()) {
            let omega = o
                .stand_in()
                .unwrap()
                .solid_angle_bound(distance_below(&o.poly, x));
            for &(_, le) in &a.lights {
                bound += (material.kd * le).max_element() / PI * omega;
            }
        }
        let diff = (la - lb).abs().max_element();
        assert!(
            diff <= bound + 1e-12 * lb.max_element(),
            "{x}: {la} vs {lb}, bound {bound:e}"
        );
        if diff > 0.0 {
            differ += 1;
        }
    }
    // The comparison is not vacuous: the two paths compute different polygons.
    assert!(differ > 100, "{differ}");
}

/// A quad light written with six decimals, its fourth corner off the plane of the other three
/// by the rounding (Blender's monkey's light in `tests/data/blender/suzanne.obj`), is flat up
/// to its rounding; the same quad bent by 1e-3 is not, nor is a pair of faces folded back onto
/// each other. The shading of a point under the flat-classified light equals the face-by-face
/// path's (the per-triangle method over the fan the file's bent quad is split into) to 1e-12.
#[test]
fn a_quad_bent_by_its_rounding_is_flat_and_shades_as_its_triangles() {
    use penumbra::geometry::flat_up_to_rounding;
    let quad = |z3: f64| {
        let v = [
            DVec3::new(-0.262450, 2.429410, -0.608538),
            DVec3::new(0.688802, 2.170590, -0.776269),
            DVec3::new(0.862450, 2.170590, z3),
            DVec3::new(-0.088802, 2.429410, 0.376270),
        ];
        Polyhedron::new(&v, &[vec![0, 1, 2, 3]])
    };
    let rounding = 5e-7 * 3f64.sqrt();
    let bent = quad(0.208538);
    assert!(!bent.diagnostics.planar, "bent beyond 1e-9 of its radius");
    let off = flat_up_to_rounding(&bent, rounding).expect("flat up to its rounding");
    assert!(off > 1e-9 && off < 1e-7, "{off}");
    assert!(flat_up_to_rounding(&quad(0.209538), rounding).is_none());
    // Two triangles folded back onto each other along their shared edge.
    let folded = Polyhedron::new(
        &[DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.5, 0.5, 1e-9)],
        &[vec![0, 1, 2], vec![2, 1, 3]],
    );
    assert!(flat_up_to_rounding(&folded, rounding).is_none());

    // Shading under it: the whole light (flat path) against its faces one by one.
    let obj = "v -0.262450 2.429410 -0.608538\nv 0.688802 2.170590 -0.776269\n\
               v 0.862450 2.170590 0.208538\nv -0.088802 2.429410 0.376270\n\
               v -0.3 1.2 -0.3\nv 0.3 1.2 -0.3\nv 0.3 1.2 0.3\nv -0.3 1.2 0.3\n\
               o Light\nf 1 2 3 4\no Card\nf 5 6 7 8\n";
    let mut scene = load_obj_str(obj, None, "bent_light.obj").expect("parses");
    scene.objects[0].flags.light = true;
    scene.objects[0].material.ke = DVec3::ONE;
    let prepared = PreparedScene::prepare(&scene, PrepareOptions::default());
    let light = &prepared.objects[0];
    assert!(light.poly.diagnostics.planar, "classified flat");
    let mut scratch = ShadingScratch::default();
    let mut rng = Pcg32::new(3, 7);
    let mut lit = 0;
    for _ in 0..200 {
        let p = DVec3::new(
            rng.range(-2.0, 2.0),
            rng.range(-0.5, 0.0),
            rng.range(-2.0, 2.0),
        );
        let sp = ShadingPoint {
            position: p,
            normal: DVec3::Y,
            view: DVec3::new(0.2, 1.0, 0.1).normalize(),
            object: None,
            face: None,
        };
        let m = penumbra::scene::Material {
            kd: DVec3::splat(0.7),
            ks: DVec3::splat(0.3),
            alpha: 0.3,
            ..penumbra::scene::Material::default()
        };
        let whole = shade(
            &prepared,
            &sp,
            &m,
            Method::Analytic,
            &mut scratch,
            &mut NoRecorder,
        );
        let faces = shade(
            &prepared,
            &sp,
            &m,
            Method::PerTriangle,
            &mut scratch,
            &mut NoRecorder,
        );
        assert!(
            (whole - faces).abs().max_element() <= 1e-12 * faces.abs().max_element() + 1e-15,
            "{p}: {whole} vs {faces}"
        );
        lit += (faces.max_element() > 1e-6) as u32;
    }
    assert!(lit > 100, "only {lit} of 200 points lit");
}
