//! The stochastic competitors of the analytic method (001 Sect. 3.6, 6; 003 Sect. 3): solid-
//! angle sampling of triangulated silhouettes, MIS with BRDF sampling, and the estimators built
//! from S_N, U_N and the analytic U.
//!
//! * `light_set`: the lights at one shading point as spherical triangles (the silhouette
//!   stages of the analytic path, then a fan).
//! * `estimator`: the sums S_N and U_N from the same samples (003 Eq. 21, 22).
//! * `estimators`: full-stochastic, control variate, ratio and grayscale ratio (Eq. 10, 11,
//!   15, Sect. 3.4).
//! * `area`: area sampling, the baseline.

pub(crate) mod area;
pub(crate) mod estimator;
pub(crate) mod estimators;
pub(crate) mod light_set;

pub use area::AreaLights;
pub use estimator::{EstimatorScratch, LightSampling, SampleSums, SampledScene, direct_samples};
pub use estimators::{Estimator, combine};
pub use light_set::{LightRun, LightSet, LightShape, light_shape};
