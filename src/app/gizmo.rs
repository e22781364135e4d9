//! On-screen handles to move the selected object in the viewport: three arrows that translate
//! along the world axes and a ring that rotates about the vertical through the pivot. Plain
//! screen geometry over the camera's projection; what a drag does to the scene is
//! `scene::edit`'s business.

use crate::scene::camera::CameraBasis;
use egui::{Color32, Painter, Pos2, Rect, Stroke, Vec2};
use glam::DVec3;

/// A handle of the gizmo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handle {
    /// Translate along world axis 0 (x), 1 (y) or 2 (z).
    Axis(usize),
    /// Rotate about the world y axis through the pivot.
    RotateY,
}

/// What a pointer motion on a handle asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Motion {
    Translate(DVec3),
    /// Radians about +y (right-handed).
    RotateY(f64),
}

/// Pixels within which the pointer grabs a handle.
const GRAB_PX: f32 = 9.0;
const RING_POINTS: usize = 64;
const AXIS_COLOURS: [Color32; 3] = [
    Color32::from_rgb(235, 70, 70),
    Color32::from_rgb(90, 210, 90),
    Color32::from_rgb(80, 140, 255),
];

/// The gizmo of one object as seen by one camera in one viewport rectangle.
#[derive(Clone, Copy, Debug)]
pub struct Gizmo {
    pub basis: CameraBasis,
    pub rect: Rect,
    pub pivot: DVec3,
    /// World length of the arrows (the ring's radius is 0.8 of it).
    pub length: f64,
}

impl Gizmo {
    /// A gizmo whose arrows are about a sixth of the viewport's height, whatever the distance.
    pub fn new(basis: CameraBasis, rect: Rect, pivot: DVec3) -> Self {
        let depth = (pivot - basis.eye).dot(basis.forward).max(1e-6);
        // World size of one viewport height at the pivot's depth, times 1/6.
        let aspect = (rect.width() / rect.height().max(1.0)) as f64;
        let length = 2.0 * depth * basis.tan_half_fov_at(aspect) / 6.0;
        Gizmo {
            basis,
            rect,
            pivot,
            length,
        }
    }

    /// The screen position of a world point (the inverse of `CameraBasis::direction`);
    /// `None` behind the camera.
    pub fn project(&self, p: DVec3) -> Option<Pos2> {
        let b = &self.basis;
        let d = p - b.eye;
        let z = d.dot(b.forward);
        if z <= 1e-9 {
            return None;
        }
        let aspect = (self.rect.width() / self.rect.height()) as f64;
        let t = b.tan_half_fov_at(aspect);
        let sx = d.dot(b.right) / z / (aspect * t);
        let sy = d.dot(b.up) / z / t;
        Some(Pos2::new(
            self.rect.min.x + ((sx + 1.0) * 0.5) as f32 * self.rect.width(),
            self.rect.min.y + ((1.0 - sy) * 0.5) as f32 * self.rect.height(),
        ))
    }

    /// The arrow along world axis `i` on the screen: from the pivot to its tip.
    pub fn arrow(&self, i: usize) -> Option<(Pos2, Pos2)> {
        Some((self.project(self.pivot)?, self.project(self.axis_end(i))?))
    }

    fn axis_end(&self, i: usize) -> DVec3 {
        let mut e = DVec3::ZERO;
        e[i] = self.length;
        self.pivot + e
    }

    /// The ring point at angle `phi`: rotating by θ about +y moves it to `phi + θ`.
    fn ring_point(&self, phi: f64) -> DVec3 {
        let r = 0.8 * self.length;
        self.pivot + DVec3::new(r * phi.cos(), 0.0, -r * phi.sin())
    }

    fn ring(&self) -> Vec<Pos2> {
        (0..=RING_POINTS)
            .filter_map(|k| {
                self.project(self.ring_point(k as f64 / RING_POINTS as f64 * std::f64::consts::TAU))
            })
            .collect()
    }

