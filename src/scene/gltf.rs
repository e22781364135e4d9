//! glTF 2.0 loading, `.glb` and `.gltf` (docs/scenes.md, "glTF 2.0").
//!
//! The `gltf` crate reads the container and the JSON (`container`); buffers, accessors,
//! materials and the node hierarchy are decoded here with every index and byte range checked
//! (`buffers`, `accessor`, `materials`, `nodes`), so that bad input is an error naming the
//! file, never a panic.
//!
//! Each drawn node's mesh becomes one object per material: the triangles of its primitives
//! with that material, in world space (f64), with bit-identical positions welded (glTF splits
//! vertices at UV seams and normal creases; welded, a closed mesh is closed). The triangles
//! then go through the OBJ loader's face repair (`super::obj::build_object`), which groups
//! its warnings per object.

mod accessor;
mod buffers;
mod container;
mod materials;
mod nodes;

pub use materials::DIELECTRIC_F0;

use super::Scene;
use super::obj::{FaceOrigin, FaceSource, Warnings, build_object};
use super::precision::WrittenPrecision;
use crate::Result;
use buffers::Buffers;
use glam::{DAffine3, DVec3};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use std::collections::HashMap;
use std::path::Path;

/// Extensions a file may require that penumbra can read without them: they only change what
/// is ignored anyway (textures, material lobes, punctual lights).
const HARMLESS_EXTENSIONS: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "KHR_materials_unlit",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_iridescence",
    "KHR_materials_anisotropy",
    "KHR_materials_dispersion",
    "KHR_materials_variants",
    "KHR_lights_punctual",
    "EXT_texture_webp",
];

