//! Oracles and generators shared by the geometry tests.

use super::{SphericalPolygon, orient};
use crate::math::{Frame, Pcg32};
use glam::DVec3;

/// Appends a random loop star-shaped around `frame.z` (hence positively oriented), with `n`
/// vertices at tangent-plane radius up to `spread` (spread 1 ≈ 45°).
pub(crate) fn random_star_loop(
    poly: &mut SphericalPolygon,
    frame: &Frame,
    n: usize,
    spread: f64,
    rng: &mut Pcg32,
) {
    let angles: Vec<f64> = (0..n)
        .map(|k| (k as f64 + 0.8 * rng.next_f64()) * std::f64::consts::TAU / n as f64)
        .collect();
    poly.push_loop(angles.iter().map(|&a| {
        let r = spread * rng.range(0.3, 1.0);
        frame.to_world(DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize())
    }));
}

/// Does the great arc p→q (shorter than π) cross the arc a→b?
fn arcs_cross(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> bool {
    let da = orient(p, q, a);
    let db = orient(p, q, b);
    if (da > 0.0) == (db > 0.0) {
        return false;
    }
    // The one point of arc a→b on the great circle through p and q (a positive combination).
    let x = a * db.abs() + b * da.abs();
    let n = p.cross(q);
    n.dot(p.cross(x)) > 0.0 && n.dot(x.cross(q)) > 0.0
}

/// Containment by crossing parity along the arc from `p` to a direction `outside` known to lie
/// outside the region: an oracle that needs nothing of the code under test.
pub(crate) fn contains(poly: &SphericalPolygon, p: DVec3, outside: DVec3) -> bool {
    let mut inside = false;
    for lp in poly.loops() {
        for i in 0..lp.len() {
            if arcs_cross(p, outside, lp[i], lp[(i + 1) % lp.len()]) {
                inside = !inside;
            }
        }
    }
    inside
}
