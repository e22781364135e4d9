//! What the workbench reads and writes: scenes, debug dumps, bench reports, images, and the
//! command line that reproduces the current render headless.

use crate::Result;
use crate::bench::table::BenchReport;
use crate::error::InFile;
use crate::inspect::Probe;
use crate::render::{Image, RenderSettings, image_io};
use crate::scene::{Camera, Scene, scene_file};
use std::path::Path;

/// What a dropped or opened file is.
pub(crate) enum Opened {
    Scene(String, Scene),
    Dump(Box<Probe>),
    Bench(Box<BenchReport>),
    Reference(Image),
    /// An equirectangular environment map (.hdr, .exr) to light the scene with.
    Environment(super::environment_panel::MapChoice),
}

/// Loads a scene by embedded name or path (`scene_file::load_scene_by_name`).
pub(crate) fn load_scene(name: &str) -> Result<Scene> {
    scene_file::load_scene_by_name(name)
}

/// Opens a file by its content: a scene (.toml, .obj, .glb, .gltf), a debug dump or bench report (.json),
/// or a reference image (.pfm).
pub(crate) fn open(path: &Path) -> Result<Opened> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let name = path.display().to_string();
    match ext.as_str() {
        "toml" | "obj" | "glb" | "gltf" => Ok(Opened::Scene(name.clone(), load_scene(&name)?)),
        "hdr" | "exr" => Ok(Opened::Environment(
            super::environment_panel::MapChoice::File(path.to_path_buf()),
        )),
        "pfm" => Ok(Opened::Reference(
            image_io::read_pfm_image(path).in_file(&name, "")?,
        )),
        "json" => {
            let text = std::fs::read_to_string(path).in_file(&name, "")?;
            open_json(&text, &name)
        }
        _ => Err(crate::Error::from(format!(
            "{name}: unknown file type (expected .toml, .obj, .glb, .gltf, .json, .pfm, .hdr or .exr)"
        ))),
    }
}

/// A debug dump or a bench report from its JSON text; `name` names it in errors.
fn open_json(text: &str, name: &str) -> Result<Opened> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        crate::Error::from(format!("{name}:{}:{}: not JSON: {e}", e.line(), e.column()))
    })?;
    if value.get("recording").is_some() {
        let p = Probe::from_json(text, name)?;
        Ok(Opened::Dump(Box::new(p)))
    } else if value.get("equal_time").is_some() {
        let r: BenchReport =
            serde_json::from_value(value).in_file(name, "not a penumbra bench report")?;
        Ok(Opened::Bench(Box::new(r)))
    } else {
        Err(crate::Error::from(format!(
            "{name}: neither a debug dump nor a bench report"
        )))
    }
}

