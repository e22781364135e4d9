//! A cone of directions with a height, apex at a shading point: what conical ray culling
//! (002 Eq. 4, `environment::cones`) builds and the stage recorder keeps.

use glam::DVec3;

/// A cone `C = (a, d, h, ψ)` of Eq. 4, with the apex at the shading point (not stored) and
/// `cos ψ` kept instead of ψ: the culling test is a dot product.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cone {
    /// Unit axis from the shading point toward the sphere's centre (or the normal when the
    /// point is inside the sphere).
    pub axis: DVec3,
    /// Height: the distance from the apex to the far side of the sphere (Eq. 4).
    pub height: f64,
    /// Half angle ψ.
    pub half_angle: f64,
    /// cos ψ (0 for the whole hemisphere).
    pub cos_half_angle: f64,
}

impl Cone {
    /// Whether this cone is the whole hemisphere (the point was inside a sphere).
    #[inline]
    pub(crate) fn is_hemisphere(&self) -> bool {
        self.half_angle >= std::f64::consts::FRAC_PI_2
    }

    /// Whether `dir` (unit) lies inside the cone: `arccos(ω·d) < ψ` (Alg. 2 line 7), written
    /// with the cosine. The boundary itself counts as inside.
    #[inline]
    pub(crate) fn contains(&self, dir: DVec3) -> bool {
        dir.dot(self.axis) >= self.cos_half_angle
    }
}
