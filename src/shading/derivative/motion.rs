//! The rigid motion a derivative follows, and what it does at one shading point: how fast the
//! point slides along its camera ray and how fast its shading frame turns.

use crate::math::Frame;
use crate::shading::ShadingPoint;
use glam::DVec3;

crate::choice! {
    /// The parameter θ of a rigid motion of one object, as `penumbra edit` moves it.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum Axis {
        /// Translation along +x; the derivative is per scene unit.
        Tx = "tx",
        /// Translation along +y; the derivative is per scene unit.
        Ty = "ty",
        /// Translation along +z; the derivative is per scene unit.
        Tz = "tz",
        /// Rotation about +y through the centre of the object's bounding box; per radian.
        Ry = "ry",
    }
}

/// One object moving rigidly with θ: `object` (its index in the scene), along `axis`, turning
/// about `pivot` for [`Axis::Ry`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    pub object: u32,
    pub axis: Axis,
    pub pivot: DVec3,
}

impl Motion {
    /// The velocity `dp/dθ` of a point `p` of the object.
    #[inline]
    pub fn velocity(&self, p: DVec3) -> DVec3 {
        match self.axis {
            Axis::Tx => DVec3::X,
            Axis::Ty => DVec3::Y,
            Axis::Tz => DVec3::Z,
            Axis::Ry => DVec3::Y.cross(p - self.pivot),
        }
    }

    /// The rate `dd/dθ` of a direction `d` carried by the object (a face normal).
    #[inline]
    pub fn turn(&self, d: DVec3) -> DVec3 {
        match self.axis {
            Axis::Ry => DVec3::Y.cross(d),
            _ => DVec3::ZERO,
        }
    }

    /// The object's rigid motion at θ: `θ` scene units along the axis, or `θ` radians about
    /// +y through the pivot.
    pub fn at(&self, theta: f64) -> crate::scene::edit::Rigid {
        use crate::scene::edit::Rigid;
        match self.axis {
            Axis::Tx => Rigid::translation(DVec3::X * theta),
            Axis::Ty => Rigid::translation(DVec3::Y * theta),
            Axis::Tz => Rigid::translation(DVec3::Z * theta),
            Axis::Ry => Rigid::rotation_about(self.pivot, DVec3::Y, theta)
                .unwrap_or(Rigid::translation(DVec3::ZERO)),
        }
    }
}

/// What the motion does at one shading point, the point found along a fixed camera ray.
///
/// When the point lies on the moving object, it is not a point of the object: the camera ray
/// stays, so the point slides along it as the object's surface moves through it. For the
/// face's plane `n · (y − c) = h` carried by the motion, `x = o + t r` gives
/// `dt/dθ = n · v(x) / (n · r)` for a translation `v` and `dt/dθ = ṅ · (c − x) / (n · r)`
/// for a rotation about `c` (`ṅ = ŷ × n`); the normal turns at `ṅ`, and the frame built from
/// it and the (fixed) view direction turns with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMotion {
    pub motion: Motion,
    /// The point lies on the moving object: every piece of the boundary moves relative to it.
    pub on_moving: bool,
    /// `dx/dθ`.
    pub point_velocity: DVec3,
    /// The rates of the shading frame's axes (`Frame::from_normal_and_view`).
    pub frame_rate: Frame,
    /// `d cosθv / dθ`.
    pub cos_rate: f64,
    /// The point's rates are not defined here (a grazing camera ray, or a view along the
    /// normal while the normal turns): the pixel is masked.
    pub degenerate: bool,
}

impl PointMotion {
    /// The motion at the shading point `sp`, hit along the camera ray of direction `ray_dir`.
    pub fn at(motion: &Motion, sp: &ShadingPoint, ray_dir: DVec3) -> PointMotion {
        let zero = Frame {
            x: DVec3::ZERO,
            y: DVec3::ZERO,
            z: DVec3::ZERO,
        };
        let on_moving = sp.object == Some(motion.object);
        if !on_moving {
            return PointMotion {
                motion: *motion,
                on_moving,
                point_velocity: DVec3::ZERO,
                frame_rate: zero,
                cos_rate: 0.0,
                degenerate: false,
            };
        }
        let (n, x, v) = (sp.normal, sp.position, sp.view);
        let n_dot_r = n.dot(ray_dir);
        let n_rate = motion.turn(n);
        let t_rate = match motion.axis {
            Axis::Ry => n_rate.dot(motion.pivot - x),
            _ => n.dot(motion.velocity(x)),
        } / n_dot_r;
        let mut degenerate = n_dot_r.abs() <= 1e-9 * ray_dir.length() || !t_rate.is_finite();
        // Frame::from_normal_and_view: t = v − n (n·v), x = t/|t|, y = n × x, z = n.
        let t = v - n * n.dot(v);
        let len = t.length();
        let frame_rate = if n_rate == DVec3::ZERO {
            zero
        } else if len > 1e-6 {
            let fx = t / len;
            let t_dot = -n_rate * n.dot(v) - n * n_rate.dot(v);
            let x_rate = (t_dot - fx * fx.dot(t_dot)) / len;
            Frame {
                x: x_rate,
                y: n_rate.cross(fx) + n.cross(x_rate),
                z: n_rate,
            }
        } else {
            degenerate = true;
            zero
        };
        PointMotion {
            motion: *motion,
            on_moving,
            point_velocity: if degenerate {
                DVec3::ZERO
            } else {
                ray_dir * t_rate
            },
            frame_rate,
            cos_rate: n_rate.dot(v),
            degenerate,
        }
    }

    /// The velocity of a point `p` relative to the shading point, `p` moving with the object
    /// or not.
    #[inline]
    pub fn relative_velocity(&self, p: DVec3, moving: bool) -> DVec3 {
        let v = if moving {
            self.motion.velocity(p)
        } else {
            DVec3::ZERO
        };
        v - self.point_velocity
    }
}
