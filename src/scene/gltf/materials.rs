//! glTF metallic-roughness materials as penumbra materials (docs/scenes.md, "glTF 2.0").
//!
//! The glTF reference BRDF (specification, Appendix B) is a Lambertian lobe of colour
//! `c_diff = baseColor * (1 - metallic)` plus a GGX lobe with Schlick's Fresnel from
//! `F0 = lerp(0.04, baseColor, metallic)` and alpha = roughness^2: the model penumbra's
//! materials already have (`Kd`, `Ks` = F0, `alpha`), so the factors map one to one.

use super::super::Material;
use super::super::obj::alpha_from_mtl;
use glam::DVec3;
use gltf::json;

/// F0 of glTF's dielectrics (index of refraction 1.5).
pub const DIELECTRIC_F0: f64 = 0.04;

/// Material `index` of the document (the default material for `None`); `notes` collects what
/// was clamped or ignored, once per material.
pub(super) fn material(
    root: &json::Root,
    index: Option<usize>,
    notes: &mut Vec<String>,
) -> Material {
    let Some((i, m)) = index.and_then(|i| root.materials.get(i).map(|m| (i, m))) else {
        return Material::default();
    };
    let name = m
        .name
        .clone()
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| format!("material{i}"));
    let mut clamped = Vec::new();
    let mut unit = |what: &str, v: f32| -> f64 {
        let v = v as f64;
        if v.is_finite() && (0.0..=1.0).contains(&v) {
            v
        } else {
            clamped.push(what.to_owned());
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            }
        }
    };
    let pbr = &m.pbr_metallic_roughness;
    let [r, g, b, _] = pbr.base_color_factor.0;
    let base = DVec3::new(
        unit("baseColorFactor", r),
        unit("baseColorFactor", g),
        unit("baseColorFactor", b),
    );
    let metallic = unit("metallicFactor", pbr.metallic_factor.0);
    let roughness = unit("roughnessFactor", pbr.roughness_factor.0);
    let [er, eg, eb] = m.emissive_factor.0;
    let emissive = DVec3::new(
        unit("emissiveFactor", er),
        unit("emissiveFactor", eg),
        unit("emissiveFactor", eb),
    );
    let strength = m
        .extensions
        .as_ref()
        .and_then(|e| e.emissive_strength.as_ref())
        .map_or(1.0, |s| s.emissive_strength.0 as f64);
    let strength = if strength.is_finite() && strength >= 0.0 {
        strength
    } else {
        clamped.push("KHR_materials_emissive_strength".to_owned());
        0.0
    };
    clamped.dedup();
    if !clamped.is_empty() {
        notes.push(format!(
            "materials[{i}] '{name}': {} outside its range clamped",
            clamped.join(", ")
        ));
    }
    Material {
        name,
        kd: base * (1.0 - metallic),
        ks: DVec3::splat(DIELECTRIC_F0).lerp(base, metallic),
        alpha: alpha_from_mtl(Some(roughness), None),
        ke: emissive * strength,
    }
}

/// Whether any material uses a texture (they are ignored: only the factors are read).
pub(super) fn uses_textures(root: &json::Root) -> bool {
    !root.textures.is_empty()
        || root.materials.iter().any(|m| {
            m.pbr_metallic_roughness.base_color_texture.is_some()
                || m.pbr_metallic_roughness
                    .metallic_roughness_texture
                    .is_some()
                || m.normal_texture.is_some()
                || m.occlusion_texture.is_some()
                || m.emissive_texture.is_some()
        })
}