    /// The handle under the pointer, arrows first.
    pub fn hit(&self, pos: Pos2) -> Option<Handle> {
        let c = self.project(self.pivot)?;
        let mut best: Option<(f32, Handle)> = None;
        for i in 0..3 {
            if let Some(e) = self.project(self.axis_end(i)) {
                let d = segment_distance(pos, c, e);
                if d < GRAB_PX && best.is_none_or(|b| d < b.0) {
                    best = Some((d, Handle::Axis(i)));
                }
            }
        }
        if best.is_none() {
            let ring = self.ring();
            let d = ring
                .windows(2)
                .map(|w| segment_distance(pos, w[0], w[1]))
                .fold(f32::INFINITY, f32::min);
            if d < GRAB_PX {
                best = Some((d, Handle::RotateY));
            }
        }
        best.map(|b| b.1)
    }

    /// What moving the pointer from `from` to `to` on `handle` asks for. An arrow follows the
    /// pointer's motion along the arrow's screen direction; the ring, the pointer's angle
    /// about the pivot's screen position (in the ring's screen orientation).
    pub(crate) fn motion(&self, handle: Handle, from: Pos2, to: Pos2) -> Option<Motion> {
        let c = self.project(self.pivot)?;
        match handle {
            Handle::Axis(i) => {
                let e = self.project(self.axis_end(i))?;
                let s = e - c;
                let px_per_unit = s.length() as f64 / self.length;
                // An arrow seen end-on cannot be dragged along.
                if px_per_unit * self.length < 4.0 {
                    return None;
                }
                let along = (to - from).dot(s.normalized()) as f64;
                let mut t = DVec3::ZERO;
                t[i] = along / px_per_unit;
                Some(Motion::Translate(t))
            }
            Handle::RotateY => {
                let (a, b) = (from - c, to - c);
                if a.length() < 2.0 || b.length() < 2.0 {
                    return None;
                }
                let screen = cross(a, b).atan2(a.dot(b)) as f64;
                // The ring's orientation on screen (the sign of its signed area): its points
                // turn one way seen from above and the other way from below.
                let ring = self.ring();
                let turn: f32 = ring.windows(2).map(|w| cross(w[0] - c, w[1] - c)).sum();
                let extent = ring
                    .iter()
                    .map(|p| (*p - c).length_sq())
                    .fold(0.0, f32::max);
                if turn.abs() < 0.05 * extent {
                    // Edge-on: the ring is a line; follow the pointer's horizontal motion.
                    return Some(Motion::RotateY(((to.x - from.x) / 100.0) as f64));
                }
                Some(Motion::RotateY(screen * turn.signum() as f64))
            }
        }
    }

    /// Draws the handles; `active` (dragged) or `hovered` ones are highlighted.
    pub(crate) fn paint(&self, painter: &Painter, hovered: Option<Handle>, active: Option<Handle>) {
        let Some(c) = self.project(self.pivot) else {
            return;
        };
        let lit = |h: Handle| active == Some(h) || (active.is_none() && hovered == Some(h));
        let ring = self.ring();
        let ring_colour = Color32::from_rgb(240, 200, 60);
        let w = if lit(Handle::RotateY) { 3.5 } else { 2.0 };
        painter.add(egui::Shape::line(ring, Stroke::new(w, ring_colour)));
        for (i, colour) in AXIS_COLOURS.iter().enumerate() {
            let Some(e) = self.project(self.axis_end(i)) else {
                continue;
            };
            let w = if lit(Handle::Axis(i)) { 4.0 } else { 2.5 };
            painter.line_segment([c, e], Stroke::new(w, *colour));
            let dir = (e - c).normalized();
            let side = Vec2::new(-dir.y, dir.x) * 5.0;
            painter.add(egui::Shape::convex_polygon(
                vec![e + dir * 10.0, e + side, e - side],
                *colour,
                Stroke::NONE,
            ));
            painter.text(
                e + dir * 18.0,
                egui::Align2::CENTER_CENTER,
                ["x", "y", "z"][i],
                egui::FontId::proportional(13.0),
                *colour,
            );
        }
        painter.circle_filled(c, 3.5, Color32::WHITE);
    }
}