/// Opens files handed over by content (dropped on the browser's page, or chosen in its
/// picker), each with the name it is shown by. Files that others refer to come along: an
/// OBJ takes an MTL of the same drop (the one its `mtllib` names, else the only one); a TOML
/// scene's `obj` paths are matched by file name among the dropped OBJs (with their MTLs).
/// MTL files alone open nothing.
pub(crate) fn open_contents(
    files: &[super::platform::FileContent],
) -> Vec<(String, Result<Opened>)> {
    let ext = |name: &str| {
        Path::new(name)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default()
    };
    let file_name = |name: &str| {
        Path::new(name)
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let text = |f: &super::platform::FileContent| -> Result<String> {
        String::from_utf8(f.bytes.to_vec()).in_file(&f.name, "not UTF-8 text")
    };
    // An OBJ's MTL: the one its mtllib names, else the only MTL given.
    let mtl_for = |obj: &str| -> Result<Option<String>> {
        let mtls: Vec<_> = files.iter().filter(|f| ext(&f.name) == "mtl").collect();
        let named = obj
            .lines()
            .filter_map(|l| l.trim().strip_prefix("mtllib "))
            .flat_map(|names| names.split_whitespace())
            .find_map(|n| mtls.iter().find(|m| file_name(&m.name) == file_name(n)));
        match named.or(if mtls.len() == 1 { mtls.first() } else { None }) {
            Some(m) => Ok(Some(text(m)?)),
            None => Ok(None),
        }
    };
    let load_obj = |f: &super::platform::FileContent| -> Result<Scene> {
        let as_file_error = |e: crate::Error| crate::Error::File {
            file: f.name.clone(),
            message: format!("{e:#}"),
        };
        let obj = String::from_utf8(f.bytes.to_vec()).map_err(|_| crate::Error::File {
            file: f.name.clone(),
            message: "not UTF-8 text".into(),
        })?;
        let mtl = mtl_for(&obj).map_err(as_file_error)?;
        crate::scene::obj::load_obj_str(&obj, mtl.as_deref(), &f.name)
    };
    // A scene file's OBJs open with it, not on their own as well.
    let with_scene_file = files.iter().any(|f| ext(&f.name) == "toml");
    let mut out = Vec::new();
    for f in files {
        let name = f.name.clone();
        let opened = match ext(&name).as_str() {
            "obj" if with_scene_file => continue,
            "obj" => load_obj(f).map(|s| Opened::Scene(name.clone(), s)),
            "glb" | "gltf" => crate::scene::gltf::load_gltf_bytes(&f.bytes, &name, None)
                .map(|s| Opened::Scene(name.clone(), s)),
            "toml" => text(f).and_then(|t| {
                let resolve = |rel: &str| {
                    let wanted = file_name(rel);
                    let obj = files
                        .iter()
                        .find(|g| ext(&g.name) == "obj" && file_name(&g.name) == wanted)
                        .ok_or_else(|| crate::Error::File {
                            file: rel.to_string(),
                            message: format!(
                                "{name} refers to it: drop it together with the scene file"
                            ),
                        })?;
                    load_obj(obj)
                };
                Ok(Opened::Scene(
                    name.clone(),
                    scene_file::load_scene_str(&t, &name, &resolve)?,
                ))
            }),
            "json" => text(f).and_then(|t| open_json(&t, &name)),
            // Decoded when the scene is lit with it (`MapCache::light`).
            "hdr" | "exr" => Ok(Opened::Environment(
                super::environment_panel::MapChoice::Content(name.clone(), f.bytes.clone()),
            )),
            // Taken by the scene that refers to them.
            "mtl" => continue,
            _ => Err(crate::Error::from(format!(
                "{name}: this file type opens from a path only (the desktop build); the \
                 browser opens .obj (with its .mtl), .glb, .gltf, .toml, .json, .hdr and .exr"
            ))),
        };
        out.push((name, opened));
    }
    out
}

/// Writes a debug dump.
pub fn save_dump(probe: &Probe, path: &Path) -> Result<()> {
    std::fs::write(path, serde_json::to_string_pretty(probe)?).in_file(path.display(), "")
}

/// Writes an image as PNG (tone-mapped with `exposure`), PFM or EXR by the extension.
pub(crate) fn save_image(img: &Image, path: &Path, exposure: f64) -> Result<()> {
    let rgb = img.to_rgb32();
    match path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("pfm") => {
            image_io::write_pfm(path, img.width, img.height, &rgb).in_file(path.display(), "")
        }
        Some("exr") => image_io::write_exr(path, img.width, img.height, &rgb),
        _ => image_io::write_png(path, img.width, img.height, &rgb, exposure),
    }
}

/// [`save_image`]'s PNG as bytes (a download in the browser).
pub(crate) fn png_bytes(img: &Image, exposure: f64) -> Result<Vec<u8>> {
    crate::raster::io::png_bytes(img.width, img.height, &img.to_rgb32(), exposure)
}

/// [`save_screenshot`]'s PNG as bytes (a download in the browser).
pub(crate) fn screenshot_png_bytes(img: &egui::ColorImage) -> Result<Vec<u8>> {
    let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    crate::raster::io::encode_png(
        &bytes,
        img.size[0] as u32,
        img.size[1] as u32,
        image::ExtendedColorType::Rgba8,
    )
}

/// Writes an RGBA screenshot as PNG.
pub(crate) fn save_screenshot(img: &egui::ColorImage, path: &Path) -> Result<()> {
    std::fs::write(path, screenshot_png_bytes(img)?).in_file(path.display(), "")
}

