//! `ClipToHorizon` (000 Alg. 3), generalised to polygons with several loops and holes.
//!
//! Each loop is cut into *chains*: maximal runs of vertices above the horizon (z > 0), starting
//! at the point where the loop enters the upper hemisphere and ending where it leaves. The
//! chains are then joined along the horizon: a positively oriented region has the upper
//! hemisphere on its left, so the horizon is walked counter-clockwise (increasing azimuth) from
//! each exit to the nearest entry. This is the pairing that 001 Eq. 4.6–4.7 expresses with the
//! atan2 sum; it stays right for non-convex loops and holes, where joining each exit to the next
//! entry *of the same loop* (000 Alg. 3's `CloseVertices`) does not.
//!
//! Exactness: crossing points are convex combinations `a·(-z_b) + b·z_a` with non-negative
//! weights (no division by a small difference), their z is set to exactly 0, and a vertex lying
//! exactly on the horizon is kept bit for bit. Nothing is nudged.

use crate::geometry::SphericalPolygon;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

#[derive(Clone, Copy, Debug)]
struct Chain {
    start: u32,
    end: u32,
    entry_phi: f64,
    exit_phi: f64,
    used: bool,
}

/// Reusable buffers for [`clip_to_horizon`].
#[derive(Clone, Debug, Default)]
pub struct HorizonScratch {
    chains: Vec<Chain>,
    buf: Vec<DVec3>,
}

/// The point where the arc from `above` (z > 0) to `below` (z ≤ 0) meets the horizon.
#[inline]
fn crossing(above: DVec3, below: DVec3) -> DVec3 {
    if below.z == 0.0 {
        return below;
    }
    let p = above * (-below.z) + below * above.z;
    let r = p.x.hypot(p.y);
    DVec3::new(p.x / r, p.y / r, 0.0)
}

#[inline]
fn push_distinct(out: &mut SphericalPolygon, v: DVec3) {
    if out.open_loop().last() != Some(&v) {
        out.push_vertex(v);
    }
}

/// Closes the loop under construction, dropping a last vertex equal to the first.
#[inline]
fn close(out: &mut SphericalPolygon) {
    let lp = out.open_loop();
    if lp.len() > 1 && lp.first() == lp.last() {
        let n = out.vertex_count();
        // Safe: the open loop has at least two vertices.
        out.0.discard_last_vertex(n);
    }
    out.close_loop();
}

