//! What the workbench reads and writes: scenes, debug dumps, bench reports, images, and the
//! command line that reproduces the current render headless.

use crate::bench::BenchReport;
use crate::inspect::Probe;
use crate::render::{Image, RenderSettings, image_io};
use crate::scene::{Camera, Scene, scene_file};
use anyhow::{Context, Result};
use std::path::Path;

/// What a dropped or opened file is.
pub enum Opened {
    Scene(String, Scene),
    Dump(Box<Probe>),
    Bench(Box<BenchReport>),
    Reference(Image),
    /// An equirectangular environment map (.hdr, .exr) to light the scene with.
    Environment(std::path::PathBuf),
}

/// Loads a scene by embedded name or path (`scene_file::load_scene_by_name`).
pub fn load_scene(name: &str) -> Result<Scene> {
    Ok(scene_file::load_scene_by_name(name)?)
}

/// Opens a file by its content: a scene (.toml, .obj, .glb, .gltf), a debug dump or bench report (.json),
/// or a reference image (.pfm).
pub fn open(path: &Path) -> Result<Opened> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let name = path.display().to_string();
    match ext.as_str() {
        "toml" | "obj" | "glb" | "gltf" => Ok(Opened::Scene(name.clone(), load_scene(&name)?)),
        "hdr" | "exr" => Ok(Opened::Environment(path.to_path_buf())),
        "pfm" => Ok(Opened::Reference(
            image_io::read_pfm_image(path).with_context(|| name.clone())?,
        )),
        "json" => {
            let text = std::fs::read_to_string(path).with_context(|| name.clone())?;
            let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
                anyhow::anyhow!("{name}:{}:{}: not JSON: {e}", e.line(), e.column())
            })?;
            if value.get("recording").is_some() {
                let p = Probe::from_json(&text, &name).map_err(anyhow::Error::msg)?;
                Ok(Opened::Dump(Box::new(p)))
            } else if value.get("equal_time").is_some() {
                let r: BenchReport = serde_json::from_value(value)
                    .with_context(|| format!("{name}: not a penumbra bench report"))?;
                Ok(Opened::Bench(Box::new(r)))
            } else {
                anyhow::bail!("{name}: neither a debug dump nor a bench report")
            }
        }
        _ => anyhow::bail!(
            "{name}: unknown file type (expected .toml, .obj, .glb, .gltf, .json, .pfm, .hdr or .exr)"
        ),
    }
}

/// Writes a debug dump.
pub fn save_dump(probe: &Probe, path: &Path) -> Result<()> {
    std::fs::write(path, serde_json::to_string_pretty(probe)?)
        .with_context(|| path.display().to_string())
}

/// Writes an image as PNG (tone-mapped with `exposure`), PFM or EXR by the extension.
pub fn save_image(img: &Image, path: &Path, exposure: f64) -> Result<()> {
    let rgb = img.to_rgb32();
    match path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("pfm") => image_io::write_pfm(path, img.width, img.height, &rgb)
            .with_context(|| path.display().to_string()),
        Some("exr") => image_io::write_exr(path, img.width, img.height, &rgb),
        _ => image_io::write_png(path, img.width, img.height, &rgb, exposure),
    }
}

/// Writes an RGBA screenshot as PNG.
pub fn save_screenshot(img: &egui::ColorImage, path: &Path) -> Result<()> {
    let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    image::save_buffer_with_format(
        path,
        &bytes,
        img.size[0] as u32,
        img.size[1] as u32,
        image::ExtendedColorType::Rgba8,
        image::ImageFormat::Png,
    )
    .with_context(|| path.display().to_string())
}

/// The `penumbra render` command that reproduces the current view headless.
pub fn cli_command(
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
