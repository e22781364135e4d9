//! Writing a scene back as a TOML scene file (docs/scenes.md, "Editing and saving scenes").
//!
//! The format places meshes of OBJ files with `scale`/`rotate`/`translate`, but a loaded
//! [`Scene`] keeps its meshes in world space and does not remember which file, entry and
//! transform each came from. [`save_scene`] therefore writes every mesh as it is now, in
//! world space, to an OBJ file (with its MTL file) beside the TOML file, which names each
//! object once and gives its flags. Coordinates and material values are written with the
//! shortest decimal form that reads back as the same f64, so a saved scene loads with the
//! same vertices bit for bit; each entry carries the mesh's `rounding` (the precision its
//! source was written with), which the digits of the saved file could not tell.

use super::environment_spec::EnvironmentSource;
use super::{Camera, Scene};
use serde::Serialize;
use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What [`save_scene`] wrote.
#[derive(Clone, Debug, Default)]
pub struct SavedScene {
    pub toml: PathBuf,
    pub obj: PathBuf,
    pub mtl: PathBuf,
    /// Objects or materials written under another name than they had (names must be unique
    /// in the OBJ file for the scene file to select each object alone, and may not contain
    /// `#` or line breaks): (old, new).
    pub renamed: Vec<(String, String)>,
}

#[derive(Serialize)]
struct SceneOut {
    #[serde(skip_serializing_if = "Option::is_none")]
    camera: Option<CameraOut>,
    #[serde(skip_serializing_if = "Option::is_none")]
    environment: Option<EnvironmentOut>,
    object: Vec<ObjectOut>,
}

#[derive(Serialize)]
struct CameraOut {
    eye: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    fov: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    aspect: Option<f64>,
}

#[derive(Serialize)]
struct EnvironmentOut {
    map: String,
    rotate: f64,
    scale: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    method: Option<super::environment_spec::EnvMethod>,
    #[serde(skip_serializing_if = "Option::is_none")]
    spp: Option<u32>,
}

#[derive(Serialize)]
struct ObjectOut {
    obj: String,
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    light: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    occluder: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    receiver: Option<bool>,
    #[serde(rename = "static", skip_serializing_if = "Option::is_none")]
    is_static: Option<bool>,
    rounding: f64,
}

/// `name` made fit for an OBJ/MTL statement (no `#`, no line breaks, trimmed, not empty) and
/// unique among `used`.
fn unique_name(name: &str, fallback: &str, used: &mut HashSet<String>) -> String {
    let clean: String = name
        .chars()
        .map(|c| if c == '#' || c.is_control() { '_' } else { c })
        .collect();
    let clean = clean.trim();
    let base = if clean.is_empty() { fallback } else { clean };
    let mut candidate = base.to_owned();
    let mut k = 2;
    while used.contains(&candidate) {
        candidate = format!("{base}_{k}");
        k += 1;
    }
    used.insert(candidate.clone());
    candidate
}

/// A `Pr` whose square is `alpha` exactly where one exists (the loader takes alpha = Pr²).
fn roughness_for(alpha: f64) -> f64 {
    let r = alpha.sqrt();
    [
        r,
        r.next_up(),
        r.next_down(),
        r.next_up().next_up(),
        r.next_down().next_down(),
    ]
    .into_iter()
    .find(|p| p * p == alpha)
    .unwrap_or(r)
}

/// The text of a saved scene's three files, and the renamings.
#[derive(Clone, Debug, Default)]
pub(crate) struct SceneTexts {
    pub toml: String,
    pub obj: String,
    pub mtl: String,
    /// Objects or materials written under another name: (old, new).
    pub renamed: Vec<(String, String)>,
}

