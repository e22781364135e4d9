use glam::DVec3;

/// Pinhole camera (docs/scenes.md): vertical field of view in degrees; image +x is the camera's
/// right = forward x up; row 0 is the top row of the image.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    pub fov_deg: f64,
    /// The width / height the field of view was authored for (a glTF camera's
    /// `aspectRatio`, a scene file's `aspect`), if any. An image at least that wide keeps the
    /// vertical field of view `fov_deg`; a narrower one keeps the authored horizontal field of
    /// view instead, so that the authored frame stays in the picture whatever `--size` says
    /// (docs/scenes.md, "Camera").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aspect: Option<f64>,
}

/// The camera's orthonormal basis and image-plane scale, computed once per render.
#[derive(Clone, Copy, Debug)]
pub struct CameraBasis {
    pub eye: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    /// tan(fov / 2) of the vertical field of view, for images at least [`Camera::aspect`]
    /// wide (see `CameraBasis::tan_half_fov_at`).
    pub tan_half_fov: f64,
    pub aspect: Option<f64>,
}

impl Camera {
    /// Validates the camera: finite, eye != target, up not parallel to the view direction.
    pub fn basis(&self) -> crate::Result<CameraBasis> {
        let all = [self.eye, self.target, self.up];
        if all.iter().any(|v| !v.is_finite()) || !self.fov_deg.is_finite() {
            return Err("camera has a non-finite coordinate".into());
        }
        if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(crate::Error::from(format!(
                "field of view {} is not in (0, 180) degrees",
                self.fov_deg
            )));
        }
        let forward = (self.target - self.eye)
            .try_normalize()
            .ok_or("camera eye equals target")?;
        let right = forward
            .cross(self.up)
            .try_normalize()
            .ok_or("camera up vector is zero or parallel to the view direction")?;
        let up = right.cross(forward);
        Ok(CameraBasis {
            eye: self.eye,
            forward,
            right,
            up,
            tan_half_fov: (self.fov_deg.to_radians() * 0.5).tan(),
            aspect: self.aspect.filter(|a| a.is_finite() && *a > 0.0),
        })
    }
}

impl CameraBasis {
    /// tan of half the vertical field of view of an image of width / height `aspect`: the
    /// camera's own, or, for an image narrower than the camera's authored aspect, the one that
    /// keeps the authored horizontal field of view.
    #[inline]
    pub(crate) fn tan_half_fov_at(&self, aspect: f64) -> f64 {
        match self.aspect {
            Some(authored) if aspect < authored => self.tan_half_fov * authored / aspect,
            _ => self.tan_half_fov,
        }
    }

    /// Unit direction through the image position (x, y) in pixels, measured from the top-left
    /// corner of the image (so pixel (i, j) spans [i, i+1) x [j, j+1)).
    #[inline]
    pub fn direction(&self, x: f64, y: f64, width: u32, height: u32) -> DVec3 {
        let aspect = width as f64 / height as f64;
        let t = self.tan_half_fov_at(aspect);
        let sx = (2.0 * x / width as f64 - 1.0) * aspect * t;
        let sy = (1.0 - 2.0 * y / height as f64) * t;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_axes_follow_the_convention() {
        let cam = Camera {
            eye: DVec3::ZERO,
            target: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_deg: 90.0,
            aspect: None,
        };
        let b = cam.basis().unwrap();
        // forward = -z, up = +y, so right = forward x up = +x.
        assert!((b.right - DVec3::X).length() < 1e-15);
        let centre = b.direction(50.0, 50.0, 100, 100);
        assert!((centre - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-15);
        // Top-left corner: left (-x) and up (+y); 90 degrees means the edge is at 45 degrees.
        let tl = b.direction(0.0, 0.0, 100, 100);
        assert!(tl.x < 0.0 && tl.y > 0.0);
        assert!((tl.y / -tl.z - 1.0).abs() < 1e-12);
    }

    /// A camera authored for 4:3: a wider image keeps its vertical field of view, a narrower
    /// one (square, portrait) its horizontal one, so the authored frame's left and right edges
    /// stay the image's edges.
    #[test]
    fn an_authored_aspect_keeps_the_frame_in_the_picture() {
        let cam = Camera {
            eye: DVec3::ZERO,
            target: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_deg: 40.0,
            aspect: Some(4.0 / 3.0),
        };
        let b = cam.basis().unwrap();
        let slope = |d: DVec3| (d.x / -d.z, d.y / -d.z);
        let (x43, y43) = slope(b.direction(0.0, 0.0, 640, 480));
        let t = 20f64.to_radians().tan();
        assert!((y43 - t).abs() < 1e-12 && (x43 + 4.0 / 3.0 * t).abs() < 1e-12);
        // Wider: the same vertical extent.
        let (_, y169) = slope(b.direction(0.0, 0.0, 1600, 900));
        assert!((y169 - t).abs() < 1e-12);
        // Square and portrait: the same horizontal extent.
        for (w, h) in [(256, 256), (300, 600)] {
            let (x, _) = slope(b.direction(0.0, 0.0, w, h));
            assert!((x - x43).abs() < 1e-12, "{w}x{h}: {x} vs {x43}");
        }
        // Without an authored aspect the vertical field of view holds at every size.
        let free = Camera {
            aspect: None,
            ..cam
        }
        .basis()
        .unwrap();
        let (_, y) = slope(free.direction(0.0, 0.0, 256, 256));
        assert!((y - t).abs() < 1e-12);
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        let c = Camera {
            eye: DVec3::ZERO,
            target: DVec3::ZERO,
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        };
        assert!(c.basis().is_err());
        let c = Camera {
            eye: DVec3::ZERO,
            target: DVec3::Y,
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        };
        assert!(c.basis().is_err());
        let c = Camera {
            eye: DVec3::NAN,
            target: DVec3::Y,
            up: DVec3::Z,
            fov_deg: 45.0,
            aspect: None,
        };
        assert!(c.basis().is_err());
    }
}
