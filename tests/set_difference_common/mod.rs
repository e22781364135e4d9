//! Helpers shared by the set-difference tests: oracles and polygon plumbing that do not use the
//! code under test.
#![allow(dead_code)]

use glam::DVec3;
use penumbra::geometry::{PlanarPolygon, orient};
use std::f64::consts::TAU;

/// Sutherland–Hodgman: the part of a loop where n · p ≥ 0 (on the sphere; crossing points are
/// positive combinations of the edge's endpoints, exact zeros stay exact for n = ±z).
pub fn clip_halfspace(lp: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(lp.len() + 2);
    for i in 0..lp.len() {
        let a = lp[i];
        let b = lp[(i + 1) % lp.len()];
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let x = if da > 0.0 {
                b * da - a * db
            } else {
                a * db - b * da
            };
            let x = x.normalize();
            out.push(if n == DVec3::Z {
                DVec3::new(x.x, x.y, 0.0).normalize()
            } else {
                x
            });
        }
    }
    out
}

pub fn horizon_clip(lp: &[DVec3]) -> Vec<DVec3> {
    clip_halfspace(lp, DVec3::Z)
}

pub fn loops_of(p: &PlanarPolygon) -> Vec<Vec<DVec3>> {
    p.loops()
        .map(|l| l.iter().map(|v| v.normalize()).collect())
        .collect()
}

/// Unit normal of the great circle through a and b, as a × (b − a): for short edges a × b
/// loses its relative precision to cancellation (1e-7 for an edge of 1e-9 rad).
pub fn line_normal(a: DVec3, b: DVec3) -> DVec3 {
    a.cross(b - a).normalize()
}

/// `orient(a, b, c)` as a · ((b − a) × (c − a)): accurate for nearby points, where the direct
/// a · (b × c) is rounding noise (1e-16 against determinants of 1e-20 for points 1e-10 apart).
pub fn orient_near(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    a.dot((b - a).cross(c - a))
}

/// Winding number of the loops about the unit direction p: the sum of the angles the edges
/// subtend about p (each arc is shorter than π and avoids ±p, so its angle is the signed angle
/// between its endpoints' projections onto the plane orthogonal to p).
pub fn winding(loops: &[Vec<DVec3>], p: DVec3) -> f64 {
    let mut w = 0.0;
    for lp in loops {
        for i in 0..lp.len() {
            let a = lp[i];
            let b = lp[(i + 1) % lp.len()];
            let ta = a - p * p.dot(a);
            let tb = b - p * p.dot(b);
            w += orient(p, ta, tb).atan2(ta.dot(tb));
        }
    }
    w / TAU
}
