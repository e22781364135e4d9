//! Shading with Linearly Transformed Cosines (Heitz, Dupuy, Hill, Neubelt 2016; 001 Sect. 3.4,
//! 000 Sect. 3): the GGX BRDF, the edge integral of Baum et al. 1989, the fitted LTC table
//! and the fitter. Equations, table layout and measured accuracy: docs/ltc.md.
//!
//! Specular radiance from a polygon `P` (local frame, `z` = normal, `v` in the xz-plane):
//! `L · E(clip(M⁻¹P)) · (F0 (norm − fresnel) + fresnel)` with
//! `entry = LtcTable::embedded().lookup(cosθv, α)`, `M⁻¹P` = `entry.transform` of each
//! vertex and `E` = [`form_factor`].

pub(crate) mod edge_integral;
pub mod error_map;
pub mod fit;
pub mod ggx;
pub mod nelder_mead;
pub mod polygon_error;
pub mod published;
pub(crate) mod table;

pub use edge_integral::{edge_integral, form_factor, form_factor_terms};
pub use table::{ALPHA_MIN, COS_THETA_MIN, LTC_TABLE_SIZE, LtcEntry, LtcTable, MAGIC};
