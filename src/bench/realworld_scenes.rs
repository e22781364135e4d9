//! The scenes of `penumbra bench --suite realworld`, written the way exporters write them
//! (docs/benchmarks.md, "Real-world scenes").
//!
//! Every scene is generated here and written out as OBJ, MTL and a scene file, then loaded back
//! through the OBJ loader like any user's file, so that the suite measures what a user meets:
//! coordinates rounded to the digits an exporter writes (`%.6f` for Blender, `%.9g` for
//! others), transforms baked into the coordinates (rotated objects are not axis-aligned, so
//! rounding bends their "planar" faces), n-gon caps, quads split into triangles along one
//! diagonal whatever the shape, 32–64 segment primitives, and subdivided, displaced meshes.
//! The scanned mesh is the Stanford bunny of `assets/meshes/bunny.obj` (3,674 triangles).

use crate::scene::Mesh;
use crate::scene::shapes::{cuboid, cylinder, icosphere, quad, truncated_cone, uv_ellipsoid};
use glam::{DAffine3, DMat3, DVec3};
use std::fmt::Write;

/// How an exporter prints a coordinate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NumberFormat {
    /// `%.Nf`: N decimals whatever the magnitude (Blender's OBJ exporter: 6).
    Fixed(u32),
    /// `%.Sg`: S significant digits, trailing zeros stripped (many C++ exporters: 9).
    Significant(u32),
}

impl NumberFormat {
    /// `v` as the exporter prints it.
    pub(crate) fn write(self, v: f64) -> String {
        match self {
            NumberFormat::Fixed(n) => {
                let s = format!("{v:.*}", n as usize);
                // `-0.000000` is what C prints for a tiny negative; keep it, loaders accept it.
                s
            }
            NumberFormat::Significant(s) => {
                if v == 0.0 || !v.is_finite() {
                    return "0".into();
                }
                let e = v.abs().log10().floor() as i32;
                if !(-5..s as i32).contains(&e) {
                    // %g switches to the exponent form outside this range.
                    let t = format!("{v:.*e}", (s - 1) as usize);
                    let (m, x) = t.split_once('e').unwrap_or((&t, "0"));
                    let m = strip_zeros(m);
                    return format!("{m}e{x}");
                }
                let decimals = (s as i32 - 1 - e).max(0) as usize;
                strip_zeros(&format!("{v:.decimals$}")).to_string()
            }
        }
    }

    /// How the format is named in the report.
    pub(crate) fn describe(self) -> String {
        match self {
            NumberFormat::Fixed(n) => format!("%.{n}f"),
            NumberFormat::Significant(s) => format!("%.{s}g"),
        }
    }
}

/// `1.2500` → `1.25`, `3.000` → `3` (what `%g` does to a fixed rendering).
fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// A material as the MTL file states it.
#[derive(Clone, Debug)]
pub struct ExportedMaterial {
    pub name: &'static str,
    pub kd: DVec3,
    pub ke: DVec3,
}

/// One object of an exported scene.
#[derive(Clone, Debug)]
pub struct ExportedObject {
    pub name: &'static str,
    pub mesh: Mesh,
    pub material: usize,
    /// Writes the faces as triangles, each polygon split as a fan from its first vertex (an
    /// exporter's "triangulate faces" option: it does not look at which diagonal is convex).
    pub triangulate: bool,
    pub occluder: bool,
}

/// A scene as an exporter wrote it.
#[derive(Clone, Debug)]
pub struct ExportedScene {
    pub name: &'static str,
    pub description: &'static str,
    pub format: NumberFormat,
    pub eye: DVec3,
    pub target: DVec3,
    pub fov: f64,
    pub materials: Vec<ExportedMaterial>,
    pub objects: Vec<ExportedObject>,
}

impl ExportedScene {
    /// The OBJ text: every coordinate printed with `format`, one `o` per object.
    pub fn obj(&self) -> String {
        let mut s = format!(
            "# {} ({}), written by penumbra's real-world suite like an exporter would\nmtllib {}.mtl\n",
            self.name,
            self.format.describe(),
            self.name
        );
        let mut base = 1usize;
        for o in &self.objects {
            let _ = writeln!(s, "o {}", o.name);
            for p in &o.mesh.positions {
                let _ = writeln!(
                    s,
                    "v {} {} {}",
                    self.format.write(p.x),
                    self.format.write(p.y),
                    self.format.write(p.z)
                );
            }
            let _ = writeln!(s, "usemtl {}", self.materials[o.material].name);
            for f in &o.mesh.faces {
                if o.triangulate && f.len() > 3 {
                    for k in 1..f.len() - 1 {
                        let _ = writeln!(
                            s,
                            "f {} {} {}",
                            f[0] as usize + base,
                            f[k] as usize + base,
                            f[k + 1] as usize + base
                        );
                    }
                } else {
                    s.push('f');
                    for &i in f {
                        let _ = write!(s, " {}", i as usize + base);
                    }
                    s.push('\n');
                }
            }
            base += o.mesh.positions.len();
        }
        s
    }

