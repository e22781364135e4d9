//! Closed-form integral of the clamped cosine over a spherical polygon (Lambert 1760,
//! Baum, Rushmeier, Winget 1989; 001 Eq. 3.14):
//!
//! `E(P) = ∫_P cosθ/π dω = 1/(2π) Σ_edges θ_ab · (a×b)·z / |a×b|`, `θ_ab = ∠(a, b)`,
//!
//! valid for a region of the upper hemisphere whose boundary loops are counter-clockwise
//! seen from outside the sphere (holes clockwise). Clipping to the horizon is the caller's
//! job; for loops that dip below it the sum is the integral of the *unclamped* cosine.

use glam::DVec3;
use std::f64::consts::TAU;

/// Below this `tanθ` the ratio `θ/sinθ` is evaluated by its series (see [`edge_integral`]).
const SERIES_TAN: f64 = 1e-2;

/// `θ · (a×b).z / |a×b|` with `θ = atan2(|a×b|, a·b)` the angle between `a` and `b`.
///
/// This is the contribution of the great-circle arc `a → b` (shorter than π) to
/// `2π ∫ cosθ/π dω`. The cross product is formed as `½ (a + b) × (b − a)`, whose rounding
/// error is proportional to the edge length, so that small polygons keep their relative
/// accuracy (the terms of a polygon of size h are O(h) and sum to O(h²)), and which makes the
/// function exactly antisymmetric in `a`, `b`. The result depends only on the directions of `a` and `b` (the angle
/// comes from `atan2`, which is exact for non-unit inputs, never from `acos`, which loses
/// half the digits near 0 and π). It is evaluated as `(a×b).z · θ/|a×b|`, where
/// `θ/|a×b| = atan(t)/(t · a·b)` with `t = |a×b|/(a·b) = tanθ`; for `0 < t < 1e-2` the
/// series `atan(t)/t = 1 − t²/3 + t⁴/5 − t⁶/7 + t⁸/9` (the series of `θ/sinθ · cosθ` for unit
/// vectors, truncation error < 1e-21) avoids the `0/0` and the `atan2` call for short
/// edges. Returns 0 for `a ∥ b` (`a == b`, and also exactly antipodal points, whose arc is
/// undefined). Allocation-free.
#[inline]
pub fn edge_integral(a: DVec3, b: DVec3) -> f64 {
    // a × b = ½ (a + b) × (b − a): for short edges b − a is exact or nearly so (Sterbenz),
    // so the rounding error of w is relative to the edge length instead of absolute (~ε);
    // and swapping a, b negates every rounded operation, so edge_integral(b, a) is exactly
    // −edge_integral(a, b) (edges shared by adjacent loops cancel exactly).
    let w = (a + b).cross(b - a) * 0.5;
    let s2 = w.length_squared();
    if s2 == 0.0 {
        return 0.0;
    }
    let c = a.dot(b);
    let s = s2.sqrt();
    let theta_over_s = if c > 0.0 && s < SERIES_TAN * c {
        let t2 = s2 / (c * c);
        (1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0))))) / c
    } else {
        s.atan2(c) / s
    };
    w.z * theta_over_s
}

/// `∫ cosθ/π dω` over the region bounded by `loops`, each an implicitly closed sequence of
/// directions (last vertex connects to the first):
/// `(1/2π) Σ_loops Σ_edges edge_integral(p_i, p_{i+1})`.
///
/// Outer boundaries counter-clockwise seen from outside the sphere (`det(a, b, c) > 0` for
/// a small convex triangle `a → b → c`), holes clockwise; all loops already clipped to the
/// upper hemisphere. A clockwise loop yields the negated value. Loops with fewer than three
/// vertices contribute 0. Allocation-free.
pub fn form_factor<'a>(loops: impl IntoIterator<Item = &'a [DVec3]>) -> f64 {
    let mut sum = 0.0;
    form_factor_terms(loops, |_, _, term| sum += term);
    sum / TAU
}

/// The terms of [`form_factor`]'s sum (000 Eq. 9) in the order it adds them:
/// `term(loop, k, edge_integral(p_{k−1}, p_k))`, each loop from its closing edge (`k = 0`
/// is the edge from the last vertex to the first). The debugger's recording lists them.
#[inline]
pub fn form_factor_terms<'a>(
    loops: impl IntoIterator<Item = &'a [DVec3]>,
    mut term: impl FnMut(usize, usize, f64),
) {
    for (li, lp) in loops.into_iter().enumerate() {
        if lp.len() < 3 {
            continue;
        }
        let mut prev = lp[lp.len() - 1];
        for (k, &p) in lp.iter().enumerate() {
            term(li, k, edge_integral(prev, p));
            prev = p;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    #[test]
    fn closed_hemisphere_and_simple_cases() {
        // The horizon traversed counter-clockwise seen from above bounds the whole upper
        // hemisphere: ∫ cos/π = 1.
        let ring: Vec<DVec3> = (0..7)
            .map(|k| {
                let p = TAU * k as f64 / 7.0;
                DVec3::new(p.cos(), p.sin(), 0.0)
            })
            .collect();
        assert!((form_factor([ring.as_slice()]) - 1.0).abs() < 1e-15);
        let rev: Vec<DVec3> = ring.iter().rev().copied().collect();
        assert!((form_factor([rev.as_slice()]) + 1.0).abs() < 1e-15);
        assert_eq!(edge_integral(DVec3::Z, DVec3::Z), 0.0);
        assert_eq!(edge_integral(DVec3::X, DVec3::X * 3.0), 0.0);
        // Octant x, y, z >= 0: cos-weighted integral is 1/4 of the hemisphere.
        let oct = [DVec3::X, DVec3::Y, DVec3::Z];
        assert!((form_factor([oct.as_slice()]) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn scale_invariant_and_continuous_across_series_switch() {
        let mut rng = Pcg32::new(3, 4);
        for _ in 0..1000 {
            let a = rng.unit_vector();
            let b = rng.unit_vector();
            let e = edge_integral(a, b);
            let d = (edge_integral(a * 2.5, b * 0.3) - e).abs();
            // Rounding of w relative to |w| = sinθ is amplified by θ/sinθ near antipodes.
            let s = a.cross(b).length();
            let bound = 16.0 * f64::EPSILON * s.atan2(a.dot(b)) / s;
            assert!(d <= bound, "{a} {b} {e} {d:e} > {bound:e}");
        }
        // Around t = 1e-2 both branches must agree to rounding.
        let a = DVec3::new(0.3, -0.2, 0.9).normalize();
        let axis = a.cross(DVec3::new(0.1, 0.7, 0.2)).normalize();
        let rot = |t: f64| a * t.cos() + axis.cross(a) * t.sin();
        for k in -20..=20 {
            let th = (SERIES_TAN).atan() * (1.0 + k as f64 * 1e-9);
            let b = rot(th);
            let w = a.cross(b);
            let exact = th * w.z / w.length();
            assert!((edge_integral(a, b) - exact).abs() < 1e-16);
        }
    }
}
