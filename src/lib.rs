//! penumbra: analytic shading and soft shadows from polyhedral area lights.
//!
//! The four papers it implements are cited by number throughout (`000 Alg. 1`, `001 Sect.
//! 4.3`):
//!
//! | number | paper |
//! |---|---|
//! | 000 | Aakash KT, P. Sakurikar, P. J. Narayanan: *Fast Analytic Soft Shadows from Area Lights*, EGSR 2021 |
//! | 001 | A bachelor's thesis on the silhouettes of polyhedral light sources for real-time shading: contour and silhouette, exact silhouettes of non-convex polyhedra, BSP trees of precomputed silhouettes, solid-angle sampling of triangulated silhouettes |
//! | 002 | Y. Xu et al.: *Real-Time Ray-Traced Soft Shadows of Environmental Lighting by Conical Ray Culling*, I3D 2022 |
//! | 003 | E. Heitz, S. Hill, M. McGuire: *Combining Analytic Direct Illumination and Stochastic Shadows*, I3D 2018 |
//!
//! The modules follow the pipeline of KT et al. 2021 (paper 000, Alg. 1):
//!
//! * [`app`]: the egui workbench (viewport, picked point, sphere view, stepping, plots, exports).
//! * [`scene`]: OBJ/MTL and scene files, procedural shapes, the camera.
//! * [`geometry`]: polyhedra, contour edges and silhouettes, spherical polygons,
//!   horizon clipping, the planar projection and the set difference.
//! * [`ltc`]: the GGX BRDF, Linearly Transformed Cosines and the edge integral.
//! * [`shading`]: one shading point, light by light (Alg. 1), with an optional recorder.
//! * [`accel`]: rays, triangles and the BVH for camera rays and the ray-cast oracle.
//! * [`render`]: images, tiles, output files.
//! * [`environment`]: the environment light of paper 002: equirectangular maps, 3-band SH
//!   (Eq. 7, 8), conical ray culling, and E_occluded computed exactly by the closed-form SH
//!   integral over spherical polygons.
//! * [`denoise`]: the ratio denoiser of paper 003 (Sect. 3.5, 4.1–4.2): `U × denoise[S_N] /
//!   denoise[U_N]` with a noise-driven joint-bilateral filter.
//! * [`inspect`]: one pixel under the microscope: the recorded stages and per-light numbers
//!   (the debug dump).
//! * [`views`]: the debugger's views as figures (plain data from a recording), for the
//!   command line's `penumbra figure`.
//! * [`reference`]: brute-force ray-cast estimates used as independent oracles.
//! * [`stochastic`]: solid-angle and BRDF sampling with MIS, and the estimators of 003.
//! * [`stress`]: random and adversarial shading configurations.
//! * [`bench`](mod@bench): the report of `penumbra bench`: rows of time and error, equal-time
//!   comparisons, scaling fits, PNG charts.

pub use choice::Choice;
pub use error::{Error, InFile, Result};

pub mod accel;
#[cfg(feature = "gui")]
pub mod app;
pub mod bench;
mod choice;
pub mod denoise;
pub mod environment;
mod error;
pub mod figure;
pub mod geometry;
pub mod inspect;
pub mod ltc;
pub mod math;
pub mod raster;
pub mod reference;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod shading;
pub mod stochastic;
pub mod stress;
pub mod views;
