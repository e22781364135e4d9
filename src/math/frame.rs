use glam::{DMat3, DVec3};

/// An orthonormal frame. `to_local` maps world directions into the frame's
/// coordinates; `z` is the axis the frame was built around.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub x: DVec3,
    pub y: DVec3,
    pub z: DVec3,
}

impl Frame {
    /// A right-handed frame around the unit vector `n`, continuous everywhere except
    /// on a set of measure zero (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
    pub fn from_z(n: DVec3) -> Self {
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { x, y, z: n }
    }

    /// The LTC shading frame (001 Fig. 3.3): `z` is the normal `n`, `x` is the direction in the
    /// tangent plane closest to the view direction `v`, so that `v` lies in the xz-plane with
    /// `v.x >= 0`. Falls back to [`Frame::from_z`] when `v` is parallel to `n`.
    pub fn from_normal_and_view(n: DVec3, v: DVec3) -> Self {
        let t = v - n * n.dot(v);
        let len = t.length();
        if len > 1e-12 * v.length().max(f64::MIN_POSITIVE) {
            let x = t / len;
            Frame {
                x,
                y: n.cross(x),
                z: n,
            }
        } else {
            Self::from_z(n)
        }
    }

    #[inline]
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.x), w.dot(self.y), w.dot(self.z))
    }

    #[inline]
    pub fn to_world(&self, l: DVec3) -> DVec3 {
        self.x * l.x + self.y * l.y + self.z * l.z
    }

    /// The matrix whose rows are the frame axes (world to local).
    pub(crate) fn world_to_local(&self) -> DMat3 {
        DMat3::from_cols(self.x, self.y, self.z).transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        let mut rng = crate::math::Pcg32::new(7, 1);
        for _ in 0..10_000 {
            let n = rng.unit_vector();
            let v = rng.unit_vector();
            for f in [Frame::from_z(n), Frame::from_normal_and_view(n, v)] {
                assert!((f.x.length() - 1.0).abs() < 1e-12);
                assert!((f.y.length() - 1.0).abs() < 1e-12);
                assert!(f.x.dot(f.y).abs() < 1e-12 && f.x.dot(f.z).abs() < 1e-12);
                assert!((f.x.cross(f.y) - f.z).length() < 1e-12);
                let w = rng.unit_vector();
                assert!((f.to_world(f.to_local(w)) - w).length() < 1e-12);
            }
            let f = Frame::from_normal_and_view(n, v);
            let vl = f.to_local(v);
            assert!(vl.y.abs() < 1e-12 && vl.x >= 0.0);
        }
    }
}
