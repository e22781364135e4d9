//! TOML scene files, scene dispatch by extension, and the embedded scenes (docs/scenes.md).
//!
//! ```toml
//! [camera]
//! eye = [0.0, 1.5, 4.0]
//! target = [0.0, 0.5, 0.0]
//! up = [0.0, 1.0, 0.0]      # optional, default +y
//! fov = 40.0                # vertical field of view, degrees
//!
//! [[object]]
//! obj = "room.obj"          # relative to this file
//! name = "floor"            # optional: only the OBJ objects of that name
//! occluder = false          # optional flag overrides: light, occluder, receiver
//! scale = 2.0               # optional: scalar or [sx, sy, sz], applied first
//! translate = [0, 0, 1]     # optional, applied after scaling
//! ```

use super::obj::{MtlSource, load_obj, load_obj_with, read_text};
use super::{Camera, Scene, SceneError, SceneObject};
use glam::DVec3;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;
use toml::Spanned;

/// Scene files compiled into the binary: (file name, contents). The TOML scenes refer to the
/// OBJ files by these names, the OBJ files to the MTL files.
const EMBEDDED_FILES: &[(&str, &str)] = &[
    (
        "default.toml",
        include_str!("../../assets/scenes/default.toml"),
    ),
    (
        "default.obj",
        include_str!("../../assets/scenes/default.obj"),
    ),
    (
        "default.mtl",
        include_str!("../../assets/scenes/default.mtl"),
    ),
    ("fig4.toml", include_str!("../../assets/scenes/fig4.toml")),
    ("fig4.obj", include_str!("../../assets/scenes/fig4.obj")),
    ("fig4.mtl", include_str!("../../assets/scenes/fig4.mtl")),
    ("chair.toml", include_str!("../../assets/scenes/chair.toml")),
    ("chair.obj", include_str!("../../assets/scenes/chair.obj")),
    ("chair.mtl", include_str!("../../assets/scenes/chair.mtl")),
    (
        "nonconvex.toml",
        include_str!("../../assets/scenes/nonconvex.toml"),
    ),
    (
        "nonconvex.obj",
        include_str!("../../assets/scenes/nonconvex.obj"),
    ),
    (
        "nonconvex.mtl",
        include_str!("../../assets/scenes/nonconvex.mtl"),
    ),
    (
        "polyhedra.toml",
        include_str!("../../assets/scenes/polyhedra.toml"),
    ),
    (
        "polyhedra.obj",
        include_str!("../../assets/scenes/polyhedra.obj"),
    ),
    (
        "polyhedra.mtl",
        include_str!("../../assets/scenes/polyhedra.mtl"),
    ),
];

const EMBEDDED_SCENES: &[&str] = &["default", "fig4", "chair", "nonconvex", "polyhedra"];

/// Names of the scenes compiled into the binary (`load_embedded` takes these).
pub fn embedded_scene_names() -> &'static [&'static str] {
    EMBEDDED_SCENES
}

/// Loads an embedded scene by name (`"fig4"` or `"fig4.toml"`); works from any directory.
pub fn load_embedded(name: &str) -> Result<Scene, SceneError> {
    let stem = name.strip_suffix(".toml").unwrap_or(name);
    if !EMBEDDED_SCENES.contains(&stem) {
        return Err(SceneError::File {
            file: name.to_owned(),
            message: format!(
                "no embedded scene of that name; available: {}",
                EMBEDDED_SCENES.join(", ")
            ),
        });
    }
    let file = format!("{stem}.toml");
    let text = embedded_file(&file).unwrap_or_default();
    let label = embedded_label(&file);
    parse_scene_toml(text, &label, &|rel: &str| {
        let key = normalize(rel);
        let text = embedded_file(&key)
            .ok_or_else(|| ObjFailure::Missing(format!("no embedded file '{key}'")))?;
        load_obj_with(text, &embedded_label(&key), &|mtl: &str| {
            let key = normalize(mtl);
            match embedded_file(&key) {
                Some(text) => MtlSource::Found {
                    label: embedded_label(&key),
                    text: text.to_owned(),
                },
                None => MtlSource::Missing {
                    label: embedded_label(&key),
                    reason: "no such embedded file".into(),
                },
            }
        })
        .map_err(ObjFailure::Obj)
    })
}

