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
//! # What a reader meets first
//!
//! * [`scene`]: a scene from a file (penumbra's TOML, OBJ/MTL, glTF) or by name, its camera.
//! * [`render`]: a render as a user asks for it ([`render::request::RenderRequest`], with its
//!   defaults), the renderers ([`render::RenderMethod`]) and their images.
//! * [`raster`]: images in linear radiance and their PFM/EXR/PNG files.
//! * [`shading`]: one shading point, light by light (000 Alg. 1), and the recording a
//!   [`shading::Recorder`] makes of it: what the debugger shows.
//! * [`inspect`]: one pixel under the microscope, the recorded stages and numbers (the debug
//!   dump).
//! * [`views`] and [`figure`]: the debugger's views as figures, plain data drawn as PNG, SVG or
//!   PDF, or by the workbench.
//! * `app` (feature `gui`): the egui workbench.
//! * [`Error`], one error type, and [`Choice`], the options a user picks by name.
//!
//! # The stages and the tools
//!
//! The pipeline's stages and the tools built on them are public, so that the command line,
//! Python, the benchmark, the stress test and the integration tests (`tests/`) call the same
//! functions the renderer does, but hidden from these pages: `geometry` (polyhedra, contours
//! and silhouettes, spherical polygons, horizon clipping, the planar projection and the set
//! difference), `ltc` (GGX, the LTC table, the edge integral), `accel` (rays, the BVH),
//! `sampling` and `stochastic` (003's estimators), `environment` (002), `denoise` (003's ratio
//! denoiser), `reference` (the ray-cast oracles), `math`, and the tools `bench` (the report of
//! `penumbra bench`) and `stress` (`penumbra stress`). docs/architecture.md maps every module,
//! and one page per algorithm maps its equations to functions.

// A public type is nameable: it has a public path (one, as the modules are laid out).
#![warn(unnameable_types)]

pub use choice::Choice;
pub use error::{EditError, Error, ImportError, InFile, Result, TableFormatError};

#[doc(hidden)]
pub mod accel;
#[cfg(feature = "gui")]
pub mod app;
#[doc(hidden)]
pub mod bench;
mod choice;
#[doc(hidden)]
pub mod denoise;
#[doc(hidden)]
pub mod environment;
mod error;
pub mod figure;
#[doc(hidden)]
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod inspect;
#[doc(hidden)]
pub mod ltc;
#[doc(hidden)]
pub mod math;
pub mod raster;
#[doc(hidden)]
pub mod reference;
pub mod render;
#[doc(hidden)]
pub mod sampling;
pub mod scene;
pub mod shading;
#[doc(hidden)]
pub mod stochastic;
#[doc(hidden)]
pub mod stress;
pub mod views;
