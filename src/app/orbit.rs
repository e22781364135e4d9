//! Orbit / pan / zoom around a target point, converted to the renderer's `Camera`.

use crate::scene::Camera;
use glam::DVec3;

/// A camera on a sphere around `target`: yaw about +y, pitch above the horizontal plane.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrbitCamera {
    pub target: DVec3,
    pub distance: f64,
    /// Radians about +y, 0 looking down −z.
    pub yaw: f64,
    /// Radians, positive above the target.
    pub pitch: f64,
    pub fov_deg: f64,
    /// The camera's authored aspect (`Camera::aspect`), kept through orbiting.
    #[serde(default)]
    pub aspect: Option<f64>,
}

impl OrbitCamera {
    /// The orbit that reproduces `cam` (its up vector is taken as +y).
    pub(crate) fn from_camera(cam: &Camera) -> Self {
        let d = cam.eye - cam.target;
        let distance = d.length().max(1e-9);
        OrbitCamera {
            target: cam.target,
            distance,
            yaw: d.x.atan2(d.z),
            pitch: (d.y / distance).clamp(-1.0, 1.0).asin(),
            fov_deg: cam.fov_deg,
            aspect: cam.aspect,
        }
    }

    pub fn camera(&self) -> Camera {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let dir = DVec3::new(sy * cp, sp, cy * cp);
        Camera {
            eye: self.target + dir * self.distance,
            target: self.target,
            up: DVec3::Y,
            fov_deg: self.fov_deg,
            aspect: self.aspect,
        }
    }

    /// Rotates by a drag of (dx, dy) in points.
    pub(crate) fn orbit(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * 0.008;
        self.pitch = (self.pitch + dy * 0.008).clamp(-1.55, 1.55);
    }

    /// Moves the target in the image plane by a drag of (dx, dy) points in a view `height`
    /// points high.
    pub(crate) fn pan(&mut self, dx: f64, dy: f64, height: f64) {
        let cam = self.camera();
        let Ok(b) = cam.basis() else {
            return;
        };
        let per_point = 2.0 * self.distance * b.tan_half_fov / height.max(1.0);
        self.target += (-b.right * dx + b.up * dy) * per_point;
    }

    /// Zooms by `steps` (positive: closer).
    pub(crate) fn zoom(&mut self, steps: f64) {
        self.distance = (self.distance * (-0.1 * steps).exp()).max(1e-6);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_a_camera() {
        let cam = Camera {
            eye: DVec3::new(1.0, 2.2, 6.0),
            target: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        };
        let back = OrbitCamera::from_camera(&cam).camera();
        assert!((back.eye - cam.eye).length() < 1e-12);
        assert_eq!(back.target, cam.target);
    }
}