    /// The MTL text.
    pub fn mtl(&self) -> String {
        let mut s = String::new();
        for m in &self.materials {
            let v = |c: DVec3| format!("{} {} {}", c.x, c.y, c.z);
            let _ = writeln!(
                s,
                "newmtl {}\nKd {}\nKs 0 0 0\nKe {}\n",
                m.name,
                v(m.kd),
                v(m.ke)
            );
        }
        s
    }

    /// The scene file: the camera and, per object, whether it occludes.
    pub(crate) fn toml(&self) -> String {
        let v = |p: DVec3| format!("[{}, {}, {}]", p.x, p.y, p.z);
        let mut s = format!(
            "# {}\n\n[camera]\neye = {}\ntarget = {}\nup = [0, 1, 0]\nfov = {}\n",
            self.description,
            v(self.eye),
            v(self.target),
            self.fov
        );
        for o in &self.objects {
            let _ = write!(
                s,
                "\n[[object]]\nobj = \"{}.obj\"\nname = \"{}\"\n",
                self.name, o.name
            );
            if !o.occluder {
                s.push_str("occluder = false\n");
            }
        }
        s
    }
}

/// `mesh` as an exporter writes it and the OBJ loader reads it back: every coordinate printed
/// with `format` (rotated by `r` about the origin first, as exporters bake object rotations
/// into the coordinates), faces as they are or, with `triangulate`, fanned into triangles.
/// The loaded mesh carries the rounding inferred from its digits.
pub(crate) fn as_exported(
    mesh: &Mesh,
    format: NumberFormat,
    r: DMat3,
    triangulate: bool,
) -> crate::Result<Mesh> {
    let scene = ExportedScene {
        name: "exported",
        description: "one mesh as an exporter writes it",
        format,
        eye: DVec3::Z,
        target: DVec3::ZERO,
        fov: 45.0,
        materials: vec![diffuse("grey", [0.5, 0.5, 0.5])],
        objects: vec![ExportedObject {
            triangulate,
            ..object("mesh", rotated_about(mesh, DVec3::ZERO, r), 0)
        }],
    };
    let loaded = crate::scene::obj::load_obj_str(&scene.obj(), Some(&scene.mtl()), "exported.obj")
        .map_err(|e| e.to_string())?;
    loaded
        .objects
        .into_iter()
        .next()
        .map(|o| o.mesh)
        .ok_or_else(|| "exported.obj: no object".into())
}

fn rotation(yaw_deg: f64, pitch_deg: f64, roll_deg: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw_deg.to_radians())
        * DMat3::from_rotation_x(pitch_deg.to_radians())
        * DMat3::from_rotation_z(roll_deg.to_radians())
}

/// `mesh` rotated about `centre` (the exporter bakes object rotations into the coordinates).
fn rotated_about(mesh: &Mesh, centre: DVec3, r: DMat3) -> Mesh {
    let t = DAffine3::from_translation(centre)
        * DAffine3::from_mat3(r)
        * DAffine3::from_translation(-centre);
    mesh.transformed(&t)
}

/// A UV ellipsoid whose rings are twisted a little (each ring turned by `twist` radians more
/// than the one above it): its quads are no longer planar, as in a sculpted or simulated mesh.
/// Written triangulated, each quad is split along the same diagonal whichever way it bends, so
/// that some creases fold inward: a slightly dented mesh.
pub fn twisted_ellipsoid(
    center: DVec3,
    radii: DVec3,
    slices: u32,
    stacks: u32,
    twist: f64,
) -> Mesh {
    let mut m = uv_ellipsoid(DVec3::ZERO, DVec3::ONE, slices, stacks);
    for p in &mut m.positions {
        // The ring's index from its height: phi = acos(y), k = phi / (π / stacks).
        let k = (p.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI * stacks as f64).round();
        let (s, c) = (twist * k).sin_cos();
        *p = DVec3::new(c * p.x - s * p.z, p.y, s * p.x + c * p.z);
    }
    m.scaled(radii).translated(center)
}

/// An icosphere pushed in and out by smooth bumps: a subdivided, displaced mesh (the kind a
/// sculpting or scanning tool exports), closed and not convex.
pub fn displaced_icosphere(center: DVec3, radius: f64, subdivisions: u32, amount: f64) -> Mesh {
    let mut m = icosphere(DVec3::ZERO, 1.0, subdivisions);
    for p in &mut m.positions {
        let d = p.normalize();
        let bump = (3.0 * d.x + 1.0).sin() * (2.0 * d.y).cos() * (2.5 * d.z + 0.5).sin();
        *p = d * (1.0 + amount * bump);
    }
    m.scaled(DVec3::splat(radius)).translated(center)
}

