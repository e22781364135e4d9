//! Writes the embedded scenes (OBJ + MTL + TOML) into assets/scenes/ from `scene::shapes`.
//!
//!     cargo run --example make_assets [-- OUTPUT_DIR]
//!
//! Units are metres, +y is up, the floor is the plane y = 0. Light radiances are calibrated so
//! that the unshadowed irradiance at the calibration point on the floor is about 1 (each light
//! gets a share of it), then rounded to 3 significant digits. The output is deterministic;
//! after changing this file, regenerate and commit the assets (the library embeds them).

use glam::{DAffine3, DVec2, DVec3};
use penumbra::scene::scene_file::load_scene;
use penumbra::scene::shapes::{
    capped_icosahedron, cuboid, cylinder, icosphere, l_shape, prism, quad, t_shape, truncated_cone,
    u_shape, uv_ellipsoid,
};
use penumbra::scene::thesis_polyhedra::{TABLE_7_1, thesis_polyhedron};
use penumbra::scene::{Camera, Mesh};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One MTL material.
#[derive(Clone)]
struct Mat {
    name: &'static str,
    kd: DVec3,
    ks: Option<DVec3>,
    pr: Option<f64>,
    /// Ke = `radiance * tint`, `radiance` from calibration.
    light: Option<Light>,
}

#[derive(Clone, Copy)]
struct Light {
    tint: DVec3,
    /// Share of the target irradiance at the calibration point.
    share: f64,
}

fn diffuse(name: &'static str, kd: [f64; 3]) -> Mat {
    Mat {
        name,
        kd: DVec3::from_array(kd),
        ks: None,
        pr: None,
        light: None,
    }
}

fn glossy(name: &'static str, kd: [f64; 3], ks: f64, pr: f64) -> Mat {
    Mat {
        ks: Some(DVec3::splat(ks)),
        pr: Some(pr),
        ..diffuse(name, kd)
    }
}

fn emitter(name: &'static str, tint: [f64; 3], share: f64) -> Mat {
    Mat {
        light: Some(Light {
            tint: DVec3::from_array(tint),
            share,
        }),
        ..diffuse(name, [0.0; 3])
    }
}

struct Object {
    name: &'static str,
    mesh: Mesh,
    mat: Mat,
    /// Extra TOML lines for this object (flag overrides).
    toml: &'static str,
}

fn object(name: &'static str, mesh: Mesh, mat: &Mat) -> Object {
    Object {
        name,
        mesh,
        mat: mat.clone(),
        toml: "",
    }
}

struct SceneDef {
    name: &'static str,
    description: &'static str,
    camera: Camera,
    /// Floor point where the unshadowed irradiance is calibrated to `target`.
    calibration_point: DVec3,
    target: f64,
    objects: Vec<Object>,
    /// Extra TOML written after the camera (e.g. an `[environment]`).
    extra_toml: &'static str,
}

fn camera(eye: [f64; 3], target: [f64; 3], fov_deg: f64) -> Camera {
    Camera {
        eye: DVec3::from_array(eye),
        target: DVec3::from_array(target),
        up: DVec3::Y,
        fov_deg,
        aspect: None,
    }
}

/// 20 m x 20 m floor at y = 0, front up (u x v = z x x = +y); receiver only.
fn floor(mat: &Mat) -> Object {
    Object {
        toml: "occluder = false\n",
        ..object(
            "floor",
            quad(DVec3::ZERO, DVec3::Z * 10.0, DVec3::X * 10.0),
            mat,
        )
    }
}

/// A chair of six convex boxes (4 legs, seat, back), seat 0.46 m wide, 0.47 m high, back
/// towards -z. Parts are separated by 1 mm gaps so that no two boxes share a face.
fn chair(origin: DVec3, mat: &Mat) -> Vec<Object> {
    let b = |name, c: [f64; 3], h: [f64; 3]| {
        object(
            name,
            cuboid(origin + DVec3::from_array(c), DVec3::from_array(h)),
            mat,
        )
    };
    let leg = [0.025, 0.2095, 0.025];
    vec![
        b("leg_front_left", [-0.2, 0.2095, 0.2], leg),
        b("leg_front_right", [0.2, 0.2095, 0.2], leg),
        b("leg_back_left", [-0.2, 0.2095, -0.2], leg),
        b("leg_back_right", [0.2, 0.2095, -0.2], leg),
        b("seat", [0.0, 0.445, 0.0], [0.23, 0.025, 0.23]),
        b("back", [0.0, 0.721, -0.21], [0.23, 0.25, 0.02]),
    ]
}

