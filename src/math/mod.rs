//! Small math utilities shared by every module: the shading frame, a deterministic RNG and
//! Newell's area vector of a polygon.

mod frame;
mod polygon;
mod rng;

pub use frame::Frame;
pub use polygon::polygon_area_vector;
pub use rng::Pcg32;
