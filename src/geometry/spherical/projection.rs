//! Projection of spherical polygons to a plane and back (000 Sect. 3.2).
//!
//! 000 projects with a look-at camera and a perspective division (the gnomonic projection), which
//! sends a vertex on the horizon to infinity: the public implementation nudges such vertices by
//! 1e-3 to survive. penumbra keeps the projected points in **homogeneous coordinates**
//! (x, y, w) instead of dividing by w. Great-circle arcs map to straight segments exactly as in
//! the gnomonic plane, every planar predicate becomes a 3×3 determinant (see [`orient`]) that
//! stays exact in the limit w → 0, and a vertex on the horizon is simply a point at infinity of
//! the oriented projective plane (Stolfi 1991). Nothing is nudged.
//!
//! [`orient`]: crate::geometry::orient

use crate::geometry::{PolygonLoops, SphericalPolygon};
use crate::math::Frame;
use glam::DVec3;
use std::ops::{Deref, DerefMut};

/// A polygon of the projection plane, vertices in homogeneous coordinates (x, y, w) with
/// w ≥ 0 (horizon-clipped input). Orientation is inherited from [`SphericalPolygon`]: filled
/// loops are counter-clockwise in the plane.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanarPolygon(pub PolygonLoops);

impl Deref for PlanarPolygon {
    type Target = PolygonLoops;
    fn deref(&self) -> &PolygonLoops {
        &self.0
    }
}

impl DerefMut for PlanarPolygon {
    fn deref_mut(&mut self) -> &mut PolygonLoops {
        &mut self.0
    }
}

impl PlanarPolygon {
    pub fn new() -> Self {
        Self::default()
    }
}

/// The look-at camera of 000 Sect. 3.2: the plane w = 1 of a frame whose w axis is the look-at
/// direction `p`. Alg. 1 uses p = +z (the normal), which makes every horizon-clipped polygon lie
/// in the closed half-space w ≥ 0.
#[derive(Clone, Copy, Debug)]
pub struct ProjectionPlane {
    frame: Frame,
}

impl ProjectionPlane {
    /// The plane of Alg. 1 line 2: look-at p = (0, 0, 1), so projection keeps the coordinates.
    pub const NORMAL: ProjectionPlane = ProjectionPlane {
        frame: Frame {
            x: DVec3::X,
            y: DVec3::Y,
            z: DVec3::Z,
        },
    };

    /// A plane looking along the unit direction `p`.
    #[cfg(test)]
    pub(crate) fn looking_along(p: DVec3) -> Self {
        ProjectionPlane {
            frame: Frame::from_z(p),
        }
    }

    /// Homogeneous coordinates of the direction `v`.
    #[inline]
    pub(crate) fn project_point(&self, v: DVec3) -> DVec3 {
        self.frame.to_local(v)
    }

    /// The unit direction of the homogeneous point `h` (the inverse camera matrix, then a
    /// normalisation).
    #[inline]
    pub fn reproject_point(&self, h: DVec3) -> DVec3 {
        self.frame.to_world(h).normalize()
    }

    /// Whether this is [`ProjectionPlane::NORMAL`], whose frame is the identity: projecting
    /// keeps the coordinates and reprojecting only normalises.
    #[inline]
    fn is_normal(&self) -> bool {
        self.frame.x == DVec3::X && self.frame.y == DVec3::Y && self.frame.z == DVec3::Z
    }

    /// `project` of Alg. 1 (lines 6 and 11).
    pub fn project(&self, sphere: &SphericalPolygon, out: &mut PlanarPolygon) {
        out.copy_from(sphere);
        if !self.is_normal() {
            out.map_vertices(|v| self.project_point(v));
        }
    }

    /// `reproject` of Alg. 1 (line 13).
    pub fn reproject(&self, plane: &PlanarPolygon, out: &mut SphericalPolygon) {
        out.copy_from(plane);
        if self.is_normal() {
            out.map_vertices(DVec3::normalize);
        } else {
            out.map_vertices(|h| self.reproject_point(h));
        }
    }

    /// Euclidean plane coordinates of a homogeneous point (for display); `None` at infinity.
    #[cfg(test)]
    pub(crate) fn to_euclidean(h: DVec3) -> Option<glam::DVec2> {
        (h.z > 0.0).then(|| glam::DVec2::new(h.x / h.z, h.y / h.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    #[test]
    fn projection_round_trips_and_keeps_orientation() {
        let mut rng = Pcg32::new(5, 5);
        for _ in 0..1000 {
            let plane = ProjectionPlane::looking_along(rng.unit_vector());
            let (a, b, c) = (rng.unit_vector(), rng.unit_vector(), rng.unit_vector());
            let mut s = SphericalPolygon::new();
            s.push_loop([a, b, c]);
            let mut p = PlanarPolygon::new();
            plane.project(&s, &mut p);
            let mut back = SphericalPolygon::new();
            plane.reproject(&p, &mut back);
            for (u, v) in s.vertices().iter().zip(back.vertices()) {
                assert!((*u - *v).length() < 1e-14);
            }
            // A rotation keeps determinants.
            let pv = p.loop_at(0);
            assert!(
                (crate::geometry::orient(pv[0], pv[1], pv[2]) - crate::geometry::orient(a, b, c))
                    .abs()
                    < 1e-14
            );
        }
    }

    #[test]
    fn horizon_points_are_points_at_infinity() {
        let h = ProjectionPlane::NORMAL.project_point(DVec3::X);
        assert_eq!(h, DVec3::X);
        assert!(ProjectionPlane::to_euclidean(h).is_none());
        let e = ProjectionPlane::to_euclidean(DVec3::new(1.0, 2.0, 2.0)).unwrap();
        assert_eq!(e, glam::DVec2::new(0.5, 1.0));
    }
}
