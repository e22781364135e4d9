//! The environment as a scene file or the command line describes it: which map, turned and
//! scaled how, and which method computes its shadows. Plain data, so that a scene can say it
//! without knowing how a map is loaded or integrated (`environment::EnvironmentLight::load`).

use std::path::{Path, PathBuf};

/// Rays per camera ray of the environment's ray methods when neither the command line nor the
/// scene says (002 Sect. 5 uses 128).
pub(crate) const DEFAULT_SPP: u32 = 128;

crate::choice! {
    /// How E_occluded (and with it E) is computed; `penumbra render --env-method`.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum EnvMethod {
        /// Exact: the SH radiance × cos integrated over the region the dynamic objects hide
        /// (silhouettes, horizon clip, set difference; no rays, no noise).
        Analytic = "analytic",
        /// 002 as published: Hammersley cosine rays inside the merged cones (direction and length
        /// culling, Alg. 1–2), 5×5 cross-bilateral filter on E_occluded.
        Rt = "rt",
        /// `rt` tracing every ray to infinity (the tables' "without culling"); the same E_occluded
        /// bit for bit.
        RtUnculled = "rt-unculled",
        /// Ray-traced ambient occlusion × E_static (E_unshadowed of Eq. 7 when nothing is static):
        /// the baseline 002 compares with.
        Rtao = "rtao",
        /// E_static alone: no shadows of dynamic objects (Eq. 7, no shadows at all, when nothing
        /// is static).
        Unshadowed = "unshadowed",
        /// Monte Carlo of the map itself (not its SH), importance-sampled, with shadow rays
        /// against every object: the independent oracle.
        Reference = "reference",
    }
}

impl EnvMethod {
    /// Whether 002's 5×5 cross-bilateral filter applies to the method's E_occluded: the
    /// ray-traced `rt` and `rt-unculled` (the one place that says so).
    pub(crate) fn is_filterable(self) -> bool {
        matches!(self, EnvMethod::Rt | EnvMethod::RtUnculled)
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

impl EnvironmentSource {
    /// The source a scene file's `map` or `--env` names: `sky`, `sky-sh`, or else a file path;
    /// `None` for an empty name. The one reading of those names.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "" => None,
            "sky" => Some(EnvironmentSource::Sky),
            "sky-sh" => Some(EnvironmentSource::SkySh),
            path => Some(EnvironmentSource::File(PathBuf::from(path))),
        }
    }

    /// The name [`EnvironmentSource::from_name`] reads back: `sky`, `sky-sh` or the path.
    pub fn name(&self) -> String {
        match self {
            EnvironmentSource::Sky => "sky".to_string(),
            EnvironmentSource::SkySh => "sky-sh".to_string(),
            EnvironmentSource::File(p) => p.display().to_string(),
        }
    }
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
    ) -> crate::Result<Self> {
        let source = EnvironmentSource::from_name(map)
            .ok_or("environment map must be 'sky', 'sky-sh' or a file")?;
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
    pub(crate) fn resolve_relative_to(&mut self, dir: &Path) {
        if let EnvironmentSource::File(p) = &mut self.source
            && p.is_relative()
        {
            *p = dir.join(&*p);
        }
    }
}

impl EnvironmentSpec {
    /// The method, [`EnvMethod::Analytic`] when none is given.
    pub(crate) fn method_or_default(&self) -> EnvMethod {
        self.method.unwrap_or(EnvMethod::Analytic)
    }

    /// The rays per camera ray, [`DEFAULT_SPP`] when none is given.
    pub(crate) fn spp_or_default(&self) -> u32 {
        self.spp.unwrap_or(DEFAULT_SPP)
    }

    /// The map as a scene file or `--env` names it ([`EnvironmentSource::name`]).
    pub(crate) fn map_name(&self) -> String {
        self.source.name()
    }
}

/// What the command line (or any caller) says of the environment over what the scene file
/// says: each `Some` replaces the scene's value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvironmentOverrides {
    /// `sky`, `sky-sh`, a file, or `none` (no environment, whatever the scene says).
    pub map: Option<String>,
    pub rotate_deg: Option<f64>,
    pub scale: Option<f64>,
    pub method: Option<EnvMethod>,
    pub spp: Option<u32>,
}

