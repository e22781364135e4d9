//! The BVH against a brute-force loop over every triangle (the oracle), watertightness on
//! closed meshes, robustness (empty and degenerate input, scales 1e-4 to 1e4, deep trees).

use glam::DVec3;
use penumbra::accel::{Bvh, Hit, Ray, intersect_triangle, newell_normal};
use penumbra::math::Pcg32;
use penumbra::scene::{Material, Mesh, ObjectFlags, Scene, SceneObject};

// ---------------------------------------------------------------------------------------
// Scene construction

fn object(name: &str, positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> SceneObject {
    SceneObject {
        name: name.into(),
        mesh: Mesh {
            positions,
            faces,
            rounding: 0.0,
        },
        material: Material::default(),
        flags: ObjectFlags {
            light: false,
            occluder: true,
            receiver: true,
            is_static: false,
        },
    }
}

fn scene(objects: Vec<SceneObject>) -> Scene {
    Scene {
        objects,
        ..Default::default()
    }
}

/// Axis-aligned box as six quads, counter-clockwise seen from outside.
fn cube(center: DVec3, half: f64) -> SceneObject {
    let p = |x: f64, y: f64, z: f64| center + half * DVec3::new(x, y, z);
    let positions = vec![
        p(-1., -1., -1.),
        p(1., -1., -1.),
        p(1., 1., -1.),
        p(-1., 1., -1.),
        p(-1., -1., 1.),
        p(1., -1., 1.),
        p(1., 1., 1.),
        p(-1., 1., 1.),
    ];
    let faces = vec![
        vec![0, 3, 2, 1], // -z
        vec![4, 5, 6, 7], // +z
        vec![0, 1, 5, 4], // -y
        vec![2, 3, 7, 6], // +y
        vec![0, 4, 7, 3], // -x
        vec![1, 2, 6, 5], // +x
    ];
    object("cube", positions, faces)
}

/// Same box, each quad split into two triangles along the other diagonal.
fn cube_triangles(center: DVec3, half: f64) -> SceneObject {
    let mut c = cube(center, half);
    c.mesh.faces = c
        .mesh
        .faces
        .iter()
        .flat_map(|f| [vec![f[1], f[2], f[3]], vec![f[1], f[3], f[0]]])
        .collect();
    c
}

fn octahedron(center: DVec3, r: f64) -> SceneObject {
    let positions = vec![
        center + r * DVec3::X,
        center - r * DVec3::X,
        center + r * DVec3::Y,
        center - r * DVec3::Y,
        center + r * DVec3::Z,
        center - r * DVec3::Z,
    ];
    let faces = vec![
        vec![0, 2, 4],
        vec![2, 1, 4],
        vec![1, 3, 4],
        vec![3, 0, 4],
        vec![2, 0, 5],
        vec![1, 2, 5],
        vec![3, 1, 5],
        vec![0, 3, 5],
    ];
    object("octahedron", positions, faces)
}

/// UV sphere: quads between parallels, triangles at the poles, counter-clockwise outside.
fn uv_sphere(center: DVec3, r: f64, n_lon: u32, n_lat: u32) -> SceneObject {
    let m = penumbra::scene::shapes::uv_ellipsoid(center, DVec3::splat(r), n_lon, n_lat);
    object("uv_sphere", m.positions, m.faces)
}

/// Random triangles, quads and pentagons (planar and not) in [-1, 1]^3 times `scale`.
fn soup(rng: &mut Pcg32, name: &str, n: usize, scale: f64, offset: DVec3) -> SceneObject {
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for _ in 0..n {
        let c = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let size = if rng.below(20) == 0 { 0.8 } else { 0.1 };
        let k = 3 + rng.below(3);
        let base = positions.len() as u32;
        let u = rng.unit_vector();
        let w = u.cross(rng.unit_vector()).normalize();
        let planar = rng.below(2) == 0;
        for i in 0..k {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            let mut p = c + size * (a.cos() * u + a.sin() * w);
            if !planar {
                p += 0.3 * size * rng.unit_vector();
            }
            positions.push(offset + scale * p);
        }
        faces.push((base..base + k).collect());
    }
    // Some shared-vertex faces and some degenerate ones.
    let m = positions.len() as u32;
    faces.push(vec![0, 1, 3]);
    faces.push(vec![2, 2, 2]);
    faces.push(vec![0, 1]);
    let p = positions[5];
    positions.push(p);
    faces.push(vec![5, m, 6]);
    object(name, positions, faces)
}

// ---------------------------------------------------------------------------------------
// Oracle

/// Closest hit by brute force: (t, object, face), first in (object, face, triangle) order
/// among equal t.
fn brute_intersect(scene: &Scene, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, u32, u32)> {
    let mut best: Option<(f64, u32, u32)> = None;
    let mut t_best = t_max;
    for (o, obj) in scene.objects.iter().enumerate() {
        let p = &obj.mesh.positions;
        for (f, face) in obj.mesh.faces.iter().enumerate() {
            for k in 1..face.len().saturating_sub(1) {
                let (v0, v1, v2) = (
                    p[face[0] as usize],
                    p[face[k] as usize],
                    p[face[k + 1] as usize],
                );
                if let Some(h) = intersect_triangle(ray, v0, v1, v2, t_min, t_best) {
                    t_best = h.t;
                    best = Some((h.t, o as u32, f as u32));
                }
            }
        }
    }
    best
}

fn brute_occluded(
    scene: &Scene,
    ray: &Ray,
    t_min: f64,
    t_max: f64,
    accept: impl Fn(u32, u32) -> bool,
) -> bool {
    scene.objects.iter().enumerate().any(|(o, obj)| {
        let p = &obj.mesh.positions;
        obj.mesh.faces.iter().enumerate().any(|(f, face)| {
            (1..face.len().saturating_sub(1)).any(|k| {
                let (v0, v1, v2) = (
                    p[face[0] as usize],
                    p[face[k] as usize],
                    p[face[k + 1] as usize],
                );
                intersect_triangle(ray, v0, v1, v2, t_min, t_max).is_some()
                    && accept(o as u32, f as u32)
            })
        })
    })
}

fn check_hit(scene: &Scene, hit: &Hit, ray: &Ray, scale: f64) {
    let obj = &scene.objects[hit.object as usize];
    let face = &obj.mesh.faces[hit.face as usize];
    let n = newell_normal(&obj.mesh.positions, face);
    assert!((hit.geometric_normal - n).length() < 1e-12, "normal");
    assert!((hit.geometric_normal.length() - 1.0).abs() < 1e-12);
    let p = ray.at(hit.t);
    assert!(
        (hit.point - p).length() <= 1e-9 * (scale + ray.origin.length()),
        "point {} vs {p}",
        hit.point
    );
}

/// Compares the BVH with the oracle on `rays`; returns the number of hits.
fn compare(scene: &Scene, bvh: &Bvh, rays: &[(Ray, f64, f64)], scale: f64) -> usize {
    let mut hits = 0;
    for (i, (ray, t_min, t_max)) in rays.iter().enumerate() {
        let got = bvh.intersect(ray, *t_min, *t_max);
        let want = brute_intersect(scene, ray, *t_min, *t_max);
        match (got, want) {
            (None, None) => {}
            (Some(h), Some((t, o, f))) => {
                assert!(
                    (h.t - t).abs() <= 1e-12 * t.abs(),
                    "ray {i}: t {} vs {t}",
                    h.t
                );
                assert_eq!(
                    (h.object, h.face),
                    (o, f),
                    "ray {i} {ray:?}: t {} vs {t}",
                    h.t
                );
                check_hit(scene, &h, ray, scale);
                hits += 1;
            }
            (g, w) => panic!("ray {i} {ray:?} [{t_min}, {t_max}]: bvh {g:?}, brute force {w:?}"),
        }
        let accept = |o: u32, f: u32| !(o + f + i as u32).is_multiple_of(3);
        assert_eq!(
            bvh.occluded(ray, *t_min, *t_max, accept),
            brute_occluded(scene, ray, *t_min, *t_max, accept),
            "occluded, ray {i}"
        );
        assert_eq!(
            bvh.occluded(ray, *t_min, *t_max, |_, _| true),
            want.is_some(),
            "occluded (all), ray {i}"
        );
    }
    hits
}

/// Rays of every kind: random, aimed at vertices, axis-aligned, short and long directions,
/// various ranges.
fn random_rays(
    rng: &mut Pcg32,
    scene: &Scene,
    n: usize,
    scale: f64,
    offset: DVec3,
) -> Vec<(Ray, f64, f64)> {
    let verts: Vec<DVec3> = scene
        .objects
        .iter()
        .flat_map(|o| o.mesh.positions.iter().copied())
        .collect();
    (0..n)
        .map(|i| {
            let origin = offset
                + scale
                    * 2.0
                    * DVec3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    );
            let dir = match i % 4 {
                0 => rng.unit_vector(),
                1 if !verts.is_empty() => verts[rng.below(verts.len() as u32) as usize] - origin,
                2 => {
                    let mut d = DVec3::ZERO;
                    d[rng.below(3) as usize] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                    d
                }
                _ => rng.unit_vector() * DVec3::new(1.0, 1.0, 0.0),
            } * (scale * rng.range(0.01, 100.0));
            let (t_min, t_max) = match i % 5 {
                0 => (0.0, f64::INFINITY),
                1 => (0.0, rng.range(0.0, 0.1)),
                2 => (rng.range(0.0, 0.05), rng.range(0.05, 1.0)),
                3 => (f64::NEG_INFINITY, f64::INFINITY),
                _ => (rng.range(-0.1, 0.1), f64::INFINITY),
            };
            (Ray::new(origin, dir), t_min, t_max)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Tests

#[test]
fn random_scenes_match_brute_force() {
    let mut rng = Pcg32::new(10, 1);
    let mut hits = 0;
    let mut total = 0;
    for round in 0..6 {
        let scale = [1e-4, 1.0, 1e4][round % 3];
        let offset = if round >= 3 {
            DVec3::new(3.0, -2.0, 1.0) * scale * 10.0
        } else {
            DVec3::ZERO
        };
        let n = [50, 400, 2000][round % 3];
        let sc = scene(vec![
            soup(&mut rng, "a", n, scale, offset),
            soup(&mut rng, "b", n / 2, scale, offset),
            object("empty", vec![], vec![]),
            cube(offset, 0.5 * scale),
            uv_sphere(
                offset + DVec3::new(0.3, 0.2, 0.1) * scale,
                0.4 * scale,
                24,
                12,
            ),
        ]);
        let bvh = Bvh::build(&sc);
        let rays = random_rays(&mut rng, &sc, 1500, scale, offset);
        hits += compare(&sc, &bvh, &rays, scale);
        total += rays.len();
    }
    assert!(hits > total / 4, "only {hits} of {total} rays hit");
}

#[test]
fn closed_meshes_are_hit_from_inside() {
    let mut rng = Pcg32::new(11, 1);
    for &scale in &[1e-4, 1.0, 1e4] {
        let center = DVec3::new(0.7, -1.3, 2.1) * scale;
        let sc = scene(vec![
            uv_sphere(center, scale, 40, 20),
            cube(center, 3.0 * scale),
        ]);
        let bvh = Bvh::build(&sc);
        let mut rays = Vec::new();
        for _ in 0..3000 {
            let origin = center + 0.9 * scale * rng.next_f64().cbrt() * rng.unit_vector();
            let ray = Ray::new(origin, rng.unit_vector() * scale * rng.range(0.1, 10.0));
            let hit = bvh
                .intersect(&ray, 0.0, f64::INFINITY)
                .expect("escaped the sphere");
            assert_eq!(hit.object, 0);
            // Seen from inside, the front side (outward) faces away from the ray.
            assert!(hit.geometric_normal.dot(ray.dir) > 0.0);
            rays.push((ray, 0.0, f64::INFINITY));
        }
        compare(&sc, &bvh, &rays[..500], scale);
    }
}

/// Rays from inside aimed exactly at shared edges and vertices of closed meshes (cube as
/// triangles, octahedron) never escape, at every scale and far from the world origin.
#[test]
fn watertight_at_shared_edges_and_vertices() {
    let mut rng = Pcg32::new(12, 1);
    let mut rays = 0;
    for &scale in &[1e-4, 1.0, 1e4] {
        for &offset in &[
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-1e3, 7e2, 3e3),
        ] {
            let center = offset * scale;
            for obj in [cube_triangles(center, scale), octahedron(center, scale)] {
                // Edges of the mesh: every pair of consecutive vertices of every face.
                let pos = obj.mesh.positions.clone();
                let mut edges = Vec::new();
                for f in &obj.mesh.faces {
                    for k in 0..f.len() {
                        edges.push((pos[f[k] as usize], pos[f[(k + 1) % f.len()] as usize]));
                    }
                }
                let sc = scene(vec![obj]);
                let bvh = Bvh::build(&sc);
                for i in 0..4000 {
                    // Inside both (|x| + |y| + |z| < 0.9 scale).
                    let origin = center
                        + 0.3
                            * scale
                            * DVec3::new(
                                rng.range(-1.0, 1.0),
                                rng.range(-1.0, 1.0),
                                rng.range(-1.0, 1.0),
                            );
                    let (a, b) = edges[rng.below(edges.len() as u32) as usize];
                    let target = match i % 4 {
                        0 => a,
                        1 => a.lerp(b, 0.5),
                        _ => a.lerp(b, rng.next_f64()),
                    };
                    let origin = if i % 8 == 3 { center } else { origin };
                    let ray = Ray::new(origin, target - origin);
                    assert!(
                        bvh.intersect(&ray, 0.0, f64::INFINITY).is_some(),
                        "escaped: {ray:?}"
                    );
                    assert!(bvh.occluded(&ray, 0.0, f64::INFINITY, |_, _| true));
                    assert!(brute_intersect(&sc, &ray, 0.0, f64::INFINITY).is_some());
                    rays += 1;
                }
            }
        }
    }
    assert_eq!(rays, 3 * 3 * 2 * 4000);
}

/// A grid of unit squares (alternating diagonals) hit by vertical rays through grid
/// vertices and edge midpoints: every edge value is exactly zero, so this exercises the
/// exact-sign fallback; every ray must hit.
#[test]
fn grid_rays_through_vertices_and_edges_hit() {
    let n = 16u32;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, d]);
                faces.push(vec![b, c, d]);
            }
        }
    }
    let sc = scene(vec![object("grid", positions, faces)]);
    let bvh = Bvh::build(&sc);
    let mut rng = Pcg32::new(13, 1);
    for j2 in 0..=2 * n {
        for i2 in 0..=2 * n {
            let p = DVec3::new(i2 as f64 * 0.5, j2 as f64 * 0.5, 0.0);
            let mut dirs = vec![
                DVec3::new(0.0, 0.0, -1.0),
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(0.25, -0.5, -1.0), // p - dir is exact: through p exactly
            ];
            // A rounded origin may pass just outside the grid's border: interior only.
            let interior = i2 > 0 && j2 > 0 && i2 < 2 * n && j2 < 2 * n;
            if interior {
                dirs.push(DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), -1.0));
            }
            for dir in dirs {
                let ray = Ray::new(p - dir, dir);
                let hit = bvh
                    .intersect(&ray, 0.0, f64::INFINITY)
                    .unwrap_or_else(|| panic!("hole in the grid: {ray:?}"));
                assert!((hit.t - 1.0).abs() < 1e-15);
                assert!(interior || hit.t == 1.0);
                assert_eq!(hit.geometric_normal, DVec3::Z);
                // Ties go to the smallest face, as in the oracle.
                assert_eq!(
                    brute_intersect(&sc, &ray, 0.0, f64::INFINITY).unwrap().2,
                    hit.face
                );
            }
        }
    }
}