fn emitter(name: &'static str, ke: [f64; 3]) -> ExportedMaterial {
    ExportedMaterial {
        name,
        kd: DVec3::ZERO,
        ke: DVec3::from_array(ke),
    }
}

fn diffuse(name: &'static str, kd: [f64; 3]) -> ExportedMaterial {
    ExportedMaterial {
        name,
        kd: DVec3::from_array(kd),
        ke: DVec3::ZERO,
    }
}

fn object(name: &'static str, mesh: Mesh, material: usize) -> ExportedObject {
    ExportedObject {
        name,
        mesh,
        material,
        triangulate: false,
        occluder: true,
    }
}

/// 000 Fig. 4's three lights and three occluders, exported with nine significant digits:
/// plane, 10-sided cylinder and truncated-cone lights (n-gon caps), a box, an icosphere and a
/// twisted 18 × 8 UV ellipsoid written as triangles; every object rotated.
pub fn fig4_9g() -> ExportedScene {
    let floor = quad(DVec3::ZERO, DVec3::Z * 10.0, DVec3::X * 10.0);
    let plane_c = DVec3::new(-1.3, 3.0, -0.2);
    let cyl_c = DVec3::new(0.0, 3.1, -0.5);
    let cone_c = DVec3::new(1.3, 2.9, -0.2);
    let cube_c = DVec3::new(-1.2, 0.8, 0.3);
    let ico_c = DVec3::new(0.0, 0.9, 0.2);
    let ell_c = DVec3::new(1.25, 0.75, 0.3);
    let objects = vec![
        ExportedObject {
            occluder: false,
            ..object("floor", floor, 0)
        },
        object(
            "light_plane",
            rotated_about(
                &quad(plane_c, DVec3::X * 0.4, DVec3::Z * 0.4),
                plane_c,
                rotation(17.0, 0.0, 0.0),
            ),
            1,
        ),
        object(
            "light_cylinder",
            rotated_about(
                &cylinder(cyl_c, 0.15, 0.6, 10),
                cyl_c,
                rotation(7.0, 0.0, 75.0),
            ),
            2,
        ),
        object(
            "light_cone",
            rotated_about(
                &truncated_cone(cone_c, 0.3, 0.12, 0.4, 10),
                cone_c,
                rotation(11.0, 8.0, 0.0),
            ),
            3,
        ),
        object(
            "cube",
            rotated_about(
                &cuboid(cube_c, DVec3::splat(0.3)),
                cube_c,
                rotation(30.0, 10.0, 0.0),
            ),
            4,
        ),
        object(
            "icosphere",
            rotated_about(&icosphere(ico_c, 0.35, 1), ico_c, rotation(13.0, 21.0, 5.0)),
            5,
        ),
        ExportedObject {
            triangulate: true,
            ..object(
                "ellipsoid",
                rotated_about(
                    &twisted_ellipsoid(ell_c, DVec3::new(0.45, 0.25, 0.3), 18, 8, -0.06),
                    ell_c,
                    rotation(25.0, 0.0, 10.0),
                ),
                6,
            )
        },
    ];
    ExportedScene {
        name: "fig4_9g",
        description: "000 Fig. 4 written with 9 significant digits: plane, 10-sided cylinder and \
                      truncated-cone lights; box, icosphere and a twisted 18x8 UV ellipsoid \
                      (triangulated, slightly dented) occluders; every object rotated",
        format: NumberFormat::Significant(9),
        eye: DVec3::new(0.0, 2.2, 6.0),
        target: DVec3::new(0.0, 1.0, 0.0),
        fov: 45.0,
        materials: vec![
            diffuse("floor", [0.7, 0.7, 0.7]),
            emitter("light_plane", [6.99, 6.99, 6.99]),
            emitter("light_cylinder", [37.6, 32.0, 26.3]),
            emitter("light_cone", [12.8, 14.5, 17.1]),
            diffuse("red", [0.7, 0.3, 0.25]),
            diffuse("green", [0.3, 0.6, 0.3]),
            diffuse("blue", [0.3, 0.4, 0.75]),
        ],
        objects,
    }
}

