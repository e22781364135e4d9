//! A light's window that reaches the horizon, split for a shading point on an occluder's own
//! surface: the part above a great circle tilted just above the horizon across the window,
//! where the windowed exact outline is exact (its window must stay strictly above the horizon,
//! on which the edges of the point's own face lie), and the thin part below it, where the
//! occluder's faces are subtracted one by one, each clipped to that part.
//!
//! With `W` the window (convex, in the shading frame, z up), `m` the tilted circle's normal and
//! `R` the region the mesh covers: `W ∖ R = (W ∖ (R ∩ W⁺)) ∖ (R ∩ W⁻)` for `W⁺ = W ∩ {d·m ≥ 0}`
//! and `W⁻ = W ∩ {d·m ≤ 0}`, since `W = W⁺ ∪ W⁻`. The windowed outline supplies `R ∩ W⁺` (its
//! loops agree with `R` in a slight widening of `W⁺`, and so may remove a little of `W⁻` too,
//! which is in `R` as well); the faces clipped to `W⁻` supply `R ∩ W⁻`.

use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
use glam::DVec3;

/// The tilted circle's least elevation (radians, as a tangent) over the window: far above the
/// margin the windowed outline needs (its window widened by 1e-3 of its extent must stay 1e-7
/// above the horizon), and low enough that the part below holds few faces.
const MIN_ELEVATION: f64 = 1e-2;

/// Windows spanning more azimuth than this (the least cosine of a corner's azimuth from the
/// window's middle) are not split: the tilted circle would have to rise too steeply at the
/// middle to stay above the horizon at the sides.
const MIN_AZIMUTH_COS: f64 = 0.25;

/// The two parts of a split window.
#[derive(Clone, Debug, Default)]
pub(crate) struct HorizonSplit {
    /// `W⁺`, one convex loop in the window's orientation (empty when the window lies below the
    /// tilted circle).
    pub upper: Vec<DVec3>,
    /// Inward normals of the half-spaces whose intersection is `W⁻`: `−m` first (the test that
    /// rejects most faces), then the window's sides.
    pub lower_planes: Vec<DVec3>,
    buf: Vec<DVec3>,
}

impl HorizonSplit {
    /// Splits `window` (one positively oriented convex loop of unit directions, z up). `false`
    /// when it spans too much azimuth or has no horizontal extent to tilt toward.
    pub(crate) fn split(&mut self, window: &[DVec3]) -> bool {
        self.upper.clear();
        self.lower_planes.clear();
        let m = window.len();
        if m < 3 {
            return false;
        }
        // The horizontal direction of the window's middle, and the least cosine of a corner's
        // azimuth from it (corners at the zenith have none and do not count).
        let mid = window
            .iter()
            .map(|w| DVec3::new(w.x, w.y, 0.0))
            .sum::<DVec3>();
        let Some(mid) = mid.try_normalize() else {
            return false;
        };
        let mut least = 1.0f64;
        for w in window {
            let h = DVec3::new(w.x, w.y, 0.0);
            if let Some(h) = h.try_normalize() {
                least = least.min(h.dot(mid));
            }
        }
        if least < MIN_AZIMUTH_COS {
            return false;
        }
        // The circle d·m = 0 with m = z − k·mid: at azimuth φ from the middle its elevation has
        // the tangent k cos φ, at least MIN_ELEVATION over the window.
        let k = MIN_ELEVATION / least;
        let tilt = (DVec3::Z - mid * k).normalize();
        let orient = window[0].cross(window[1]).dot(window[2]).signum();
        self.lower_planes.push(-tilt);
        for i in 0..m {
            let n = window[i].cross(window[(i + 1) % m]) * orient;
            self.lower_planes.push(n);
        }
        clip_loop_to_half_spaces(window, &[tilt], &mut self.upper, &mut self.buf);
        if self.upper.len() < 3 {
            self.upper.clear();
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SphericalPolygon;

    fn quad(el0: f64, el1: f64, az0: f64, az1: f64) -> Vec<DVec3> {
        let d = |el: f64, az: f64| DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        vec![d(el0, az0), d(el0, az1), d(el1, az1), d(el1, az0)]
    }

    fn area(lp: &[DVec3]) -> f64 {
        let mut p = SphericalPolygon::new();
        p.push_loop(lp.iter().copied());
        p.signed_solid_angle()
    }

    /// A window from the horizon up: the two parts cover it without overlap (their areas add
    /// up to its own, by the solid-angle formula), the upper part is above the horizon by at
    /// least the minimum elevation, and the lower part is a thin strip.
    #[test]
    fn the_parts_of_a_split_window_add_up_to_it() {
        let w = quad(0.0, 0.6, -0.5, 0.7);
        let mut s = HorizonSplit::default();
        assert!(s.split(&w));
        assert!(s.upper.iter().all(|d| d.z >= 0.99 * MIN_ELEVATION));
        let mut lower = Vec::new();
        clip_loop_to_half_spaces(&w, &s.lower_planes, &mut lower, &mut Vec::new());
        assert!(lower.iter().all(|d| d.z <= MIN_ELEVATION / MIN_AZIMUTH_COS));
        let (a, up, lo) = (area(&w), area(&s.upper), area(&lower));
        assert!(up > 0.0 && lo > 0.0);
        assert!((up + lo - a).abs() < 1e-12 * a, "{up} + {lo} vs {a}");
        // Too wide around the zenith's foot: not split.
        assert!(!s.split(&quad(0.0, 0.3, -1.4, 1.4)));
    }
}
