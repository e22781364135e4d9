//! An environment light ready to shade with: the map (rotated and scaled), its 3-band SH
//! projection, and its importance sampler. What every method reads about the environment
//! goes through here, so the map convention, the rotation and the scale live in one place.

use super::map::{EnvironmentMap, EnvironmentSampler};
use super::polygon_integral::{PolygonMoments, cosine_weighted_integral_local};
use super::sh::Sh9;
use super::{EnvironmentSource, EnvironmentSpec};
use crate::geometry::SphericalPolygon;
use crate::math::Frame;
use glam::DVec3;

/// Size of the embedded sky map (equirectangular, 2:1).
pub(crate) const SKY_WIDTH: usize = 512;
pub(crate) const SKY_HEIGHT: usize = 256;

pub struct EnvironmentLight {
    /// Where it came from (shown to the user, written to reports).
    pub label: String,
    pub map: EnvironmentMap,
    /// The projection of `map` (rotation and scale included) on bands 0–2.
    pub sh: Sh9,
    pub sampler: EnvironmentSampler,
}

impl EnvironmentLight {
    /// Loads (or builds) the map `spec` names, with its rotation and scale, and projects it.
    pub fn load(spec: &EnvironmentSpec) -> crate::Result<Self> {
        let (map, label) = Self::load_map(&spec.source)?;
        Ok(Self::from_map(
            map.with_rotation(spec.rotate_deg).with_scale(spec.scale),
            label,
        ))
    }

    /// The map `source` names, unrotated and unscaled, with its label (the workbench keeps it
    /// to rotate and scale it again without reading the file).
    pub(crate) fn load_map(source: &EnvironmentSource) -> crate::Result<(EnvironmentMap, String)> {
        let map = match source {
            EnvironmentSource::Sky => EnvironmentMap::sky(SKY_WIDTH, SKY_HEIGHT),
            EnvironmentSource::SkySh => {
                let sky = EnvironmentMap::sky(SKY_WIDTH, SKY_HEIGHT);
                EnvironmentMap::from_sh(&Sh9::project(&sky), SKY_WIDTH, SKY_HEIGHT)
            }
            EnvironmentSource::File(p) => EnvironmentMap::load(p)?,
        };
        Ok((map, source.name()))
    }

    /// The light of a map whose rotation and scale are already set.
    pub fn from_map(map: EnvironmentMap, label: String) -> Self {
        let sh = Sh9::project(&map);
        let sampler = EnvironmentSampler::new(&map);
        EnvironmentLight {
            label,
            map,
            sh,
            sampler,
        }
    }

    /// The map's radiance toward `dir` (what a camera ray that misses everything sees, and
    /// what the reference integrates).
    #[inline]
    pub fn radiance(&self, dir: DVec3) -> DVec3 {
        self.map.radiance(dir)
    }

    /// The SH reconstruction of the radiance toward `dir` (002 Eq. 8).
    #[inline]
    pub fn sh_radiance(&self, dir: DVec3) -> DVec3 {
        self.sh.eval(dir)
    }

    /// E_unshadowed(n) (002 Eq. 7, Ramamoorthi–Hanrahan).
    #[inline]
    pub fn irradiance(&self, n: DVec3) -> DVec3 {
        self.sh.irradiance(n)
    }

    /// ∫_P L_SH(ω) cos θ dω over a spherical polygon `poly` given in `frame` (z = normal): the
    /// closed form of docs/environment.md.
    pub fn integrate(&self, frame: &Frame, poly: &SphericalPolygon) -> DVec3 {
        if poly.is_empty() {
            return DVec3::ZERO;
        }
        let q = self.sh.local_quadratic(frame.world_to_local());
        let m = PolygonMoments::of_loops(poly.loops(), DVec3::Z);
        cosine_weighted_integral_local(&q, &m)
    }

    /// A direction drawn from the map's importance sampler: (direction, radiance, pdf per
    /// steradian).
    #[inline]
    pub fn sample(&self, u1: f64, u2: f64) -> (DVec3, DVec3, f64) {
        self.sampler.sample(u1, u2)
    }
}
