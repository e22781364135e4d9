//! Scenes: meshes with materials and flags, loaded from OBJ/MTL, glTF 2.0 and scene files, plus
//! the camera.
//!
//! Conventions (docs/scenes.md):
//! * `Ke` > 0 makes a mesh an area light with constant radiance `Ke`, emitting from the front
//!   side of each face (counter-clockwise winding seen from the front).
//! * `Kd` is the Lambertian albedo, `Ks` the reflectance F0 of a GGX lobe with alpha = `Pr`^2.
//! * Receivers are shaded two-sided; every surface occludes unless the scene file says otherwise.

pub(crate) mod camera;
pub mod edit;
pub mod environment_spec;
pub mod face_triangulation;
pub mod gltf;
pub mod obj;
pub mod precision;
pub mod save;
pub mod scene_file;
pub mod shapes;
pub mod thesis_polyhedra;

pub use camera::{Camera, CameraBasis};

use glam::DVec3;

/// Surface description after the MTL conventions above have been applied.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    pub name: String,
    /// Lambertian albedo (`Kd`).
    pub kd: DVec3,
    /// Specular reflectance at normal incidence, Schlick's F0 (`Ks`).
    pub ks: DVec3,
    /// GGX roughness alpha = `Pr`^2 (see docs/scenes.md for the fallback when `Pr` is absent).
    pub alpha: f64,
    /// Emitted radiance (`Ke`); nonzero makes the mesh a light.
    pub ke: DVec3,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: "default".into(),
            kd: DVec3::splat(0.8),
            ks: DVec3::ZERO,
            alpha: 0.25,
            ke: DVec3::ZERO,
        }
    }
}

impl Material {
    pub fn is_emissive(&self) -> bool {
        self.ke.max_element() > 0.0
    }
    pub fn has_specular(&self) -> bool {
        self.ks.max_element() > 0.0
    }
}

/// What an object takes part in. 000 marks lights and occluders explicitly so that, e.g.,
/// the walls of a room are never tested as occluders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ObjectFlags {
    pub light: bool,
    pub occluder: bool,
    pub receiver: bool,
    /// A static object of 002 (Sect. 3.2): its shadow under the environment light is part of
    /// the precomputed term (PRT), and only dynamic objects are traced or subtracted at run
    /// time. Objects are dynamic unless a scene file says `static = true`.
    #[serde(default)]
    pub is_static: bool,
}

/// A polygon mesh in world space. Faces are vertex-index loops, counter-clockwise seen from
/// the front; they are kept as polygons (not triangulated) so that a quad light stays one face.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
    /// The largest distance of a vertex from the position its author meant: the rounding
    /// radius of the digits the file wrote it with (`precision`), 0 for meshes computed here
    /// (exact up to f64 rounding). Transforms scale it with the mesh.
    pub rounding: f64,
}

impl Mesh {
    /// The centre of the bounding box of the positions and the largest distance of a position
    /// from it.
    pub(crate) fn bounding_sphere(&self) -> (DVec3, f64) {
        let (lo, hi) = self
            .positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
                (a.min(p), b.max(p))
            });
        let c = 0.5 * (lo + hi);
        let r = self
            .positions
            .iter()
            .map(|p| p.distance(c))
            .fold(0.0, f64::max);
        (c, r)
    }

    /// Fan triangulation of every face, as index triples (the per-triangle method, ray casting).
    pub(crate) fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.faces
            .iter()
            .flat_map(|f| (1..f.len().saturating_sub(1)).map(move |i| [f[0], f[i], f[i + 1]]))
    }
}

/// One object of a scene: a mesh, its material and its flags.
#[derive(Clone, Debug)]
pub struct SceneObject {
    pub name: String,
    pub mesh: Mesh,
    pub material: Material,
    pub flags: ObjectFlags,
}

/// A loaded scene. `camera` is the scene file's camera, if it has one.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub objects: Vec<SceneObject>,
    pub camera: Option<Camera>,
    /// Repairs and notes produced while loading (shown to the user, never silent).
    pub warnings: Vec<String>,
    /// The scene file's `[environment]`, if it has one (the command line may override it).
    pub environment: Option<environment_spec::EnvironmentSpec>,
}