#[test]
fn empty_and_degenerate_scenes() {
    let ray = Ray::new(DVec3::ZERO, DVec3::X);
    let empty = Bvh::build(&Scene::default());
    assert_eq!(empty.triangle_count(), 0);
    assert!(empty.intersect(&ray, 0.0, f64::INFINITY).is_none());
    assert!(!empty.occluded(&ray, 0.0, f64::INFINITY, |_, _| true));

    let p = DVec3::new(1.0, 0.0, 0.0);
    let sc = scene(vec![
        object("nothing", vec![], vec![]),
        object(
            "points",
            vec![p, p, p],
            vec![vec![0, 1, 2], vec![0, 1], vec![]],
        ),
        object(
            "line",
            vec![p, p + DVec3::Y, p + 2.0 * DVec3::Y],
            vec![vec![0, 1, 2]],
        ),
    ]);
    let bvh = Bvh::build(&sc);
    assert_eq!(bvh.triangle_count(), 0);
    assert!(bvh.intersect(&ray, 0.0, f64::INFINITY).is_none());
    assert!(!bvh.occluded(&ray, 0.0, f64::INFINITY, |_, _| true));

    // A real triangle among them; a zero direction hits nothing.
    let mut sc = sc;
    sc.objects.push(object(
        "tri",
        vec![
            p - DVec3::Y - DVec3::Z,
            p + DVec3::Y - DVec3::Z,
            p + DVec3::Z,
        ],
        vec![vec![0, 1, 2]],
    ));
    let bvh = Bvh::build(&sc);
    assert_eq!(bvh.triangle_count(), 1);
    let hit = bvh.intersect(&ray, 0.0, f64::INFINITY).unwrap();
    assert_eq!((hit.t, hit.object, hit.face), (1.0, 3, 0));
    assert_eq!(hit.point, p);
    assert!(
        bvh.intersect(&Ray::new(DVec3::ZERO, DVec3::ZERO), 0.0, f64::INFINITY)
            .is_none()
    );
    assert!(!bvh.occluded(
        &Ray::new(DVec3::ZERO, DVec3::ZERO),
        0.0,
        f64::INFINITY,
        |_, _| true
    ));
}

