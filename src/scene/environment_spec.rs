//! The environment as a scene file or the command line describes it: which map, turned and
//! scaled how, and which method computes its shadows. Plain data, so that a scene can say it
//! without knowing how a map is loaded or integrated (`environment::EnvironmentLight::load`).

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
