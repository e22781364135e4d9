//! The environment light of paper 002 (Xu et al. 2022): an equirectangular map projected on
//! 3-band spherical harmonics, E = E_unshadowed − E_occluded (Eq. 3), conical ray culling, and
//! penumbra's own exact E_occluded over spherical polygons. See docs/environment.md.
//!
//! * [`map`]: [`EnvironmentMap`] (y up, equirectangular, rotation about +y, scale; `.hdr` and
//!   `.exr` files; a procedural default sky) and [`EnvironmentSampler`].
//! * [`sh`]: [`Sh9`] (projection, reconstruction, irradiance) and its quadratic form
//!   [`ShQuadratic`], in world or in a local shading frame.
//! * [`polygon_integral`]: [`PolygonMoments`] and [`cosine_weighted_integral`]: the SH radiance
//!   × cos integrated over a spherical polygon in closed form.
//! * [`light`]: [`EnvironmentLight`]: the map, its projection and its sampler together.
//! * [`cones`]: 002 Eq. 4, Alg. 1 (merging) and the culling test of Alg. 2.
//! * [`hemisphere_samples`]: the cosine-weighted Hammersley rays and per-pixel rotations.
//! * [`cross_bilateral`]: 002's 5×5 cross-bilateral filter of E_occluded.

pub mod cones;
pub mod cross_bilateral;
pub mod hemisphere_samples;
pub mod light;
pub mod map;
pub mod polygon_integral;
pub mod prt;
pub mod sh;

pub use cones::{BoundingSphere, Cone, construct_and_merge_cones, ray_extent};
pub use cross_bilateral::cross_bilateral_5x5;
pub use hemisphere_samples::{HemisphereSamples, pixel_rotation};
pub use light::EnvironmentLight;
pub use map::{EnvironmentMap, EnvironmentSampler, luminance};
pub use polygon_integral::{
    PolygonMoments, cosine_weighted_integral, cosine_weighted_integral_local,
};
pub use sh::{Quadratic, Sh9, ShQuadratic, sh_basis};

use std::path::{Path, PathBuf};

/// How E_occluded (and with it E) is computed; `penumbra render --env-method`.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum EnvMethod {
    /// Exact: the SH radiance × cos integrated over the region the dynamic objects hide
    /// (silhouettes, horizon clip, set difference; no rays, no noise).
    Analytic,
    /// 002 as published: Hammersley cosine rays inside the merged cones (direction and length
    /// culling, Alg. 1–2), 5×5 cross-bilateral filter on E_occluded.
    Rt,
    /// `rt` tracing every ray to infinity (the tables' "without culling"); the same E_occluded
    /// bit for bit.
    RtUnculled,
    /// Ray-traced ambient occlusion × E_static (E_unshadowed of Eq. 7 when nothing is static):
    /// the baseline 002 compares with.
    Rtao,
    /// E_static alone: no shadows of dynamic objects (Eq. 7, no shadows at all, when nothing
    /// is static).
    Unshadowed,
    /// Monte Carlo of the map itself (not its SH), importance-sampled, with shadow rays
    /// against every object: the independent oracle.
    Reference,
}

impl EnvMethod {
    pub const ALL: [EnvMethod; 6] = [
        EnvMethod::Analytic,
        EnvMethod::Rt,
        EnvMethod::RtUnculled,
        EnvMethod::Rtao,
        EnvMethod::Unshadowed,
        EnvMethod::Reference,
    ];

    pub fn name(self) -> &'static str {
        match self {
            EnvMethod::Analytic => "analytic",
            EnvMethod::Rt => "rt",
            EnvMethod::RtUnculled => "rt-unculled",
            EnvMethod::Rtao => "rtao",
            EnvMethod::Unshadowed => "unshadowed",
            EnvMethod::Reference => "reference",
        }
    }

    /// Whether the method draws rays (and so depends on `spp` and the seed).
    pub fn is_stochastic(self) -> bool {
        matches!(
            self,
            EnvMethod::Rt | EnvMethod::RtUnculled | EnvMethod::Rtao | EnvMethod::Reference
        )
    }
}

/// Where the environment's radiance comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    /// The embedded procedural sky (`sky`).
    Sky,
    /// The sky's 3-band SH projection, reconstructed as a map (`sky-sh`): band-limited, so the
    /// analytic method is exact on it and the reference converges to the same image.
    SkySh,
    /// An equirectangular `.hdr` or `.exr` file.
    File(PathBuf),
}

/// An environment as a scene file or the command line describes it (plain data: loading the
/// map is `EnvironmentLight::load`'s business).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentSpec {
    pub source: EnvironmentSource,
    /// Rotation about +y, degrees.
    pub rotate_deg: f64,
    /// Radiance scale.
    pub scale: f64,
    pub method: Option<EnvMethod>,
    pub spp: Option<u32>,
}

impl EnvironmentSpec {
    /// `map` is `sky`, `sky-sh` or a file path; rotation and scale must be finite (scale ≥ 0).
    pub fn new(
        map: &str,
        rotate_deg: Option<f64>,
        scale: Option<f64>,
        method: Option<EnvMethod>,
        spp: Option<u32>,
    ) -> Result<Self, String> {
        let source = match map {
            "sky" => EnvironmentSource::Sky,
            "sky-sh" => EnvironmentSource::SkySh,
            "" => return Err("environment map must be 'sky', 'sky-sh' or a file".into()),
            path => EnvironmentSource::File(PathBuf::from(path)),
        };
        let rotate_deg = rotate_deg.unwrap_or(0.0);
        let scale = scale.unwrap_or(1.0);
        if !rotate_deg.is_finite() {
            return Err("environment rotate must be a finite angle in degrees".into());
        }
        if !(scale.is_finite() && scale >= 0.0) {
            return Err("environment scale must be finite and non-negative".into());
        }
        if spp == Some(0) {
            return Err("environment spp must be positive".into());
        }
        Ok(EnvironmentSpec {
            source,
            rotate_deg,
            scale,
            method,
            spp,
        })
    }

    /// Makes a relative map path relative to `dir` (the scene file's directory).
    pub fn resolve_relative_to(&mut self, dir: &Path) {
        if let EnvironmentSource::File(p) = &mut self.source
            && p.is_relative()
        {
            *p = dir.join(&*p);
        }
    }
}
