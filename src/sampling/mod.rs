//! Sampling routines for the stochastic estimators and the oracles.

pub mod area_light;
pub(crate) mod spherical_triangle;

pub use spherical_triangle::SphericalTriangle;
