//! `penumbra edit`: move one object rigidly and save the scene.

use super::render::load_scene;
use anyhow::{Result, bail};
use glam::DVec3;
use std::path::Path;

/// `penumbra edit`: one rigid edit of one object, then the scene saved.
pub fn edit(
    name: &str,
    object: &str,
    translate: Option<DVec3>,
    rotate_y: Option<f64>,
    pivot: Option<DVec3>,
    out: &Path,
) -> Result<()> {
    use penumbra::scene::edit::move_object;
    if out
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("toml"))
    {
        bail!(
            "--out must name a .toml scene file, got '{}'",
            out.display()
        );
    }
    let mut scene = load_scene(name)?;
    let (index, pivot) = move_object(
        &mut scene,
        object,
        translate.unwrap_or(DVec3::ZERO),
        rotate_y.unwrap_or(0.0),
        pivot,
    )
    .map_err(anyhow::Error::msg)?;
    let saved = penumbra::scene::save::save_scene(&scene, scene.camera.as_ref(), out)
        .map_err(anyhow::Error::msg)?;
    for (old, new) in &saved.renamed {
        eprintln!("note: '{old}' is written as '{new}' (names must be unique)");
    }
    say!(
        "moved object {index} '{}' (rotated {}° about +y through {}, then translated by {}); wrote {}, {}, {}",
        scene.objects[index].name,
        rotate_y.unwrap_or(0.0),
        fmt_vec(pivot),
        fmt_vec(translate.unwrap_or(DVec3::ZERO)),
        saved.toml.display(),
        saved.obj.display(),
        saved.mtl.display()
    );
    Ok(())
}

pub(crate) fn fmt_vec(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}