#[test]
fn occluded_skips_rejected_faces_and_respects_range() {
    // Two parallel quads at z = 1 and z = 2; the ray goes up from the origin.
    let quad = |z: f64| {
        object(
            "quad",
            vec![
                DVec3::new(-1.0, -1.0, z),
                DVec3::new(1.0, -1.0, z),
                DVec3::new(1.0, 1.0, z),
                DVec3::new(-1.0, 1.0, z),
            ],
            vec![vec![0, 1, 2, 3]],
        )
    };
    let sc = scene(vec![quad(1.0), quad(2.0)]);
    let bvh = Bvh::build(&sc);
    let ray = Ray::new(DVec3::new(0.1, 0.2, 0.0), DVec3::new(0.0, 0.0, 4.0));
    assert!(bvh.occluded(&ray, 0.0, 1.0, |_, _| true));
    assert!(bvh.occluded(&ray, 0.0, 1.0, |o, _| o == 1));
    assert!(!bvh.occluded(&ray, 0.0, 1.0, |_, _| false));
    assert!(!bvh.occluded(&ray, 0.0, 0.5, |o, _| o == 1));
    assert!(!bvh.occluded(&ray, 0.25, 0.5, |_, _| true)); // open at both ends
    assert!(bvh.occluded(&ray, 0.2, 0.3, |_, _| true));
    let h = bvh.intersect(&ray, 0.0, f64::INFINITY).unwrap();
    assert_eq!((h.t, h.object, h.face), (0.25, 0, 0));
    assert_eq!(h.geometric_normal, DVec3::Z);
    assert!((h.point - DVec3::new(0.1, 0.2, 1.0)).length() < 1e-15);
    let h = bvh.intersect(&ray, 0.25, f64::INFINITY).unwrap();
    assert_eq!((h.t, h.object), (0.5, 1));
    // The accept closure is called only for geometric hits.
    let mut calls = Vec::new();
    assert!(!bvh.occluded(&ray, 0.0, 1.0, |o, f| {
        calls.push((o, f));
        false
    }));
    calls.sort();
    calls.dedup();
    assert_eq!(calls, vec![(0, 0), (1, 0)]);
}