/// The `penumbra render` command that reproduces the current view headless.
pub(crate) fn cli_command(
    scene: &str,
    camera: &Camera,
    settings: &RenderSettings,
    exposure: f64,
) -> String {
    let v = |p: glam::DVec3| format!("{},{},{}", p.x, p.y, p.z);
    let mut s = format!(
        "penumbra render {scene} --eye {} --target {} --up {} --fov {} --size {}x{} --aa {} --method {}",
        v(camera.eye),
        v(camera.target),
        v(camera.up),
        camera.fov_deg,
        settings.width,
        settings.height,
        settings.aa,
        settings.method.name()
    );
    if settings.method.is_stochastic() {
        s += &format!(" --spp {} --seed {}", settings.spp, settings.seed);
    }
    if exposure != 0.0 {
        s += &format!(" --exposure {exposure}");
    }
    s += " --out out/workbench.png";
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::platform::FileContent;

    fn content(path: &str) -> FileContent {
        let name = Path::new(path)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into();
        FileContent {
            name,
            bytes: std::fs::read(path).unwrap().into(),
        }
    }

    fn scene_of(opened: &(String, Result<Opened>)) -> &Scene {
        match &opened.1 {
            Ok(Opened::Scene(_, s)) => s,
            Ok(_) => panic!("{}: not a scene", opened.0),
            Err(e) => panic!("{}: {e:#}", opened.0),
        }
    }

    /// What the browser opens by content is what the desktop opens from the same files by
    /// path: Blender's exports, an OBJ with its MTL and a TOML scene with its OBJ.
    #[test]
    fn files_opened_by_content_are_the_files_opened_by_path() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/blender");
        let same = |a: &Scene, b: &Scene| {
            assert_eq!(a.objects.len(), b.objects.len());
            for (x, y) in a.objects.iter().zip(&b.objects) {
                assert_eq!(x.name, y.name);
                assert_eq!(x.mesh.positions, y.mesh.positions, "{}", x.name);
                assert_eq!(x.mesh.faces, y.mesh.faces, "{}", x.name);
                assert_eq!(format!("{:?}", x.material), format!("{:?}", y.material));
                assert_eq!(format!("{:?}", x.flags), format!("{:?}", y.flags));
            }
            assert_eq!(format!("{:?}", a.camera), format!("{:?}", b.camera));
        };
        for stem in ["suzanne", "text"] {
            // OBJ + MTL dropped together (in either order).
            let (obj, mtl) = (format!("{dir}/{stem}.obj"), format!("{dir}/{stem}.mtl"));
            let opened = open_contents(&[content(&mtl), content(&obj)]);
            assert_eq!(opened.len(), 1, "the MTL opens nothing on its own");
            let by_path = load_scene(&obj).unwrap();
            same(scene_of(&opened[0]), &by_path);
            // The TOML scene with its OBJ and MTL.
            let toml = format!("{dir}/{stem}.toml");
            let opened = open_contents(&[content(&toml), content(&obj), content(&mtl)]);
            assert_eq!(opened.len(), 1, "the OBJ is the scene's, not opened again");
            same(scene_of(&opened[0]), &load_scene(&toml).unwrap());
            // glTF binary.
            let glb = format!("{dir}/{stem}.glb");
            let opened = open_contents(&[content(&glb)]);
            same(scene_of(&opened[0]), &load_scene(&glb).unwrap());
        }
    }

    #[test]
    fn bad_content_is_an_error_naming_the_file_and_line() {
        let file = |name: &str, text: &str| FileContent {
            name: name.into(),
            bytes: text.as_bytes().into(),
        };
        let opened = open_contents(&[file("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")]);
        let err = format!("{:#}", opened[0].1.as_ref().err().expect("an error"));
        assert!(err.contains("bad.obj:4"), "{err}");
        let opened = open_contents(&[file("scene.toml", "[[object]]\nobj = \"missing.obj\"\n")]);
        let err = format!("{:#}", opened[0].1.as_ref().err().expect("an error"));
        assert!(err.contains("missing.obj"), "{err}");
        let opened = open_contents(&[file("notes.txt", "hello")]);
        assert!(opened[0].1.is_err());
        let binary = FileContent {
            name: "binary.obj".into(),
            bytes: vec![0xff, 0xfe, 0x00].into(),
        };
        let err = format!(
            "{:#}",
            open_contents(&[binary])[0].1.as_ref().err().unwrap()
        );
        assert!(err.contains("binary.obj") && err.contains("UTF-8"), "{err}");
    }
}