fn default_scene() -> SceneDef {
    let floor_mat = glossy("floor", [0.6, 0.6, 0.6], 0.04, 0.6);
    let wood = diffuse("wood", [0.55, 0.36, 0.22]);
    let blue = glossy("glossy_blue", [0.08, 0.15, 0.45], 0.5, 0.3);
    let panel = emitter("panel_light", [1.0, 0.95, 0.88], 0.75);
    let tube = emitter("tube_light", [0.8, 0.9, 1.0], 0.25);
    let tilt = 30f64.to_radians();
    let mut objects = vec![floor(&floor_mat)];
    objects.extend(chair(DVec3::new(-0.35, 0.0, -0.1), &wood));
    objects.push(object(
        "sphere",
        icosphere(DVec3::new(0.55, 0.302, 0.35), 0.3, 2),
        &blue,
    ));
    // 0.6 m x 0.4 m panel to the right, tilted 30 degrees towards the chair (-x).
    objects.push(object(
        "panel_light",
        quad(
            DVec3::new(0.9, 1.3, -0.3),
            DVec3::Z * 0.3,
            DVec3::new(-tilt.cos(), tilt.sin(), 0.0) * 0.2,
        ),
        &panel,
    ));
    // A 0.8 m tube (radius 5 cm, 16 sides) along x, behind to the left.
    objects.push(object(
        "tube_light",
        cylinder(DVec3::ZERO, 0.05, 0.8, 16).transformed(
            &(DAffine3::from_translation(DVec3::new(-1.0, 1.2, -0.9))
                * DAffine3::from_rotation_z(90f64.to_radians())),
        ),
        &tube,
    ));
    SceneDef {
        name: "default",
        description: "Default scene: a wooden chair of six convex boxes and a glossy sphere on a \
                      slightly glossy floor, lit by a tilted rectangular panel and a tube light.",
        camera: camera([1.5, 1.4, 2.7], [-0.3, 0.3, 0.0], 40.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

fn fig4_scene() -> SceneDef {
    let grey = diffuse("floor", [0.7, 0.7, 0.7]);
    let objects = vec![
        floor(&grey),
        object(
            "light_plane",
            quad(DVec3::new(-1.3, 3.0, -0.2), DVec3::X * 0.4, DVec3::Z * 0.4),
            &emitter("light_plane", [1.0, 1.0, 1.0], 1.0 / 3.0),
        ),
        object(
            "light_cylinder",
            cylinder(DVec3::new(0.0, 3.1, -0.5), 0.15, 0.6, 10),
            &emitter("light_cylinder", [1.0, 0.85, 0.7], 1.0 / 3.0),
        ),
        object(
            "light_cone",
            truncated_cone(DVec3::new(1.3, 2.9, -0.2), 0.3, 0.12, 0.4, 10),
            &emitter("light_cone", [0.75, 0.85, 1.0], 1.0 / 3.0),
        ),
        object(
            "cube",
            cuboid(DVec3::new(-1.2, 0.8, 0.3), DVec3::splat(0.3)),
            &diffuse("red", [0.7, 0.3, 0.25]),
        ),
        object(
            "icosphere",
            capped_icosahedron(DVec3::new(0.0, 0.9, 0.2), 0.35),
            &diffuse("green", [0.3, 0.6, 0.3]),
        ),
        object(
            "ellipsoid",
            uv_ellipsoid(
                DVec3::new(1.25, 0.75, 0.3),
                DVec3::new(0.45, 0.25, 0.3),
                19,
                9,
            ),
            &diffuse("blue", [0.3, 0.4, 0.75]),
        ),
    ];
    SceneDef {
        name: "fig4",
        description: "Paper 000, Fig. 4 (bottom right): lights = plane (4 vertices), cylinder \
                      (20), truncated cone (20); occluders = cube (8), icosphere (16: an \
                      icosahedron with 4 faces capped, see shapes::capped_icosahedron), \
                      ellipsoid (154: 19 slices x 9 stacks); Lambertian only.",
        camera: camera([0.0, 2.2, 6.0], [0.0, 1.0, 0.0], 45.0),
        calibration_point: DVec3::new(0.0, 0.0, 0.3),
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

fn chair_scene() -> SceneDef {
    let mut objects = vec![floor(&diffuse("floor", [0.7, 0.7, 0.7]))];
    objects.extend(chair(DVec3::ZERO, &diffuse("chair", [0.6, 0.5, 0.4])));
    objects.push(object(
        "light",
        quad(DVec3::new(-0.4, 1.5, 0.5), DVec3::X * 0.25, DVec3::Z * 0.25),
        &emitter("light", [1.0, 1.0, 1.0], 1.0),
    ));
    SceneDef {
        name: "chair",
        description: "Like paper 000, Fig. 8: a chair of six convex boxes under one quad \
                      light (4 vertices); Lambertian.",
        camera: camera([1.5, 1.4, 2.4], [0.0, 0.35, 0.0], 40.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

/// The plainest shadow there is: one 0.8 m quad light 3 m above a 6 m floor, a 0.9 m cube
/// turned about two axes between them. `penumbra bench --suite speed` times it, since a
/// constant factor shows here before anywhere else.
fn cube_scene() -> SceneDef {
    let turn = DAffine3::from_translation(DVec3::new(0.1, 1.1, 0.0))
        * DAffine3::from_rotation_y(35f64.to_radians())
        * DAffine3::from_rotation_x(25f64.to_radians());
    let mut cube = cuboid(DVec3::ZERO, DVec3::splat(0.45));
    for p in &mut cube.positions {
        *p = turn.transform_point3(*p);
    }
    let objects = vec![
        Object {
            toml: "occluder = false\n",
            ..object(
                "floor",
                quad(DVec3::ZERO, DVec3::Z * 3.0, DVec3::X * 3.0),
                &diffuse("floor", [0.7, 0.7, 0.7]),
            )
        },
        object(
            "light",
            quad(DVec3::new(0.0, 3.0, 0.0), DVec3::X * 0.4, DVec3::Z * 0.4),
            &emitter("light", [1.0, 1.0, 1.0], 1.0),
        ),
        object("cube", cube, &diffuse("cube", [0.7, 0.3, 0.25])),
    ];
    SceneDef {
        name: "cube",
        description: "One quad light (0.8 m, 3 m up) over a 6 m floor, a 0.9 m cube turned \
                      35 degrees about y and 25 about x between them; Lambertian.",
        camera: camera([2.6, 2.4, 3.4], [0.0, 0.4, 0.0], 45.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

fn nonconvex_scene() -> SceneDef {
    let objects = vec![
        floor(&diffuse("floor", [0.7, 0.7, 0.7])),
        // Upright L (0.8 m foot, 1 m tall, 0.25 m thick, 0.35 m deep), floating 0.1 m up.
        object(
            "l_occluder",
            l_shape(DVec3::new(0.0, 0.6, 0.0), 0.8, 1.0, 0.25, 0.35),
            &diffuse("orange", [0.7, 0.45, 0.3]),
        ),
        // A U (1 m x 0.8 m, 0.22 m walls, 8 cm thick) lying flat behind and above the L,
        // opening towards -z.
        object(
            "u_light",
            u_shape(DVec3::ZERO, 1.0, 0.8, 0.22, 0.08).transformed(
                &(DAffine3::from_translation(DVec3::new(0.2, 2.0, -1.0))
                    * DAffine3::from_rotation_x(-90f64.to_radians())),
            ),
            &emitter("u_light", [1.0, 1.0, 1.0], 1.0),
        ),
    ];
    SceneDef {
        name: "nonconvex",
        description: "Non-convex occluder (L-shaped prism) under a non-convex light (flat \
                      U-shaped prism), for the per-triangle method of paper 000, Sect. 4.4; \
                      Lambertian.",
        camera: camera([2.0, 2.0, 2.8], [0.0, 0.5, 0.0], 50.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

/// The nine polyhedra of 001 Table 7.1 as lights (0.3 m across, 0.6 m above a glossy floor,
/// on a 3 × 3 grid in the table's order, each turned a little so that no face is parallel to
/// the floor's grid of shading points), with a box occluder in the middle of the grid.
fn polyhedra_scene() -> SceneDef {
    let tints = [[1.0, 0.85, 0.7], [0.7, 0.85, 1.0], [1.0, 1.0, 1.0]];
    let mut objects = vec![floor(&glossy("floor", [0.6, 0.6, 0.6], 0.04, 0.6))];
    for (i, row) in TABLE_7_1.iter().enumerate() {
        let (gx, gz) = ((i % 3) as f64 - 1.0, (i / 3) as f64 - 1.0);
        let mesh = thesis_polyhedron(row.name)
            .expect("a Table 7.1 name")
            .transformed(
                &(DAffine3::from_translation(DVec3::new(0.9 * gx, 0.75, 0.9 * gz))
                    * DAffine3::from_rotation_y(0.35 + 0.2 * i as f64)
                    * DAffine3::from_rotation_x(0.15)
                    * DAffine3::from_scale(DVec3::splat(0.3))),
            );
        objects.push(object(
            row.name,
            mesh,
            &emitter(row.name, tints[i % 3], 1.0 / 9.0),
        ));
    }
    objects.push(object(
        "pillar",
        cuboid(DVec3::new(0.45, 0.3, 0.45), DVec3::new(0.06, 0.3, 0.06)),
        &diffuse("pillar", [0.5, 0.5, 0.55]),
    ));
    SceneDef {
        name: "polyhedra",
        description: "The nine test polyhedra of 001 Table 7.1 (cube, cone, cylinder, \
                      icosahedron, sphere, corner, extruded cube, hole, bowl) as lights over a \
                      glossy floor, with a box pillar casting shadows.",
        camera: camera([0.0, 2.6, 3.0], [0.0, 0.3, 0.0], 45.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

/// Neon letters "LTC" (001's non-convex lights as a sign): an L and a T (star-shaped: sampled
/// by fans of their exact silhouettes) and a C (a U turned to open to +x: not star-shaped,
/// sampled by its precomputed per-cell triangulations), 0.6 m tall, 8 cm deep, standing 0.35 m
/// above a glossy floor and turned a little toward the camera, with a post and a crossbar in
/// front casting shadows.
fn letters_scene() -> SceneDef {
    let (h, w, t, d) = (0.6, 0.42, 0.1, 0.08);
    let place = |mesh: Mesh, x: f64| {
        mesh.transformed(
            &(DAffine3::from_translation(DVec3::new(x, 0.35 + 0.5 * h, -0.4))
                * DAffine3::from_rotation_y(0.12 * x)),
        )
    };
    let c_shape = u_shape(DVec3::ZERO, h, w, t, d)
        .transformed(&DAffine3::from_rotation_z(-90f64.to_radians()));
    let objects = vec![
        floor(&glossy("floor", [0.5, 0.5, 0.55], 0.05, 0.5)),
        object(
            "letter_l",
            place(l_shape(DVec3::ZERO, w, h, t, d), -0.6),
            &emitter("neon_pink", [1.0, 0.3, 0.6], 1.0 / 3.0),
        ),
        object(
            "letter_t",
            place(t_shape(DVec3::ZERO, w, h, t, d), 0.0),
            &emitter("neon_cyan", [0.3, 0.9, 1.0], 1.0 / 3.0),
        ),
        object(
            "letter_c",
            place(c_shape, 0.6),
            &emitter("neon_yellow", [1.0, 0.85, 0.3], 1.0 / 3.0),
        ),
        object(
            "post",
            cuboid(DVec3::new(-0.25, 0.3, 0.05), DVec3::new(0.04, 0.3, 0.04)),
            &diffuse("post", [0.45, 0.45, 0.5]),
        ),
        object(
            "crossbar",
            cuboid(DVec3::new(0.25, 0.22, 0.1), DVec3::new(0.35, 0.025, 0.04)),
            &diffuse("crossbar", [0.45, 0.45, 0.5]),
        ),
    ];
    SceneDef {
        name: "letters",
        description: "Neon letters LTC: non-convex lights (an L and a T, star-shaped, and a C,                       not star-shaped) over a glossy floor, with a post and a crossbar casting                       shadows.",
        camera: camera([0.3, 1.3, 2.4], [0.0, 0.45, -0.2], 45.0),
        calibration_point: DVec3::new(0.0, 0.0, 0.3),
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

/// Issue 14's glossy test: a pure GGX floor (Kd 0, F0 = 1, α = Pr² ≈ 0.30) lit by one tilted
/// quad light, with a box between them whose shadow crosses the highlight.
fn glossy_scene() -> SceneDef {
    let objects = vec![
        floor(&glossy("ggx_floor", [0.0, 0.0, 0.0], 1.0, 0.55)),
        // 0.8 m x 0.5 m, front (u x v) facing (0, -0.6, 0.8): down toward the camera.
        object(
            "quad_light",
            quad(
                DVec3::new(0.0, 1.0, -1.2),
                DVec3::X * 0.4,
                DVec3::new(0.0, 0.8, 0.6) * 0.25,
            ),
            &emitter("quad_light", [1.0, 0.95, 0.9], 1.0),
        ),
        object(
            "box",
            cuboid(DVec3::new(0.1, 0.3, 0.05), DVec3::splat(0.12)),
            &diffuse("box", [0.5, 0.5, 0.5]),
        ),
    ];
    SceneDef {
        name: "glossy",
        description: "Glossy GGX floor (Kd 0, Ks 1, Pr 0.55: alpha 0.30) lit by a tilted quad \
                      light, a box casting a shadow across the highlight.",
        camera: camera([0.0, 0.7, 3.2], [0.0, 0.0, -0.2], 40.0),
        calibration_point: DVec3::new(0.0, 0.0, 0.3),
        target: 1.0,
        objects,
        extra_toml: "",
    }
}

/// Snaps values within 1e-12 of a multiple of 1e-9 onto it (0.47000000000000003 -> 0.47,
/// 6e-17 -> 0), so the files are readable; the shapes move by less than 1e-12.
fn clean(v: f64) -> f64 {
    let r = (v * 1e9).round() / 1e9;
    if (r - v).abs() < 1e-12 { r + 0.0 } else { v }
}

fn fmt3(v: DVec3) -> String {
    format!("{} {} {}", clean(v.x), clean(v.y), clean(v.z))
}

fn sig3(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let e = 10f64.powi(2 - x.abs().log10().floor() as i32);
    (x * e).round() / e
}

fn array(v: DVec3) -> String {
    format!("[{}, {}, {}]", clean(v.x), clean(v.y), clean(v.z))
}

/// A standing figure in a T pose, 1.76 m tall, 1.1 m across the arms, 0.25 m deep: the front
/// outline of a person extruded (`shapes::prism`), one closed non-convex mesh of 44 vertices
/// like one character of 002's scenes. `yaw` turns it about +y; its feet are 1 mm above the
/// floor so that no face lies in the floor's plane.
fn figure(feet: DVec3, yaw_deg: f64) -> Mesh {
    let p = |x: f64, y: f64| DVec2::new(x, y);
    let outline = [
        p(-0.2, 0.0),
        p(-0.03, 0.0),
        p(-0.03, 0.8),
        p(0.03, 0.8),
        p(0.03, 0.0),
        p(0.2, 0.0),
        p(0.2, 1.25),
        p(0.55, 1.25),
        p(0.55, 1.4),
        p(0.06, 1.4),
        p(0.06, 1.48),
        p(0.12, 1.52),
        p(0.12, 1.7),
        p(0.06, 1.76),
        p(-0.06, 1.76),
        p(-0.12, 1.7),
        p(-0.12, 1.52),
        p(-0.06, 1.48),
        p(-0.06, 1.4),
        p(-0.55, 1.4),
        p(-0.55, 1.25),
        p(-0.2, 1.25),
    ];
    let pieces = vec![
        vec![0, 1, 2, 21],
        vec![4, 5, 6, 3],
        vec![21, 2, 3, 6, 9, 18],
        vec![6, 7, 8, 9],
        vec![18, 19, 20, 21],
        vec![9, 10, 17, 18],
        vec![10, 11, 12, 13, 14, 15, 16, 17],
    ];
    prism(&outline, &pieces, 0.25).transformed(
        &(DAffine3::from_translation(feet + DVec3::Y * 0.001)
            * DAffine3::from_rotation_y(yaw_deg.to_radians())),
    )
}

/// The floor of the environment scenes: static, and an occluder (it hides the ground half of
/// the map from the figures).
fn env_floor(mat: &Mat) -> Object {
    Object {
        toml: "static = true\n",
        ..object(
            "floor",
            quad(DVec3::ZERO, DVec3::Z * 10.0, DVec3::X * 10.0),
            mat,
        )
    }
}

const SKY: &str = "\n[environment]\nmap = \"sky\"\n";

fn env_figures_scene() -> SceneDef {
    let skin = diffuse("figure", [0.7, 0.6, 0.5]);
    let objects = vec![
        env_floor(&diffuse("floor", [0.6, 0.6, 0.6])),
        object("figure_a", figure(DVec3::new(-0.55, 0.0, 0.0), 20.0), &skin),
        object("figure_b", figure(DVec3::new(0.7, 0.0, -0.4), -35.0), &skin),
    ];
    SceneDef {
        name: "env_figures",
        description: "Like 002, Fig. 7 (top): two dynamic figures on a static plane under the \
                      embedded sky; no area lights.",
        camera: camera([0.4, 1.6, 4.2], [0.0, 0.75, 0.0], 45.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: SKY,
    }
}

fn env_atrium_scene() -> SceneDef {
    let stone = diffuse("stone", [0.65, 0.62, 0.55]);
    let static_obj = |name: &'static str, mesh: Mesh| Object {
        toml: "static = true\n",
        ..object(name, mesh, &stone)
    };
    const COLUMNS: [&str; 10] = [
        "column_l0",
        "column_l1",
        "column_l2",
        "column_l3",
        "column_l4",
        "column_r0",
        "column_r1",
        "column_r2",
        "column_r3",
        "column_r4",
    ];
    let mut objects = vec![env_floor(&diffuse("floor", [0.55, 0.55, 0.5]))];
    for (k, name) in COLUMNS.iter().enumerate() {
        let x = if k < 5 { -2.0 } else { 2.0 };
        let z = -4.0 + 2.0 * (k % 5) as f64;
        objects.push(static_obj(
            name,
            cylinder(DVec3::new(x, 1.5005, z), 0.2, 2.999, 12),
        ));
    }
    // Roofs over the two aisles, resting on the columns; the middle stays open to the sky.
    objects.push(static_obj(
        "roof_l",
        cuboid(DVec3::new(-2.9, 3.101, 0.0), DVec3::new(1.1, 0.1, 4.6)),
    ));
    objects.push(static_obj(
        "roof_r",
        cuboid(DVec3::new(2.9, 3.101, 0.0), DVec3::new(1.1, 0.1, 4.6)),
    ));
    objects.push(static_obj(
        "back_wall",
        cuboid(DVec3::new(0.0, 1.601, -5.0), DVec3::new(4.0, 1.6, 0.15)),
    ));
    let skin = diffuse("figure", [0.7, 0.6, 0.5]);
    objects.push(object(
        "figure_a",
        figure(DVec3::new(-0.6, 0.0, 0.3), 15.0),
        &skin,
    ));
    objects.push(object(
        "figure_b",
        figure(DVec3::new(0.8, 0.0, -0.8), -30.0),
        &skin,
    ));
    SceneDef {
        name: "env_atrium",
        description: "Like 002's Sponza scene: a static colonnade (ten columns, two aisle roofs, \
                      a back wall) open to the sky in the middle, with two dynamic figures.",
        camera: camera([0.0, 1.7, 6.5], [0.0, 1.2, -1.0], 50.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: SKY,
    }
}

fn env_crowd_scene() -> SceneDef {
    const NAMES: [&str; 10] = [
        "figure_0", "figure_1", "figure_2", "figure_3", "figure_4", "figure_5", "figure_6",
        "figure_7", "figure_8", "figure_9",
    ];
    let skin = diffuse("figure", [0.7, 0.6, 0.5]);
    let mut objects = vec![env_floor(&diffuse("floor", [0.6, 0.6, 0.6]))];
    for (k, name) in NAMES.iter().enumerate() {
        let (row, col) = ((k / 5) as f64, (k % 5) as f64);
        let feet = DVec3::new(-2.4 + 1.2 * col + 0.3 * row, 0.0, -0.6 - 1.4 * row);
        objects.push(object(
            name,
            figure(feet, -40.0 + 20.0 * col + 13.0 * row),
            &skin,
        ));
    }
    SceneDef {
        name: "env_crowd",
        description: "Like 002, Fig. 10: ten dynamic figures on a static plane under the \
                      embedded sky: the case where conical ray culling helps least.",
        camera: camera([0.0, 2.2, 5.5], [0.0, 0.7, -1.0], 50.0),
        calibration_point: DVec3::ZERO,
        target: 1.0,
        objects,
        extra_toml: SKY,
    }
}

fn write_scene(dir: &Path, def: &SceneDef) -> std::io::Result<()> {
    let name = def.name;
    // Calibrate the radiances: Ke = radiance * tint, the tint scaled to a channel mean of 1.
    let mut kes = Vec::new();
    for o in &def.objects {
        let ke = o.mat.light.map(|l| {
            let factor = o
                .mesh
                .irradiance_factor(def.calibration_point, DVec3::Y)
                .max(1e-6);
            let radiance = def.target * l.share / factor;
            let t = l.tint / (l.tint.element_sum() / 3.0);
            DVec3::new(
                sig3(radiance * t.x),
                sig3(radiance * t.y),
                sig3(radiance * t.z),
            )
        });
        kes.push(ke);
    }

    let header = format!(
        "# penumbra scene '{name}', generated by `cargo run --example make_assets`; do not edit.\n# {}\n",
        def.description
    );

    let mut mtl = header.clone();
    let mut written: Vec<&str> = Vec::new();
    for (o, ke) in def.objects.iter().zip(&kes) {
        if written.contains(&o.mat.name) {
            continue;
        }
        written.push(o.mat.name);
        let m = &o.mat;
        writeln!(mtl, "\nnewmtl {}", m.name).unwrap();
        writeln!(mtl, "Kd {}", fmt3(m.kd)).unwrap();
        writeln!(mtl, "Ks {}", fmt3(m.ks.unwrap_or(DVec3::ZERO))).unwrap();
        if let Some(pr) = m.pr {
            writeln!(mtl, "Pr {pr}").unwrap();
        }
        if let Some(ke) = ke {
            writeln!(mtl, "Ke {}", fmt3(*ke)).unwrap();
        }
    }

    let mut obj = header.clone();
    writeln!(obj, "mtllib {name}.mtl").unwrap();
    let mut base = 1usize;
    for o in &def.objects {
        writeln!(
            obj,
            "\no {}\nusemtl {}\n# vertices: {}, faces: {}",
            o.name,
            o.mat.name,
            o.mesh.positions.len(),
            o.mesh.faces.len()
        )
        .unwrap();
        for p in &o.mesh.positions {
            writeln!(obj, "v {}", fmt3(*p)).unwrap();
        }
        for f in &o.mesh.faces {
            let idx: Vec<String> = f.iter().map(|&i| (i as usize + base).to_string()).collect();
            writeln!(obj, "f {}", idx.join(" ")).unwrap();
        }
        base += o.mesh.positions.len();
    }

    let c = &def.camera;
    let mut toml = header;
    write!(
        toml,
        "\n[camera]\neye = {}\ntarget = {}\nup = {}\nfov = {}\n",
        array(c.eye),
        array(c.target),
        array(c.up),
        c.fov_deg
    )
    .unwrap();
    toml.push_str(def.extra_toml);
    for o in &def.objects {
        write!(
            toml,
            "\n[[object]]\nobj = \"{name}.obj\"\nname = \"{}\"\n{}",
            o.name, o.toml
        )
        .unwrap();
    }

    std::fs::write(dir.join(format!("{name}.mtl")), mtl)?;
    std::fs::write(dir.join(format!("{name}.obj")), obj)?;
    std::fs::write(dir.join(format!("{name}.toml")), toml)?;
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes"));
    std::fs::create_dir_all(&dir)?;
    for def in [
        default_scene(),
        fig4_scene(),
        chair_scene(),
        cube_scene(),
        nonconvex_scene(),
        polyhedra_scene(),
        letters_scene(),
        env_figures_scene(),
        env_atrium_scene(),
        env_crowd_scene(),
        glossy_scene(),
    ] {
        write_scene(&dir, &def)?;
        // Read the files back through the loader and report.
        let path = dir.join(format!("{}.toml", def.name));
        let scene = load_scene(&path).map_err(|e| anyhow::anyhow!("{e}"))?;
        anyhow::ensure!(
            scene.warnings.is_empty(),
            "{}: warnings {:?}",
            def.name,
            scene.warnings
        );
        let e = scene.unshadowed_irradiance(def.calibration_point, DVec3::Y);
        println!(
            "{}: {} objects, unshadowed irradiance at {} = {}",
            path.display(),
            scene.objects.len(),
            array(def.calibration_point),
            fmt3(e)
        );
        for o in &scene.objects {
            println!(
                "  {:<18} {:>4} vertices {:>4} faces  light={} occluder={} receiver={}  Ke={}",
                o.name,
                o.mesh.positions.len(),
                o.mesh.faces.len(),
                o.flags.light,
                o.flags.occluder,
                o.flags.receiver,
                fmt3(o.material.ke)
            );
        }
    }
    Ok(())
}
