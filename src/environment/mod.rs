//! The environment light of Xu et al. 2022 (paper 002), pure math: the equirectangular map
//! and its sampling, 3-band spherical harmonics (Eq. 7, 8) and the closed-form
//! cosine-weighted integral of an SH radiance over a spherical polygon, which gives the
//! occluded irradiance of Eq. 3 exactly for polygonal occluders.
//!
//! * [`map`]: [`EnvironmentMap`] (y up, equirectangular, rotation about +y, scale; `.hdr` and
//!   `.exr` files; a procedural default sky) and [`EnvironmentSampler`].
//! * [`sh`]: [`Sh9`] (projection, reconstruction, irradiance) and its quadratic form
//!   [`ShQuadratic`], in world or in a local shading frame.
//! * [`polygon_integral`]: [`PolygonMoments`] and [`cosine_weighted_integral`].
//!
//! Geometry is f64 throughout; the per-point functions do not allocate.

pub mod map;
pub mod polygon_integral;
pub mod sh;

pub use map::{EnvironmentMap, EnvironmentSampler, luminance};
pub use polygon_integral::{
    PolygonMoments, cosine_weighted_integral, cosine_weighted_integral_local,
};
pub use sh::{Quadratic, Sh9, ShQuadratic, sh_basis};