/// Blender's default primitives as its OBJ exporter writes them (`%.6f`, object transforms
/// applied): a 32 × 16 UV sphere, a cube and a 32-sided cylinder light with n-gon caps, under
/// a quad light.
pub fn blender_primitives() -> ExportedScene {
    let floor = quad(DVec3::ZERO, DVec3::Z * 10.0, DVec3::X * 10.0);
    let sphere_c = DVec3::new(0.0, 1.0, 0.0);
    let cube_c = DVec3::new(-1.6, 0.5, 0.4);
    let cyl_c = DVec3::new(1.0, 3.2, -0.6);
    let lamp_c = DVec3::new(-0.8, 3.5, 0.3);
    let objects = vec![
        ExportedObject {
            occluder: false,
            ..object("Plane", floor, 0)
        },
        object(
            "Sphere",
            rotated_about(
                &uv_ellipsoid(sphere_c, DVec3::splat(0.8), 32, 16),
                sphere_c,
                rotation(0.0, 0.0, 0.0),
            ),
            1,
        ),
        object(
            "Cube",
            rotated_about(
                &cuboid(cube_c, DVec3::splat(0.45)),
                cube_c,
                rotation(35.0, 0.0, 0.0),
            ),
            2,
        ),
        object(
            "Cylinder",
            rotated_about(
                &cylinder(cyl_c, 0.25, 1.0, 32),
                cyl_c,
                rotation(20.0, 90.0, 0.0),
            ),
            3,
        ),
        object("Area", quad(lamp_c, DVec3::X * 0.5, DVec3::Z * 0.5), 4),
    ];
    ExportedScene {
        name: "blender_primitives",
        description: "Blender's default primitives written by its OBJ exporter (%.6f): a 32x16 \
                      UV sphere, a cube and a 32-sided cylinder light with n-gon caps, under a \
                      quad light",
        format: NumberFormat::Fixed(6),
        eye: DVec3::new(0.0, 2.6, 6.5),
        target: DVec3::new(0.0, 0.9, 0.0),
        fov: 45.0,
        materials: vec![
            diffuse("Material.floor", [0.7, 0.7, 0.7]),
            diffuse("Material.sphere", [0.6, 0.6, 0.65]),
            diffuse("Material.cube", [0.7, 0.35, 0.3]),
            emitter("Material.cylinder", [9.0, 8.0, 7.0]),
            emitter("Material.area", [6.0, 6.0, 6.0]),
        ],
        objects,
    }
}

/// A subdivided, displaced icosphere (1,280 triangles, 6 decimals) under a 64-sided cylinder
/// light and a quad light.
pub(crate) fn displaced_blob() -> ExportedScene {
    let floor = quad(DVec3::ZERO, DVec3::Z * 10.0, DVec3::X * 10.0);
    let blob_c = DVec3::new(0.0, 1.0, 0.0);
    let cyl_c = DVec3::new(0.6, 3.0, -0.4);
    let lamp_c = DVec3::new(-1.0, 3.3, 0.5);
    let objects = vec![
        ExportedObject {
            occluder: false,
            ..object("floor", floor, 0)
        },
        object("blob", displaced_icosphere(blob_c, 0.8, 3, 0.12), 1),
        object(
            "tube_light",
            rotated_about(
                &cylinder(cyl_c, 0.12, 1.2, 64),
                cyl_c,
                rotation(-30.0, 90.0, 0.0),
            ),
            2,
        ),
        object(
            "panel_light",
            quad(lamp_c, DVec3::X * 0.4, DVec3::Z * 0.4),
            3,
        ),
    ];
    ExportedScene {
        name: "displaced_blob",
        description: "A subdivided, displaced icosphere (642 vertices, 1,280 triangles, %.6f) \
                      under a 64-sided cylinder light and a quad light",
        format: NumberFormat::Fixed(6),
        eye: DVec3::new(0.0, 2.4, 5.5),
        target: DVec3::new(0.0, 0.9, 0.0),
        fov: 45.0,
        materials: vec![
            diffuse("floor", [0.7, 0.7, 0.7]),
            diffuse("clay", [0.65, 0.55, 0.45]),
            emitter("tube", [14.0, 12.0, 10.0]),
            emitter("panel", [5.0, 5.0, 5.0]),
        ],
        objects,
    }
}

/// The generated scenes of the suite, by name (the bunny scene is a file of `assets/`).
pub(crate) fn generated_scenes() -> Vec<ExportedScene> {
    vec![fig4_9g(), blender_primitives(), displaced_blob()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_print_like_printf_g() {
        let g = NumberFormat::Significant(9);
        assert_eq!(g.write(0.5), "0.5");
        assert_eq!(g.write(1.0 / 3.0), "0.333333333");
        assert_eq!(g.write(-12.25), "-12.25");
        assert_eq!(g.write(123456.789012), "123456.789");
        assert_eq!(g.write(3.0), "3");
        assert_eq!(g.write(1.5e-7), "1.5e-7");
        assert_eq!(NumberFormat::Fixed(6).write(0.1 + 0.2), "0.300000");
    }

    #[test]
    fn twisted_ellipsoid_has_non_planar_quads() {
        let m = twisted_ellipsoid(DVec3::ZERO, DVec3::new(0.45, 0.25, 0.3), 18, 8, 0.06);
        assert!(m.is_closed_manifold());
        assert!(m.max_face_nonplanarity() > 1e-4);
    }
}