/// Clips `input` to the upper hemisphere z ≥ 0 of the shading frame, writing the result to
/// `out` (cleared first). Loops must be positively oriented regions with holes negative.
pub fn clip_to_horizon(
    input: &SphericalPolygon,
    out: &mut SphericalPolygon,
    scratch: &mut HorizonScratch,
) {
    out.clear();
    scratch.chains.clear();
    scratch.buf.clear();
    for lp in input.loops() {
        let n = lp.len();
        let above_count = lp.iter().filter(|v| v.z > 0.0).count();
        if above_count == n {
            for &v in lp {
                push_distinct(out, v);
            }
            close(out);
            continue;
        }
        if above_count == 0 {
            continue;
        }
        // Start at a vertex above the horizon whose predecessor is not.
        let s = (0..n)
            .find(|&i| lp[i].z > 0.0 && lp[(i + n - 1) % n].z <= 0.0)
            .unwrap_or(0);
        let entry = crossing(lp[s], lp[(s + n - 1) % n]);
        let mut chain_start = scratch.buf.len();
        let mut entry_phi = entry.y.atan2(entry.x);
        scratch.buf.push(entry);
        for k in 0..n {
            let i = (s + k) % n;
            let j = (i + 1) % n;
            let (a, b) = (lp[i], lp[j]);
            if a.z > 0.0 {
                if scratch.buf.last() != Some(&a) {
                    scratch.buf.push(a);
                }
                if b.z <= 0.0 {
                    let exit = crossing(a, b);
                    if scratch.buf.last() != Some(&exit) {
                        scratch.buf.push(exit);
                    }
                    scratch.chains.push(Chain {
                        start: chain_start as u32,
                        end: scratch.buf.len() as u32,
                        entry_phi,
                        exit_phi: exit.y.atan2(exit.x),
                        used: false,
                    });
                }
            } else if b.z > 0.0 && j != s {
                let e = crossing(b, a);
                chain_start = scratch.buf.len();
                entry_phi = e.y.atan2(e.x);
                scratch.buf.push(e);
            }
        }
    }

    // Join the chains along the horizon.
    let chains = &mut scratch.chains;
    // Bound: each step of the inner walk marks an unused chain used, or closes onto `first`:
    // `chains.len()` steps over all loops.
    for first in 0..chains.len() {
        if chains[first].used {
            continue;
        }
        let mut c = first;
        loop {
            chains[c].used = true;
            let Chain {
                start,
                end,
                exit_phi,
                ..
            } = chains[c];
            for &v in &scratch.buf[start as usize..end as usize] {
                push_distinct(out, v);
            }
            // Nearest entry counter-clockwise from this exit (the chain itself included: a loop
            // that leaves and re-enters once closes onto its own entry).
            let mut best = first;
            let mut best_d = f64::INFINITY;
            for (k, ch) in chains.iter().enumerate() {
                if ch.used && k != first {
                    continue;
                }
                let mut d = (ch.entry_phi - exit_phi).rem_euclid(TAU);
                if d >= TAU {
                    d = 0.0;
                }
                if d < best_d {
                    best_d = d;
                    best = k;
                }
            }
            // Arcs along the horizon must stay shorter than π: split long ones.
            if best_d > 0.5 * PI {
                let pieces = (best_d / (0.5 * PI)).ceil() as usize;
                for p in 1..pieces {
                    let phi = exit_phi + best_d * p as f64 / pieces as f64;
                    push_distinct(out, DVec3::new(phi.cos(), phi.sin(), 0.0));
                }
            }
            if best == first {
                break;
            }
            c = best;
        }
        close(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_util::{contains, random_star_loop};
    use crate::math::{Frame, Pcg32};

    /// Monte Carlo solid angle of the part of `poly` above the horizon; `outside` is a
    /// direction known to lie outside the region.
    fn mc_clipped_area(
        poly: &SphericalPolygon,
        outside: DVec3,
        rng: &mut Pcg32,
        n: usize,
    ) -> (f64, f64) {
        let mut hits = 0;
        for _ in 0..n {
            let mut d = rng.unit_vector();
            d.z = d.z.abs(); // uniform on the upper hemisphere
            if contains(poly, d, outside) {
                hits += 1;
            }
        }
        let p = hits as f64 / n as f64;
        (TAU * p, TAU * (p * (1.0 - p) / n as f64).sqrt())
    }

    #[test]
    fn clipped_area_matches_point_sampling() {
        let mut rng = Pcg32::new(21, 2);
        let mut out = SphericalPolygon::new();
        let mut scratch = HorizonScratch::default();
        for case in 0..60 {
            // Centres near the horizon so that most polygons straddle it.
            let c = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-0.4, 0.4),
            )
            .normalize();
            let mut poly = SphericalPolygon::new();
            random_star_loop(
                &mut poly,
                &Frame::from_z(c),
                3 + rng.below(8) as usize,
                rng.range(0.1, 2.0),
                &mut rng,
            );
            clip_to_horizon(&poly, &mut out, &mut scratch);
            assert!(out.vertices().iter().all(|v| v.z >= 0.0 && v.is_finite()));
            let exact = out.signed_solid_angle_about(DVec3::Z);
            let (mc, sigma) = mc_clipped_area(&poly, -c, &mut rng, 100_000);
            assert!(
                (exact - mc).abs() < 4.5 * sigma + 1e-12,
                "case {case}: {exact} vs {mc} ± {sigma}"
            );
        }
    }

    #[test]
    fn polygon_with_a_hole_across_the_horizon() {
        // Outer square around the horizon point +x, hole inside it, both cut by the horizon.
        let f = Frame {
            x: DVec3::Y,
            y: DVec3::Z,
            z: DVec3::X,
        };
        let sq = |r: f64| {
            [(-r, -r), (r, -r), (r, r), (-r, r)]
                .map(|(a, b)| f.to_world(DVec3::new(a, b, 1.0).normalize()))
        };
        let mut poly = SphericalPolygon::new();
        poly.push_loop(sq(0.8));
        poly.push_loop(sq(0.3).into_iter().rev());
        let mut out = SphericalPolygon::new();
        clip_to_horizon(&poly, &mut out, &mut HorizonScratch::default());
        let mut outer = SphericalPolygon::new();
        outer.push_loop(sq(0.8));
        let mut hole = SphericalPolygon::new();
        hole.push_loop(sq(0.3));
        // Both squares are symmetric about the horizon: exactly half of the annulus remains.
        let expected = 0.5 * (outer.signed_solid_angle() - hole.signed_solid_angle());
        assert!((out.signed_solid_angle_about(DVec3::Z) - expected).abs() < 1e-13);
        assert_eq!(
            out.loop_count(),
            1,
            "the hole opens onto the horizon and merges with the outer loop"
        );
    }

    #[test]
    fn vertices_on_the_horizon_are_kept_exactly() {
        let tri = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 0.5f64.sqrt()),
        ];
        let mut poly = SphericalPolygon::new();
        poly.push_loop(tri);
        let mut out = SphericalPolygon::new();
        clip_to_horizon(&poly, &mut out, &mut HorizonScratch::default());
        assert_eq!(out.loop_count(), 1);
        let mut got: Vec<DVec3> = out.loop_at(0).to_vec();
        got.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        let mut want = tri.to_vec();
        want.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        assert_eq!(got, want, "no vertex moved");
    }

    #[test]
    fn near_horizon_vertices_give_continuous_results() {
        let mut out = SphericalPolygon::new();
        let mut scratch = HorizonScratch::default();
        let mut last: Option<f64> = None;
        for z in [1e-3, 1e-9, 1e-15, 1e-300, 0.0, -1e-300, -1e-15, -1e-9] {
            let mut poly = SphericalPolygon::new();
            poly.push_loop([
                DVec3::new(1.0, -0.5, z).normalize(),
                DVec3::new(1.0, 0.5, z).normalize(),
                DVec3::new(0.5, 0.0, 1.0).normalize(),
            ]);
            clip_to_horizon(&poly, &mut out, &mut scratch);
            let a = out.signed_solid_angle_about(DVec3::Z);
            assert!(a.is_finite() && a > 0.0);
            if let Some(prev) = last {
                assert!((a - prev).abs() < 2e-3, "z = {z}: {a} vs {prev}");
            }
            last = Some(a);
        }
    }

    #[test]
    fn polygon_below_the_horizon_vanishes_and_above_is_unchanged() {
        let mut poly = SphericalPolygon::new();
        poly.push_loop(
            [
                DVec3::new(1.0, 0.0, -0.1),
                DVec3::new(0.0, 1.0, -0.1),
                DVec3::new(0.0, 0.0, -1.0),
            ]
            .map(|v| v.normalize()),
        );
        let mut out = SphericalPolygon::new();
        clip_to_horizon(&poly, &mut out, &mut HorizonScratch::default());
        assert!(out.is_empty());
        poly.reverse_loops();
        poly.map_vertices(|v| -v);
        clip_to_horizon(&poly, &mut out, &mut HorizonScratch::default());
        assert_eq!(out.vertices(), poly.vertices());
    }

    #[test]
    fn a_cap_covering_the_zenith_keeps_long_horizon_arcs_short() {
        // A large loop around the zenith dipping below the horizon everywhere but one spot.
        let mut poly = SphericalPolygon::new();
        poly.push_loop((0..12).map(|k| {
            let phi = k as f64 * TAU / 12.0;
            DVec3::new(phi.cos(), phi.sin(), if k == 0 { 0.3 } else { -0.2 }).normalize()
        }));
        let mut out = SphericalPolygon::new();
        clip_to_horizon(&poly, &mut out, &mut HorizonScratch::default());
        let lp = out.loop_at(0);
        for i in 0..lp.len() {
            assert!(
                lp[i].dot(lp[(i + 1) % lp.len()]) > -1e-12,
                "arc of π or more"
            );
        }
        let mut rng = Pcg32::new(1, 1);
        let (mc, sigma) = mc_clipped_area(&poly, -DVec3::Z, &mut rng, 200_000);
        let exact = out.signed_solid_angle_about(DVec3::Z);
        assert!(
            (exact - mc).abs() < 4.5 * sigma,
            "{exact} vs {mc} ± {sigma}"
        );
    }
}
