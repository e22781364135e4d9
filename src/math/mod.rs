//! Small math utilities shared by every module: the shading frame, a deterministic RNG,
//! Newell's area vector of a polygon and the angle between unit vectors.

mod frame;
mod polygon;
mod rng;

pub use frame::Frame;
pub use polygon::polygon_area_vector;
pub use rng::Pcg32;

use glam::DVec3;

/// The angle between unit vectors `a` and `b`, accurate for small angles too: `acos(a · b)`
/// cannot tell angles below 1.5e-8 apart (the cosine's resolution at 1).
#[inline]
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}