/// Loads a scene: `.toml` scene files, or a plain `.obj` with the default flags and no camera.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("toml") => load_scene_file(path),
        Some("obj") => load_obj(path),
        _ => Err(SceneError::File {
            file: path.display().to_string(),
            message: "unknown scene file type; expected .toml (scene file) or .obj".into(),
        }),
    }
}

/// Loads a TOML scene file; OBJ paths are relative to its directory.
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let label = path.display().to_string();
    let text = read_text(path, &label)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_scene_toml(&text, &label, &|rel: &str| {
        let p = dir.join(rel);
        if !p.is_file() {
            return Err(ObjFailure::Missing(format!(
                "cannot read OBJ file '{}': no such file",
                p.display()
            )));
        }
        load_obj(&p).map_err(ObjFailure::Obj)
    })
}

/// Parses scene-file text; `label` names it in errors, `load` resolves the `obj` paths.
/// Exposed for tests and tools that keep scenes in memory.
pub fn load_scene_str(
    text: &str,
    label: &str,
    load: &dyn Fn(&str) -> Result<Scene, SceneError>,
) -> Result<Scene, SceneError> {
    parse_scene_toml(text, label, &|rel: &str| load(rel).map_err(ObjFailure::Obj))
}

fn embedded_file(name: &str) -> Option<&'static str> {
    EMBEDDED_FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
}

fn embedded_label(name: &str) -> String {
    format!("<embedded>/assets/scenes/{name}")
}

fn normalize(rel: &str) -> String {
    rel.trim_start_matches("./").to_owned()
}

// ---------------------------------------------------------------------------------------------
// Scene queries
// ---------------------------------------------------------------------------------------------

impl Scene {
    /// Objects flagged as lights.
    pub fn lights(&self) -> impl Iterator<Item = &SceneObject> {
        self.objects.iter().filter(|o| o.flags.light)
    }
    /// Objects flagged as occluders.
    pub fn occluders(&self) -> impl Iterator<Item = &SceneObject> {
        self.objects.iter().filter(|o| o.flags.occluder)
    }
    /// Objects flagged as receivers.
    pub fn receivers(&self) -> impl Iterator<Item = &SceneObject> {
        self.objects.iter().filter(|o| o.flags.receiver)
    }
    /// First object of that name.
    pub fn object(&self, name: &str) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.name == name)
    }
    /// Irradiance at `x` (normal `n`) from all lights, ignoring every occlusion (see
    /// [`crate::scene::Mesh::irradiance_factor`]); a calibration aid and test oracle.
    pub fn unshadowed_irradiance(&self, x: DVec3, n: DVec3) -> DVec3 {
        self.lights()
            .map(|l| l.material.ke * l.mesh.irradiance_factor(x, n))
            .sum()
    }
    /// Axis-aligned bounds of all meshes, `None` without vertices.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.objects
            .iter()
            .filter_map(|o| o.mesh.bounds())
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
    }
}