fn cross(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

fn segment_distance(p: Pos2, a: Pos2, b: Pos2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_sq().max(1e-6)).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::Camera;

    fn gizmo() -> Gizmo {
        let cam = Camera {
            eye: DVec3::new(0.3, 2.0, 4.0),
            target: DVec3::new(0.0, 0.2, 0.0),
            up: DVec3::Y,
            fov_deg: 45.0,
            aspect: None,
        };
        let rect = Rect::from_min_size(Pos2::new(10.0, 20.0), Vec2::new(640.0, 480.0));
        Gizmo::new(cam.basis().unwrap(), rect, DVec3::new(0.1, 0.4, -0.2))
    }

    /// `project` inverts the renderer's primary rays: the ray through the projected pixel
    /// passes through the point.
    #[test]
    fn projection_inverts_the_camera_rays() {
        let g = gizmo();
        let p = DVec3::new(-0.4, 0.9, 0.5);
        let s = g.project(p).unwrap();
        let (w, h) = (640u32, 480u32);
        let x = (s.x - g.rect.min.x) as f64 / g.rect.width() as f64 * w as f64;
        let y = (s.y - g.rect.min.y) as f64 / g.rect.height() as f64 * h as f64;
        let d = g.basis.direction(x, y, w, h);
        let to = (p - g.basis.eye).normalize();
        assert!(d.dot(to) > 1.0 - 1e-9, "{}", d.dot(to));
    }

    /// Dragging an arrow's tip by its own screen vector moves the object by the arrow's world
    /// length; dragging the ring a quarter turn on screen rotates by about a quarter turn
    /// (exactly, seen from straight above).
    #[test]
    fn drags_move_along_the_handles() {
        let g = gizmo();
        let c = g.project(g.pivot).unwrap();
        for i in 0..3 {
            let e = g.project(g.axis_end(i)).unwrap();
            assert_eq!(g.hit(c + (e - c) * 0.6), Some(Handle::Axis(i)));
            let Some(Motion::Translate(t)) = g.motion(Handle::Axis(i), c, e) else {
                panic!("axis {i}");
            };
            assert!((t[i] - g.length).abs() < 1e-4 * g.length, "{t}");
        }
        let top = Camera {
            eye: DVec3::new(0.0, 5.0, 0.0),
            target: DVec3::ZERO,
            up: DVec3::new(0.0, 0.0, -1.0),
            fov_deg: 40.0,
            aspect: None,
        };
        let g = Gizmo::new(top.basis().unwrap(), g.rect, DVec3::ZERO);
        // Between the arrows: at angle 0 the ring passes under the x arrow, which takes the
        // pointer first.
        const START: f64 = 0.7;
        let a = g.project(g.ring_point(START)).unwrap();
        let b = g
            .project(g.ring_point(START + std::f64::consts::FRAC_PI_2))
            .unwrap();
        assert_eq!(g.hit(a), Some(Handle::RotateY));
        let Some(Motion::RotateY(theta)) = g.motion(Handle::RotateY, a, b) else {
            panic!("ring");
        };
        assert!(
            (theta - std::f64::consts::FRAC_PI_2).abs() < 1e-4,
            "{theta}"
        );
        // From below, the same world rotation is the opposite screen turn: still +π/2.
        let below = Camera {
            eye: DVec3::new(0.0, -5.0, 0.0),
            ..top
        };
        let g = Gizmo::new(below.basis().unwrap(), g.rect, DVec3::ZERO);
        let a = g.project(g.ring_point(START)).unwrap();
        let b = g
            .project(g.ring_point(START + std::f64::consts::FRAC_PI_2))
            .unwrap();
        let Some(Motion::RotateY(theta)) = g.motion(Handle::RotateY, a, b) else {
            panic!("ring");
        };
        assert!(
            (theta - std::f64::consts::FRAC_PI_2).abs() < 1e-4,
            "{theta}"
        );
    }
}