/// Loads a `.glb` or `.gltf` file; external buffers are relative to its directory.
pub fn load_gltf(path: &Path) -> Result<Scene> {
    let label = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| crate::Error::File {
        file: label.clone(),
        message: format!("cannot read file: {e}"),
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    load_gltf_bytes(&bytes, &label, Some(&dir))
}

/// Loads glTF from memory (binary or JSON, told apart by the GLB magic). `name_for_errors`
/// names it in errors and warnings; external buffers are read relative to `dir`, and are an
/// error without it.
pub fn load_gltf_bytes(bytes: &[u8], name_for_errors: &str, dir: Option<&Path>) -> Result<Scene> {
    let file = name_for_errors;
    let parsed = container::parse(bytes, file)?;
    let root = &parsed.root;
    let err = |message: String| crate::Error::File {
        file: file.to_owned(),
        message,
    };
    if !root.asset.version.starts_with("2.") {
        return Err(err(format!(
            "asset.version is '{}': only glTF 2.x is read",
            root.asset.version
        )));
    }
    let mut warn = Warnings::default();
    let mut notes: Vec<String> = Vec::new();
    for ext in &root.extensions_required {
        if HARMLESS_EXTENSIONS.contains(&ext.as_str()) {
            if ext != "KHR_materials_emissive_strength" {
                notes.push(format!("required extension {ext} is ignored"));
            }
        } else {
            return Err(err(format!(
                "extensionsRequired: {ext} is not supported (e.g. compressed or quantized \
                 geometry)"
            )));
        }
    }
    if materials::uses_textures(root) {
        notes.push(format!(
            "{} textures are ignored: materials use their factors only",
            root.textures.len()
        ));
    }

    let mut buffers = Buffers::new(root, parsed.bin.as_deref(), dir, file);
    let placed = nodes::placed_nodes(root, file, &mut notes)?;
    let mut scene = Scene::default();
    let mut positions_cache: HashMap<usize, std::rc::Rc<Vec<DVec3>>> = HashMap::new();
    let mut materials_cache: HashMap<Option<usize>, super::Material> = HashMap::new();
    let mut skipped_modes = 0usize;
    let mut first_skipped = String::new();
    for p in &placed {
        let node = &root.nodes[p.node];
        let Some(mi) = node.mesh.as_ref().map(|m| m.value()) else {
            continue;
        };
        let mesh = root.meshes.get(mi).ok_or_else(|| {
            err(format!(
                "nodes[{}].mesh: meshes[{mi}] does not exist ({} meshes)",
                p.node,
                root.meshes.len()
            ))
        })?;
        let name = [node.name.as_deref(), mesh.name.as_deref()]
            .into_iter()
            .flatten()
            .find(|n| !n.is_empty())
            .map_or_else(|| format!("node{}", p.node), str::to_owned);
        // The primitives by material, in the order first met.
        let mut groups: Vec<(Option<usize>, ObjectBuilder)> = Vec::new();
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let here = format!("meshes[{mi}].primitives[{pi}]");
            if prim.mode != Checked::Valid(Mode::Triangles) {
                skipped_modes += 1;
                if first_skipped.is_empty() {
                    first_skipped = here.clone();
                }
                continue;
            }
            let Some(pos) = prim.attributes.get(&Checked::Valid(Semantic::Positions)) else {
                return Err(err(format!("{here}.attributes has no POSITION")));
            };
            let pos = pos.value();
            let local = match positions_cache.get(&pos) {
                Some(v) => v.clone(),
                None => {
                    let v =
                        std::rc::Rc::new(accessor::read_positions(root, &mut buffers, pos, file)?);
                    positions_cache.insert(pos, v.clone());
                    v
                }
            };
            let indices = match &prim.indices {
                Some(ix) => {
                    accessor::read_indices(root, &mut buffers, ix.value(), local.len(), file)?
                }
                None => (0..local.len() as u32).collect(),
            };
            if indices.len() % 3 != 0 {
                notes.push(format!(
                    "{here}: {} indices are not a whole number of triangles; the last {} ignored",
                    indices.len(),
                    indices.len() % 3
                ));
            }
            let material = prim.material.as_ref().map(|m| m.value());
            if let Some(m) = material
                && m >= root.materials.len()
            {
                return Err(err(format!(
                    "{here}.material: materials[{m}] does not exist ({} materials)",
                    root.materials.len()
                )));
            }
            let k = match groups.iter().position(|(m, _)| *m == material) {
                Some(k) => k,
                None => {
                    groups.push((material, ObjectBuilder::new(&p.world)));
                    groups.len() - 1
                }
            };
            groups[k].1.add(pi, &local, &indices);
        }
        for (material, b) in groups {
            let mat = materials_cache
                .entry(material)
                .or_insert_with(|| materials::material(root, material, &mut notes))
                .clone();
            let context = format!(
                "nodes[{}] '{name}', meshes[{mi}] primitives {}",
                p.node,
                b.primitives
                    .iter()
                    .map(|i| i.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            let rounding = |g: u32| b.rounding.get(g as usize).copied().unwrap_or(0.0);
            let src = FaceSource {
                file,
                origin: FaceOrigin::Triangles { context: &context },
                positions: &b.positions,
                rounding: &rounding,
                precision: "f32 values".to_owned(),
            };
            if let Some(obj) = build_object(&name, &b.faces, &src, mat, &mut warn) {
                scene.objects.push(obj);
            }
        }
    }
    if skipped_modes > 0 {
        notes.push(format!(
            "{skipped_modes} primitives skipped (first: {first_skipped}): only triangles \
             (mode 4) are read, not points, lines, strips or fans"
        ));
    }
    let bounds = scene.bounds();
    scene.camera = nodes::first_camera(
        root,
        &placed,
        |eye, forward| match bounds {
            // Aim at the depth of the scene's centre, or one unit ahead.
            Some((lo, hi)) => {
                let d = (0.5 * (lo + hi) - eye).dot(forward);
                if d > 1e-9 { d } else { 1.0 }
            }
            None => 1.0,
        },
        &mut notes,
    );
    let mut all: Vec<String> = notes.iter().map(|n| format!("{file}: {n}")).collect();
    all.extend(warn.finish(file));
    if scene.objects.is_empty() {
        all.push(format!("{file}: no triangles found; the scene is empty"));
    }
    scene.warnings = all;
    Ok(scene)
}

/// The triangles of one object (a drawn node's primitives of one material) in world space,
/// with bit-identical positions welded.
struct ObjectBuilder {
    world: DAffine3,
    /// The map mirrors space: triangles are reversed to keep their fronts.
    mirrors: bool,
    /// How much the map stretches a vector at most (Frobenius norm), for the rounding.
    stretch: f64,
    positions: Vec<DVec3>,
    /// Each welded vertex's rounding radius: half an f32 ulp per local coordinate, stretched.
    rounding: Vec<f64>,
    weld: HashMap<[u64; 3], u32>,
    /// (triangle number, vertices) in the order read.
    faces: Vec<(usize, Vec<u32>)>,
    primitives: Vec<usize>,
}

impl ObjectBuilder {
    fn new(world: &DAffine3) -> Self {
        let m = world.matrix3;
        ObjectBuilder {
            world: *world,
            mirrors: m.determinant() < 0.0,
            stretch: DVec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length()).length(),
            positions: Vec::new(),
            rounding: Vec::new(),
            weld: HashMap::new(),
            faces: Vec::new(),
            primitives: Vec::new(),
        }
    }

    fn add(&mut self, primitive: usize, local: &[DVec3], indices: &[u32]) {
        self.primitives.push(primitive);
        let f32_data = WrittenPrecision {
            fixed_last_digit: None,
            significant: 9,
            f32_data: true,
            empty: false,
        };
        let mut ids: HashMap<u32, u32> = HashMap::new();
        for tri in indices.chunks_exact(3) {
            let mut face = Vec::with_capacity(3);
            for &i in tri {
                let id = *ids.entry(i).or_insert_with(|| {
                    let lp = local.get(i as usize).copied().unwrap_or(DVec3::ZERO);
                    // + 0.0 turns -0.0 into 0.0, so that the two weld.
                    let w = self.world.transform_point3(lp) + DVec3::ZERO;
                    let key = [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()];
                    *self.weld.entry(key).or_insert_with(|| {
                        self.positions.push(w);
                        self.rounding
                            .push(f32_data.vertex_rounding(lp) * self.stretch);
                        (self.positions.len() - 1) as u32
                    })
                });
                face.push(id);
            }
            if self.mirrors {
                face.reverse();
            }
            self.faces.push((self.faces.len(), face));
        }
    }
}