// ---------------------------------------------------------------------------------------------
// The TOML format
// ---------------------------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneToml {
    camera: Option<Spanned<CameraToml>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectToml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraToml {
    eye: [f64; 3],
    target: [f64; 3],
    up: Option<[f64; 3]>,
    fov: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectToml {
    obj: Spanned<String>,
    name: Option<Spanned<String>>,
    light: Option<Spanned<bool>>,
    occluder: Option<bool>,
    receiver: Option<bool>,
    translate: Option<Spanned<[f64; 3]>>,
    scale: Option<Spanned<ScaleToml>>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum ScaleToml {
    Uniform(f64),
    PerAxis([f64; 3]),
}

/// Why an `obj` reference could not be loaded.
enum ObjFailure {
    /// The file is not there (reported at the TOML line).
    Missing(String),
    /// The OBJ/MTL itself is bad (its own file and line).
    Obj(SceneError),
}

fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn parse_scene_toml(
    text: &str,
    label: &str,
    load: &dyn Fn(&str) -> Result<Scene, ObjFailure>,
) -> Result<Scene, SceneError> {
    let at = |span: std::ops::Range<usize>, message: String| SceneError::Line {
        file: label.to_owned(),
        line: line_of(text, span.start),
        message,
    };
    let doc: SceneToml = toml::from_str(text).map_err(|e| {
        let mut message = e.message().trim().to_owned();
        if message.contains("ScaleToml") {
            message = "scale must be a number or an array [sx, sy, sz]".into();
        }
        match e.span() {
            Some(span) => at(span, message),
            None => SceneError::File {
                file: label.to_owned(),
                message,
            },
        }
    })?;

    let mut scene = Scene::default();
    if let Some(cam) = &doc.camera {
        let c = cam.get_ref();
        let camera = Camera {
            eye: DVec3::from_array(c.eye),
            target: DVec3::from_array(c.target),
            up: c.up.map_or(DVec3::Y, DVec3::from_array),
            fov_deg: c.fov,
        };
        camera
            .basis()
            .map_err(|m| at(cam.span(), format!("invalid camera: {m}")))?;
        scene.camera = Some(camera);
    }

    let mut cache: HashMap<String, Scene> = HashMap::new();
    for entry in &doc.object {
        let o = entry.get_ref();
        let rel = o.obj.get_ref();
        if !cache.contains_key(rel) {
            let loaded = load(rel).map_err(|f| match f {
                ObjFailure::Missing(m) => at(o.obj.span(), m),
                ObjFailure::Obj(e) => e,
            })?;
            scene.warnings.extend(loaded.warnings.iter().cloned());
            cache.insert(rel.clone(), loaded);
        }
        let source = &cache[rel];
        let selected: Vec<&SceneObject> = match &o.name {
            None => source.objects.iter().collect(),
            Some(name) => {
                let sel: Vec<_> = source
                    .objects
                    .iter()
                    .filter(|x| x.name == *name.get_ref())
                    .collect();
                if sel.is_empty() {
                    let mut names: Vec<&str> =
                        source.objects.iter().map(|x| x.name.as_str()).collect();
                    names.dedup();
                    return Err(at(
                        name.span(),
                        format!(
                            "'{rel}' has no object named '{}'; it has: {}",
                            name.get_ref(),
                            names.join(", ")
                        ),
                    ));
                }
                sel
            }
        };
        if selected.is_empty() {
            scene.warnings.push(format!(
                "{label}:{}: '{rel}' has no objects",
                line_of(text, o.obj.span().start)
            ));
        }
        let scale = match &o.scale {
            None => DVec3::ONE,
            Some(s) => {
                let v = match s.get_ref() {
                    ScaleToml::Uniform(k) => DVec3::splat(*k),
                    ScaleToml::PerAxis(a) => DVec3::from_array(*a),
                };
                if !v.is_finite() || v.cmpeq(DVec3::ZERO).any() {
                    return Err(at(
                        s.span(),
                        "scale factors must be finite and nonzero".into(),
                    ));
                }
                v
            }
        };
        let translate = match &o.translate {
            None => DVec3::ZERO,
            Some(t) => {
                let v = DVec3::from_array(*t.get_ref());
                if !v.is_finite() {
                    return Err(at(t.span(), "translation must be finite".into()));
                }
                v
            }
        };
        for src in selected {
            let mut obj = src.clone();
            obj.mesh = obj.mesh.scaled(scale).translated(translate);
            if let Some(light) = &o.light {
                obj.flags.light = *light.get_ref();
                if obj.flags.light && !obj.material.is_emissive() {
                    scene.warnings.push(format!(
                        "{label}:{}: object '{}' is flagged as a light but its Ke is zero; it emits nothing",
                        line_of(text, light.span().start),
                        obj.name
                    ));
                }
            }
            if let Some(v) = o.occluder {
                obj.flags.occluder = v;
            }
            if let Some(v) = o.receiver {
                obj.flags.receiver = v;
            }
            scene.objects.push(obj);
        }
    }
    if scene.objects.is_empty() {
        scene
            .warnings
            .push(format!("{label}: the scene has no objects"));
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_numbers() {
        assert_eq!(line_of("a\nb\nc", 0), 1);
        assert_eq!(line_of("a\nb\nc", 2), 2);
        assert_eq!(line_of("a\nb\nc", 99), 3);
    }
}