#[test]
fn newell_normal_of_polygons() {
    // A planar, non-convex (L-shaped) hexagon in the plane x + y + z = 1, CCW about (1,1,1).
    let u = DVec3::new(1.0, -1.0, 0.0).normalize();
    let w = DVec3::ONE.normalize().cross(u);
    let o = DVec3::ONE / 3.0;
    let uv = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let positions: Vec<DVec3> = uv.iter().map(|&(a, b)| o + a * u + b * w).collect();
    let face: Vec<u32> = (0..6).collect();
    let n = newell_normal(&positions, &face);
    assert!((n - DVec3::ONE.normalize()).length() < 1e-15);
    // A non-planar quad: the average of its two fan triangles' area vectors.
    let q = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.1),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.1),
    ];
    let n = newell_normal(&q, &[0, 1, 2, 3]);
    let a = (q[1] - q[0]).cross(q[2] - q[0]) + (q[2] - q[0]).cross(q[3] - q[0]);
    assert!((n - a.normalize()).length() < 1e-15);
    // Both fan triangles of a BVH hit report the face normal.
    let sc = scene(vec![object("quad", q, vec![vec![0, 1, 2, 3]])]);
    let bvh = Bvh::build(&sc);
    for target in [DVec3::new(0.8, 0.2, 0.0), DVec3::new(0.2, 0.8, 0.0)] {
        let ray = Ray::new(target + DVec3::Z, -DVec3::Z);
        let h = bvh.intersect(&ray, 0.0, f64::INFINITY).unwrap();
        assert_eq!(h.geometric_normal, bvh.face_normal(0, 0));
        assert!((h.geometric_normal - a.normalize()).length() < 1e-15);
    }
    // Degenerate and invalid faces give zero.
    assert_eq!(newell_normal(&[DVec3::ZERO; 3], &[0, 1, 2]), DVec3::ZERO);
    assert_eq!(newell_normal(&[DVec3::ZERO; 3], &[0, 1, 7]), DVec3::ZERO);
}

