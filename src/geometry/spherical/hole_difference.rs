//! The set difference of a convex region and one loop, written as the region with a hole:
//! `A ∖ B` as `A` less the part of `B` inside it.
//!
//! Every integral the renderer takes over a visible polygon is a sum of edge terms over its
//! loops (000 Eq. 9: the form factor; the specular lobe's LTC after M⁻¹), so it is linear in
//! the region's winding number, and
//!
//! ```text
//! ∫_{A∖B} = ∫_A − ∫_{A∩B}
//! ```
//!
//! needs the intersection only. For a convex `A` that is Sutherland–Hodgman clipping of `B`'s
//! loop by `A`'s edges, one half-space at a time: O(|A|·|B|), no intersection graph, no labels,
//! no traversal, and no degenerate contact to decide, because clipping by a half-space keeps
//! the winding number of every point inside it (the part of the loop outside is replaced by a
//! run along the plane, and the closed path it forms with the removed part lies in the closed
//! outer half-space). `B` need not be convex: a clipped loop that leaves `A` and comes back
//! keeps a zero-width run along an edge of `A`, which no integral sees.
//!
//! The price is one loop more to integrate (`A`'s edges whole, plus the intersection's),
//! against Greiner–Hormann's three phases; the answer differs from Greiner–Hormann's only by
//! rounding (the two sum different edge terms of the same region). It is used where the
//! difference is the last one a light piece takes (`shading::analytic`): each lobe integrates
//! `A` and the part apart, each clipped to the horizon on its own (a hole that touches its
//! region's boundary where both cross the horizon would leave the pairing of their crossings
//! to rounding), and the region is no subject for another Greiner–Hormann difference. Drawn,
//! it is `A` and the part reversed, with non-zero fill.

use crate::geometry::PlanarPolygon;
use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
use crate::geometry::spherical::spherical_polygon::{edges_of, turns};
use glam::DVec3;

/// Whether a loop is convex for [`part_inside_convex`]: a strict left turn at every vertex.
/// `overlap::is_convex_loop` also allows a straight vertex, which lets a spike through (out
/// along a segment and back: a half turn whose determinant is zero too), and clipping by the
/// spike's two opposite half-spaces would leave nothing of the clip.
fn turns_left_everywhere(lp: &[DVec3]) -> bool {
    lp.len() >= 3 && turns(lp).all(|t| t > 0.0)
}

/// The shortest edge (sine of its angle) of a subject [`part_inside_convex`] takes.
const MIN_EDGE_SINE: f64 = 1e-6;

/// Reused storage of [`part_inside_convex`].
#[derive(Clone, Debug, Default)]
pub struct HoleScratch {
    normals: Vec<DVec3>,
    part: Vec<DVec3>,
    tmp: Vec<DVec3>,
}