/// The text of the three files, naming the OBJ and MTL files `obj_name` and `mtl_name` (an
/// environment map file is named relative to `base_dir` where it lies below it).
pub(crate) fn scene_texts(
    scene: &Scene,
    camera: Option<&Camera>,
    obj_name: &str,
    mtl_name: &str,
    base_dir: &Path,
) -> crate::Result<SceneTexts> {
    let mut renamed = Vec::new();
    let mut obj = String::new();
    let mut mtl = String::new();
    let _ = writeln!(
        obj,
        "# written by penumbra (scene::save)\nmtllib {mtl_name}"
    );
    let _ = writeln!(mtl, "# written by penumbra (scene::save)");
    let mut object_names = HashSet::new();
    // Materials by name: one `newmtl` per distinct material.
    let mut materials: Vec<(String, super::Material)> = Vec::new();
    let mut material_names = HashSet::new();
    let mut entries = Vec::new();
    let mut next_vertex = 1usize;
    let v3 = |v: glam::DVec3| format!("{} {} {}", v.x, v.y, v.z);
    for (i, o) in scene.objects.iter().enumerate() {
        let name = unique_name(&o.name, &format!("object{i}"), &mut object_names);
        if name != o.name {
            renamed.push((o.name.clone(), name.clone()));
        }
        let m = &o.material;
        if !(m.kd.is_finite() && m.ks.is_finite() && m.ke.is_finite() && m.alpha.is_finite()) {
            return Err(crate::Error::from(format!(
                "object '{}' has a non-finite material",
                o.name
            )));
        }
        let mat_name = match materials.iter().find(|(_, x)| x == m) {
            Some((n, _)) => n.clone(),
            None => {
                let n = unique_name(&m.name, &format!("material{i}"), &mut material_names);
                if n != m.name {
                    renamed.push((m.name.clone(), n.clone()));
                }
                let _ = writeln!(
                    mtl,
                    "\nnewmtl {n}\nKd {}\nKs {}\nKe {}\nPr {}",
                    v3(m.kd),
                    v3(m.ks),
                    v3(m.ke),
                    roughness_for(m.alpha)
                );
                materials.push((n.clone(), m.clone()));
                n
            }
        };
        let _ = writeln!(obj, "o {name}\nusemtl {mat_name}");
        // Vertices in the order the faces first use them (the order the loader gives them).
        let pos = &o.mesh.positions;
        let mut index = vec![0usize; pos.len()];
        for f in &o.mesh.faces {
            for &k in f {
                let k = k as usize;
                let Some(p) = pos.get(k) else {
                    return Err(crate::Error::from(format!(
                        "object '{}' has a face index out of range",
                        o.name
                    )));
                };
                if !p.is_finite() {
                    return Err(crate::Error::from(format!(
                        "object '{}' has a non-finite vertex",
                        o.name
                    )));
                }
                if index[k] == 0 {
                    index[k] = next_vertex;
                    next_vertex += 1;
                    let _ = writeln!(obj, "v {}", v3(*p));
                }
            }
        }
        for f in &o.mesh.faces {
            obj.push('f');
            for &k in f {
                let _ = write!(obj, " {}", index[k as usize]);
            }
            obj.push('\n');
        }
        let fl = o.flags;
        entries.push(ObjectOut {
            obj: obj_name.to_owned(),
            name,
            light: (fl.light != m.is_emissive()).then_some(fl.light),
            occluder: (!fl.occluder).then_some(false),
            receiver: (!fl.receiver).then_some(false),
            is_static: fl.is_static.then_some(true),
            rounding: o.mesh.rounding,
        });
    }
    let environment = scene.environment.as_ref().map(|e| EnvironmentOut {
        map: match &e.source {
            EnvironmentSource::Sky | EnvironmentSource::SkySh => e.source.name(),
            EnvironmentSource::File(p) => {
                let abs = std::path::absolute(p).unwrap_or_else(|_| p.clone());
                let dir = std::path::absolute(base_dir).unwrap_or_else(|_| base_dir.into());
                abs.strip_prefix(&dir)
                    .map(Path::to_path_buf)
                    .unwrap_or(abs)
                    .to_string_lossy()
                    .into_owned()
            }
        },
        rotate: e.rotate_deg,
        scale: e.scale,
        method: e.method,
        spp: e.spp,
    });
    let doc = SceneOut {
        camera: camera.map(|c| CameraOut {
            eye: c.eye.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            fov: c.fov_deg,
            aspect: c.aspect,
        }),
        environment,
        object: entries,
    };
    let body = toml::to_string(&doc).map_err(|e| format!("cannot write the scene file: {e}"))?;
    let toml = format!(
        "# penumbra scene, written by scene::save (`penumbra edit`); meshes in world space in \
         {obj_name}\n\n{body}"
    );
    Ok(SceneTexts {
        toml,
        obj,
        mtl,
        renamed,
    })
}

/// Writes `scene` seen by `camera` as the scene file `path` (`.toml`), with its meshes in
/// `STEM.obj` and materials in `STEM.mtl` beside it (both overwritten). Loading `path` gives
/// the same objects (names made unique), vertices (bit for bit, in the order the faces use
/// them), faces, materials, flags, camera and environment.
pub fn save_scene(
    scene: &Scene,
    camera: Option<&Camera>,
    path: &Path,
) -> crate::Result<SavedScene> {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| format!("{}: not a file name", path.display()))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let (obj_name, mtl_name) = (format!("{stem}.obj"), format!("{stem}.mtl"));
    let (obj_path, mtl_path) = (dir.join(&obj_name), dir.join(&mtl_name));
    if obj_path == path {
        return Err(crate::Error::from(format!(
            "{}: the scene file must not end in .obj",
            path.display()
        )));
    }
    let texts = scene_texts(scene, camera, &obj_name, &mtl_name, &dir)?;
    let write = |p: &Path, text: &str| {
        std::fs::write(p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))
    };
    write(&obj_path, &texts.obj)?;
    write(&mtl_path, &texts.mtl)?;
    write(path, &texts.toml)?;
    Ok(SavedScene {
        toml: path.to_path_buf(),
        obj: obj_path,
        mtl: mtl_path,
        renamed: texts.renamed,
    })
}