/// Pathological builds: many identical triangles (coincident centroids), and triangles at
/// geometrically shrinking positions (SAH peels one at a time, so the depth cap is reached).
#[test]
fn pathological_builds_stay_shallow_and_correct() {
    let mut rng = Pcg32::new(14, 1);
    let tri = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    let same = object(
        "same",
        tri.to_vec(),
        (0..5000).map(|_| vec![0, 1, 2]).collect(),
    );
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for i in 0..1000 {
        let x = 2.0 + 0.5f64.powi(i / 4) + i as f64 * 1e-300;
        let b = positions.len() as u32;
        positions.extend([
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x, 1.0, 0.0),
            DVec3::new(x, 0.0, 1.0),
        ]);
        faces.push(vec![b, b + 1, b + 2]);
    }
    let shrinking = object("shrinking", positions, faces);
    let sc = scene(vec![same, shrinking]);
    let bvh = Bvh::build(&sc);
    assert_eq!(bvh.triangle_count(), 6000);
    let rays = random_rays(&mut rng, &sc, 500, 2.0, DVec3::new(1.5, 0.5, 0.5));
    compare(&sc, &bvh, &rays, 2.0);
    let ray = Ray::new(DVec3::new(0.2, 0.2, 1.0), -DVec3::Z);
    let h = bvh.intersect(&ray, 0.0, f64::INFINITY).unwrap();
    assert_eq!((h.object, h.face), (0, 0));
}