/// Writes the part of `clip` inside `subject` into `part`, so that `subject ∖ clip` is
/// `subject` less `part`, or returns `false` (and leaves `part` alone) when `subject` is not one
/// strictly convex loop with no edge shorter than `MIN_EDGE_SINE`, or `clip` not one loop. Both are positively oriented loops of homogeneous
/// points (w ≥ 0), as the projection gives them, and so is `part` (empty when nothing of
/// `clip` is inside).
///
/// Bound: one pass per edge of the subject. The part's vertices are `clip`'s vertices inside
/// the subject, the crossings of `clip`'s edges with the subject's boundary (at most two per
/// edge, the subject being convex) and the subject's corners on the runs between crossings (at
/// most |subject| per run): at most 3|clip| + |clip|·|subject| (reused buffers, no allocation
/// once grown).
pub fn part_inside_convex(
    subject: &PlanarPolygon,
    clip: &PlanarPolygon,
    part: &mut PlanarPolygon,
    scratch: &mut HoleScratch,
) -> bool {
    if subject.loop_count() != 1 || clip.loop_count() != 1 {
        return false;
    }
    let a = subject.loop_at(0);
    if !turns_left_everywhere(a) {
        return false;
    }
    // The inside of edge a_i → a_{i+1} of a positively oriented loop: n·v ≥ 0, n = a_i × a_{i+1}.
    scratch.normals.clear();
    scratch.normals.extend(edges_of(a).map(|(p, q)| p.cross(q)));
    // An edge's plane is as well determined as the edge is long: the cross product of two
    // unit vectors at angle L carries a rounding of about ε/L in its direction, which moves the
    // clipped points by that much across the clip. Below 1e-6 that could reach the invariant's
    // tolerance (1e-9): such polygons (slivers a previous difference left) go to
    // Greiner–Hormann, whose tolerances handle them.
    if scratch
        .normals
        .iter()
        .any(|m| m.length_squared() < MIN_EDGE_SINE * MIN_EDGE_SINE)
    {
        return false;
    }
    #[cfg(feature = "speed-guard-selftest")]
    for _ in 0..6 {
        // The speed guard's test of itself (scripts/speed_guard_selftest.sh): the clipping
        // done six more times, a slowdown of the set difference the guard must report.
        clip_loop_to_half_spaces(
            clip.loop_at(0),
            &scratch.normals,
            &mut scratch.part,
            &mut scratch.tmp,
        );
    }
    clip_loop_to_half_spaces(
        clip.loop_at(0),
        &scratch.normals,
        &mut scratch.part,
        &mut scratch.tmp,
    );
    part.clear();
    if !scratch.part.is_empty() {
        part.push_loop(scratch.part.iter().copied());
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_util::{contains, random_star_loop};
    use crate::geometry::{SetDifference, SphericalPolygon};
    use crate::ltc::form_factor;
    use crate::math::{Frame, Pcg32};

    fn regular(centre: DVec3, r: f64, k: usize, turn: f64) -> SphericalPolygon {
        let f = Frame::from_z(centre);
        let mut p = SphericalPolygon::new();
        p.push_loop((0..k).map(|j| {
            let a = turn + j as f64 * std::f64::consts::TAU / k as f64;
            f.to_world(DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize())
        }));
        p
    }

    fn planar(s: &SphericalPolygon) -> PlanarPolygon {
        let mut p = PlanarPolygon::new();
        p.copy_from(s);
        p
    }

    fn as_sphere(p: &PlanarPolygon) -> SphericalPolygon {
        let mut s = SphericalPolygon::new();
        s.copy_from(p);
        s.map_vertices(|v| v.normalize());
        s
    }

    /// A convex light less a random star-shaped (often non-convex) occluder: the form factor of
    /// the region with a hole equals Greiner–Hormann's difference (a second algorithm) to
    /// rounding, and both agree with a Monte Carlo estimate of the visible form factor (cosine-
    /// weighted directions counted by crossing parity, an oracle independent of both) within
    /// its 5σ interval.
    #[test]
    fn matches_greiner_hormann_and_monte_carlo() {
        let mut rng = Pcg32::new(38, 7);
        let mut gh = SetDifference::default();
        let mut scratch = HoleScratch::default();
        let (mut part, mut gh_out) = (PlanarPolygon::new(), PlanarPolygon::new());
        let mut partial = 0;
        for case in 0..300 {
            let c = DVec3::new(rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), 1.0).normalize();
            let k = 3 + rng.below(8) as usize;
            let light = regular(c, rng.range(0.1, 0.6), k, rng.range(0.0, 1.0));
            let mut occ = SphericalPolygon::new();
            let oc =
                DVec3::new(c.x + rng.range(-0.3, 0.3), c.y + rng.range(-0.3, 0.3), c.z).normalize();
            random_star_loop(
                &mut occ,
                &Frame::from_z(oc),
                3 + rng.below(9) as usize,
                rng.range(0.05, 0.5),
                &mut rng,
            );
            let (a, b) = (planar(&light), planar(&occ));
            assert!(part_inside_convex(&a, &b, &mut part, &mut scratch));
            gh.subtract(&a, &b, &mut gh_out, None);
            let f_light = form_factor(light.loops());
            let f_hole = f_light - form_factor(as_sphere(&part).loops());
            let f_gh = form_factor(as_sphere(&gh_out).loops());
            assert!(
                (f_hole - f_gh).abs() <= 1e-13 * f_light,
                "case {case}: {f_hole} vs {f_gh} (light {f_light})"
            );
            if f_hole > 0.02 * f_light && f_hole < 0.98 * f_light {
                partial += 1;
            }
            if case % 10 == 0 {
                // Cosine-weighted directions: the form factor is the fraction in the region.
                let n = 40_000;
                let hits = (0..n)
                    .filter(|_| {
                        let (u1, u2) = (rng.next_f64(), rng.next_f64());
                        let (r, phi) = (u1.sqrt(), std::f64::consts::TAU * u2);
                        let d = DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).sqrt());
                        contains(&light, d, -DVec3::Z) && !contains(&occ, d, -DVec3::Z)
                    })
                    .count();
                let p = hits as f64 / n as f64;
                let sigma = (p * (1.0 - p) / n as f64).sqrt().max(1.0 / n as f64);
                assert!(
                    (f_hole - p).abs() < 5.0 * sigma,
                    "case {case}: {f_hole} vs Monte Carlo {p} ± {sigma}"
                );
            }
        }
        assert!(partial > 100, "only {partial} partial covers");
    }

    /// Degenerate contacts need no decision: an occluder sharing an edge with the light, or
    /// with a vertex on it, gives the form factor of the exact difference, which is known in
    /// closed form here (the light split along a great circle through its centre).
    #[test]
    fn shared_edges_need_no_decision() {
        let light = regular(DVec3::Z, 0.4, 4, 0.0);
        let v = light.loop_at(0).to_vec();
        // The occluder covers the light's half beyond the diagonal v0–v2 and more: two of its
        // vertices are the light's corners v0 and v2, and its edge v2 → v0 is the diagonal.
        let beyond = |p: DVec3, q: DVec3| (p + 0.5 * (p - q)).normalize();
        let mut occ = SphericalPolygon::new();
        occ.push_loop([v[0], beyond(v[1], v[3]), v[2]]);
        let half = {
            let mut h = SphericalPolygon::new();
            h.push_loop([v[0], v[2], v[3]]);
            form_factor(h.loops())
        };
        let f_light = form_factor(light.loops());
        let mut part = PlanarPolygon::new();
        assert!(part_inside_convex(
            &planar(&light),
            &planar(&occ),
            &mut part,
            &mut HoleScratch::default()
        ));
        let f = f_light - form_factor(as_sphere(&part).loops());
        assert!((f - half).abs() < 1e-14, "{f} vs {half}");
        // An occluder equal to the light leaves nothing.
        assert!(part_inside_convex(
            &planar(&light),
            &planar(&light),
            &mut part,
            &mut HoleScratch::default()
        ));
        assert!((f_light - form_factor(as_sphere(&part).loops())).abs() < 1e-15);
    }

    /// Only one convex subject loop, with no edge too short for its plane, and one clip loop
    /// are taken.
    #[test]
    fn declines_what_it_cannot_do() {
        let mut two = planar(&regular(DVec3::Z, 0.3, 4, 0.0));
        two.extend_from(&planar(&regular(DVec3::Z, 0.1, 4, 0.0)));
        let one = planar(&regular(DVec3::Z, 0.2, 5, 0.0));
        let mut dart = PlanarPolygon::new();
        dart.push_loop([
            DVec3::new(-0.3, -0.3, 1.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.3, -0.3, 1.0),
            DVec3::new(0.0, 0.4, 1.0),
        ]);
        // A sliver a previous difference left: a convex 4-gon with an edge of 1e-9 rad, whose
        // plane rounding would move the clipped points by more than the invariant allows
        // (stress case 19654 of the mixed family found it).
        let mut sliver = PlanarPolygon::new();
        sliver.push_loop([
            DVec3::new(-0.2, 0.0, 1.0).normalize(),
            DVec3::new(0.2, 0.0, 1.0).normalize(),
            DVec3::new(0.2, 1e-9, 1.0).normalize(),
            DVec3::new(-0.2, 2e-9, 1.0).normalize(),
        ]);
        let mut part = PlanarPolygon::new();
        let mut s = HoleScratch::default();
        assert!(!part_inside_convex(&sliver, &one, &mut part, &mut s));
        assert!(!part_inside_convex(&two, &one, &mut part, &mut s));
        assert!(!part_inside_convex(&one, &two, &mut part, &mut s));
        assert!(!part_inside_convex(&dart, &one, &mut part, &mut s));
        assert!(part.is_empty());
    }
}
