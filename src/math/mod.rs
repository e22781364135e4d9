//! Small math utilities shared by every module: the shading frame and a deterministic RNG.

mod frame;
mod rng;

pub use frame::Frame;
pub use glam::{DMat3, DVec2, DVec3};
pub use rng::Pcg32;