impl EnvironmentOverrides {
    /// The environment of a scene whose file says `base`, with these overrides: a new map
    /// keeps the scene's rotation, scale, method and rays unless they are overridden too; the
    /// merged values are checked as a scene file's are. Rotation, scale or method without any
    /// environment is an error (they would be silently ignored).
    pub fn apply(&self, base: Option<&EnvironmentSpec>) -> crate::Result<Option<EnvironmentSpec>> {
        let mut spec = match (self.map.as_deref(), base) {
            (Some("none"), _) => return Ok(None),
            (Some(map), base) => {
                let mut spec = EnvironmentSpec::new(map, None, None, None, None)?;
                if let Some(b) = base {
                    spec.rotate_deg = b.rotate_deg;
                    spec.scale = b.scale;
                    spec.method = b.method;
                    spec.spp = b.spp;
                }
                spec
            }
            (None, Some(base)) => base.clone(),
            (None, None) => {
                if self.method.is_some() || self.rotate_deg.is_some() || self.scale.is_some() {
                    return Err(
                        "--env-method, --env-rotate and --env-scale need an environment: \
                         pass --env sky|sky-sh|FILE"
                            .into(),
                    );
                }
                return Ok(None);
            }
        };
        if let Some(r) = self.rotate_deg {
            spec.rotate_deg = r;
        }
        if let Some(s) = self.scale {
            spec.scale = s;
        }
        spec.method = self.method.or(spec.method);
        spec.spp = self.spp.or(spec.spp);
        EnvironmentSpec::new(
            &spec.map_name(),
            Some(spec.rotate_deg),
            Some(spec.scale),
            spec.method,
            spec.spp,
        )
        .map(Some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_env() -> EnvironmentSpec {
        EnvironmentSpec::new("sky", Some(30.0), Some(2.0), Some(EnvMethod::Rt), Some(64)).unwrap()
    }

    #[test]
    fn overrides_merge_over_the_scene_files_environment() {
        let base = scene_env();
        // Nothing said: the scene's own.
        let none = EnvironmentOverrides::default();
        assert_eq!(none.apply(Some(&base)), Ok(Some(base.clone())));
        assert_eq!(none.apply(None), Ok(None));
        // `none` removes it.
        let off = EnvironmentOverrides {
            map: Some("none".into()),
            ..Default::default()
        };
        assert_eq!(off.apply(Some(&base)), Ok(None));
        // A new map keeps the scene's rotation, scale, method and rays.
        let sh = EnvironmentOverrides {
            map: Some("sky-sh".into()),
            ..Default::default()
        };
        let got = sh.apply(Some(&base)).unwrap().unwrap();
        assert_eq!(got.source, EnvironmentSource::SkySh);
        assert_eq!(
            (got.rotate_deg, got.scale, got.method, got.spp),
            (30.0, 2.0, Some(EnvMethod::Rt), Some(64))
        );
        // Each value said replaces the scene's.
        let all = EnvironmentOverrides {
            map: None,
            rotate_deg: Some(-10.0),
            scale: Some(0.5),
            method: Some(EnvMethod::Analytic),
            spp: Some(8),
        };
        let got = all.apply(Some(&base)).unwrap().unwrap();
        assert_eq!(
            (got.rotate_deg, got.scale, got.method, got.spp),
            (-10.0, 0.5, Some(EnvMethod::Analytic), Some(8))
        );
        assert_eq!(got.method_or_default(), EnvMethod::Analytic);
        assert_eq!(scene_env().spp_or_default(), 64);
        let bare = EnvironmentSpec::new("sky", None, None, None, None).unwrap();
        assert_eq!(
            (bare.method_or_default(), bare.spp_or_default()),
            (EnvMethod::Analytic, DEFAULT_SPP)
        );
    }

    #[test]
    fn overrides_are_checked_like_a_scene_file() {
        let orphan = EnvironmentOverrides {
            method: Some(EnvMethod::Rt),
            ..Default::default()
        };
        assert!(
            orphan
                .apply(None)
                .unwrap_err()
                .to_string()
                .contains("need an environment")
        );
        let negative = EnvironmentOverrides {
            scale: Some(-1.0),
            ..Default::default()
        };
        assert!(negative.apply(Some(&scene_env())).is_err());
        let zero_rays = EnvironmentOverrides {
            map: Some("sky".into()),
            spp: Some(0),
            ..Default::default()
        };
        assert!(zero_rays.apply(None).is_err());
    }
}
