//! The environment light of paper 002 (Xu et al. 2022): an equirectangular map projected on
//! 3-band spherical harmonics, E = E_unshadowed − E_occluded (Eq. 3), conical ray culling, and
//! penumbra's own exact E_occluded over spherical polygons. See docs/environment.md.
//!
//! * `map`: [`EnvironmentMap`] (y up, equirectangular, rotation about +y, scale; `.hdr` and
//!   `.exr` files; a procedural default sky) and [`EnvironmentSampler`].
//! * `sh`: [`Sh9`] (projection, reconstruction, irradiance) and its quadratic form
//!   [`ShQuadratic`], in world or in a local shading frame.
//! * `polygon_integral`: [`PolygonMoments`] and [`cosine_weighted_integral`]: the SH radiance
//!   × cos integrated over a spherical polygon in closed form.
//! * `light`: [`EnvironmentLight`]: the map, its projection and its sampler together.
//! * `cones`: 002 Eq. 4, Alg. 1 (merging) and the culling test of Alg. 2.
//! * `hemisphere_samples`: the cosine-weighted Hammersley rays and per-pixel rotations.
//! * `cross_bilateral`: 002's 5×5 cross-bilateral filter of E_occluded.

pub(crate) mod cones;
pub(crate) mod cross_bilateral;
pub(crate) mod hemisphere_samples;
pub(crate) mod light;
pub(crate) mod map;
pub(crate) mod polygon_integral;
pub mod prt;
pub(crate) mod sh;

pub(crate) use cones::Cone;
pub use cones::{BoundingSphere, construct_and_merge_cones, ray_extent};
pub use cross_bilateral::cross_bilateral_5x5;
pub use hemisphere_samples::{HemisphereSamples, pixel_rotation};
pub use light::EnvironmentLight;
pub(crate) use map::luminance;
pub use map::{EnvironmentMap, EnvironmentSampler};
pub use polygon_integral::{
    PolygonMoments, cosine_weighted_integral, cosine_weighted_integral_local,
};
pub use sh::{Quadratic, Sh9, ShQuadratic, sh_basis};

// What a scene file or the command line says of the environment is plain data of the scene
// (`scene::environment_spec`); loading the map is this module's business.
pub(crate) use crate::scene::environment_spec::{EnvMethod, EnvironmentSource, EnvironmentSpec};
