//! The published GGX LTC table of Heitz, Dupuy, Hill and Neubelt (2016), as distributed in
//! three.js (`examples/jsm/lights/RectAreaLightTexturesLib.js`, arrays `LTC_MAT_1` and
//! `LTC_MAT_2`, 64 × 64 RGBA texels each), converted to our table format
//! (docs/ltc.md, "The published table"). The converted table is committed as
//! `assets/ltc/heitz2016_ggx_ltc_64.bin` ([`published`]); [`from_three_js`] is the
//! converter (`penumbra ltc-import-three FILE.js --out PATH`).
//!
//! Texel layout (three.js `LTC_Uv`: `uv = (roughness, √(1 − cosθv)) · 63/64 + 0.5/64`):
//! texel `(x, y)` at index `4 (64 y + x)` holds roughness `x/63` (`α = roughness²`) and
//! `√(1 − cosθv) = y/63` — our row `i = x`, column `j = y`. The shader's
//! `mInv = mat3(vec3(t1.x, 0, t1.y), vec3(0, 1, 0), vec3(t1.z, 0, t1.w))` (GLSL columns) is
//! `m00 = t1.x, m20 = t1.y, m02 = t1.z, m22 = t1.w` with `m11 = 1`, applied to directions in
//! the frame `(T1, T2, N)` with `T1` toward the view: our frame. `LTC_MAT_2`: the shader's
//! specular factor `F0 t2.x + (1 − F0) t2.y` is our `specular_scale`, so `norm = t2.x`,
//! `fresnel = t2.y`.

use super::table::{ALPHA_MIN, COS_THETA_MIN, LtcEntry, LtcTable};
use crate::ImportError;
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Side of the published table.
pub(crate) const PUBLISHED_SIZE: usize = 64;

/// The converted published table (assets/ltc/heitz2016_ggx_ltc_64.bin), parsed once.
pub fn published() -> &'static LtcTable {
    static BYTES: &[u8] = include_bytes!("../../assets/ltc/heitz2016_ggx_ltc_64.bin");
    static TABLE: OnceLock<LtcTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        LtcTable::from_bytes(BYTES).expect("the published LTC table asset is a valid table file")
    })
}

/// The numbers of the JavaScript array literal `const NAME = [ … ];` in `js` (numbers may
/// be written `- 4.5e-07`, with a space after the sign).
fn js_array(js: &str, name: &'static str) -> Result<Vec<f64>, ImportError> {
    let start = js
        .find(&format!("{name} = ["))
        .ok_or(ImportError::Missing(name))?;
    let body = &js[start..];
    let open = body.find('[').ok_or(ImportError::Missing(name))? + 1;
    let close = body[open..].find(']').ok_or(ImportError::Missing(name))? + open;
    body[open..close]
        .split(',')
        .map(|t| {
            let compact: String = t.chars().filter(|c| !c.is_whitespace()).collect();
            compact.parse::<f64>().map_err(|_| ImportError::Number {
                name,
                text: t.trim().to_string(),
            })
        })
        .collect()
}

/// One texel pair as our entry (see the module doc).
pub(crate) fn entry_from_texels(t1: [f64; 4], t2: [f64; 4]) -> LtcEntry {
    LtcEntry {
        m_inv: DMat3::from_cols(
            DVec3::new(t1[0], 0.0, t1[1]),
            DVec3::Y,
            DVec3::new(t1[2], 0.0, t1[3]),
        ),
        norm: t2[0],
        fresnel: t2[1],
        scale: 1.0,
        cosine: 0.0,
    }
}

/// Convert three.js's `RectAreaLightTexturesLib.js` (or the older
/// `RectAreaLightUniformsLib.js`) text into a 64 × 64 table on our grid (`alpha_min`,
/// `cos_theta_min` as ours: row 0 and the last column were fitted at α = 0 and cosθv = 0 by
/// Heitz et al.; on our grid they only weight the interpolation toward those nodes).
/// Every `M⁻¹` must have a positive determinant (all do).
pub fn from_three_js(js: &str) -> crate::Result<LtcTable> {
    let n = PUBLISHED_SIZE;
    let m1 = js_array(js, "LTC_MAT_1")?;
    let m2 = js_array(js, "LTC_MAT_2")?;
    for (name, a) in [("LTC_MAT_1", &m1), ("LTC_MAT_2", &m2)] {
        if a.len() != 4 * n * n {
            return Err(ImportError::Length {
                name,
                got: a.len(),
                expected: 4 * n * n,
            }
            .into());
        }
    }
    let texel = |a: &[f64], x: usize, y: usize| -> [f64; 4] {
        let k = 4 * (y * n + x);
        [a[k], a[k + 1], a[k + 2], a[k + 3]]
    };
    let mut entries = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            // Row i = roughness = texel x, column j = view = texel y.
            let e = entry_from_texels(texel(&m1, i, j), texel(&m2, i, j));
            let det = e.m_inv.determinant();
            if det.is_nan() || det <= 0.0 {
                return Err(ImportError::Determinant { x: i, y: j, det }.into());
            }
            entries.push(e);
        }
    }
    Ok(LtcTable::from_entries(
        n,
        ALPHA_MIN,
        COS_THETA_MIN,
        &entries,
    ))
}
