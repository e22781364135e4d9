//! Exact fast paths before a set difference with a convex clip polygon.
//!
//! Most occluders that survive `GetBetween` either miss the light polygon or hide all of it;
//! both are decided with orientation determinants in O(|subject|·|clip|), far cheaper than the
//! three phases of Greiner–Hormann.

use crate::geometry::PolygonLoops;
use crate::geometry::spherical::spherical_polygon::{edges_of, turns};
use glam::DVec3;

/// How a subject region relates to a convex clip loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    /// The subject lies strictly on the outer side of one clip edge: nothing to subtract.
    Disjoint,
    /// Every subject vertex lies strictly inside the clip: the difference is empty.
    SubjectInside,
    /// Anything else (including clips that are not convex): run the full set difference.
    Unknown,
}

/// Is the loop convex (no right turn)? Collinear vertices, e.g. the points that split a long
/// horizon arc, are allowed.
pub(crate) fn is_convex_loop(lp: &[DVec3]) -> bool {
    lp.len() >= 3 && turns(lp).all(|t| t >= 0.0)
}

/// Classifies `subject` against the loop `clip` (positively oriented, within the hemisphere
/// w ≥ 0 of the projection). Any clip may be found disjoint by a plane through the normal
/// (`separated_about_normal`); the other answers need a convex clip, and
/// [`Overlap::Unknown`] is returned for the rest.
pub fn classify(subject: &PolygonLoops, clip: &[DVec3]) -> Overlap {
    let verts = subject.vertices();
    if !is_convex_loop(clip) {
        return if separated_about_normal(verts, clip) {
            Overlap::Disjoint
        } else {
            Overlap::Unknown
        };
    }
    let mut all_inside = true;
    for (a, b) in edges_of(clip) {
        let ab = a.cross(b);
        let mut all_outside = true;
        for &v in verts {
            let s = ab.dot(v);
            all_outside &= s < 0.0;
            all_inside &= s > 0.0;
        }
        if all_outside {
            return Overlap::Disjoint;
        }
    }
    if all_inside {
        Overlap::SubjectInside
    } else {
        Overlap::Unknown
    }
}

/// The side of the plane through the normal (the w axis) and `r` on which `v` lies: positive
/// counter-clockwise of `r` seen from above. Homogeneous points with w ≥ 0 keep their sign.
#[inline]
fn side_of_meridian(r: DVec3, v: DVec3) -> f64 {
    r.x * v.y - r.y * v.x
}

/// The extreme vertices (clockwise-most, counter-clockwise-most) of a vertex set that spans
/// less than half a turn about the normal; `None` otherwise (it surrounds the normal, or a
/// vertex lies on it).
fn azimuth_wedge(verts: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let (&first, rest) = verts.split_first()?;
    let (mut lo, mut hi) = (first, first);
    for &v in rest {
        if side_of_meridian(lo, v) < 0.0 {
            lo = v;
        }
        if side_of_meridian(hi, v) > 0.0 {
            hi = v;
        }
    }
    // The scan is right only for a span below π: check it.
    let spans = side_of_meridian(lo, hi) > 0.0
        && verts
            .iter()
            .all(|&v| side_of_meridian(lo, v) >= 0.0 && side_of_meridian(hi, v) <= 0.0);
    spans.then_some((lo, hi))
}

/// Whether a plane through the normal has every vertex of `a` on one closed side and every
/// vertex of `b` strictly on the other. Both regions are then on their sides (a region within
/// the upper hemisphere whose boundary arcs lie in a half-space through the centre lies in
/// it), so they are disjoint. The planes tried bound the azimuth wedge of either set: this
/// is what separates two occluders seen in different directions around the normal, which
/// bounding boxes of the projection (stretched toward the horizon) often do not. O(|a| + |b|).
pub(crate) fn separated_about_normal(a: &[DVec3], b: &[DVec3]) -> bool {
    let beyond = |wedge: &[DVec3], other: &[DVec3]| {
        azimuth_wedge(wedge).is_some_and(|(lo, hi)| {
            other.iter().all(|&v| side_of_meridian(lo, v) < 0.0)
                || other.iter().all(|&v| side_of_meridian(hi, v) > 0.0)
        })
    };
    beyond(a, b) || beyond(b, a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SphericalPolygon;
    use crate::geometry::test_util::{contains, random_star_loop};
    use crate::math::{Frame, Pcg32};

    /// The classification agrees with point sampling: disjoint means no sample is in both,
    /// inside means every sample of the subject is in the clip.
    #[test]
    fn classification_agrees_with_point_sampling() {
        let mut rng = Pcg32::new(4, 4);
        let mut seen = [0usize; 3];
        for _ in 0..400 {
            let mut s = SphericalPolygon::new();
            random_star_loop(
                &mut s,
                &Frame::from_z(
                    DVec3::new(rng.range(-0.3, 0.3), rng.range(-0.3, 0.3), 1.0).normalize(),
                ),
                5,
                rng.range(0.05, 0.5),
                &mut rng,
            );
            // A convex clip: a regular polygon around a random centre.
            let c = DVec3::new(rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), 1.0).normalize();
            let f = Frame::from_z(c);
            let r = rng.range(0.02, 0.8);
            let k = 3 + rng.below(6) as usize;
            let clip: Vec<DVec3> = (0..k)
                .map(|j| {
                    let a = j as f64 * std::f64::consts::TAU / k as f64;
                    f.to_world(DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize())
                })
                .collect();
            let mut clip_poly = SphericalPolygon::new();
            clip_poly.push_loop(clip.iter().copied());
            let class = classify(&s, &clip);
            seen[class as usize] += 1;
            for _ in 0..2000 {
                let mut d = rng.unit_vector();
                d.z = d.z.abs();
                let in_s = contains(&s, d, -DVec3::Z);
                let in_c = contains(&clip_poly, d, -DVec3::Z);
                match class {
                    Overlap::Disjoint => assert!(!(in_s && in_c)),
                    Overlap::SubjectInside => assert!(!in_s || in_c),
                    Overlap::Unknown => {}
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 10), "every class occurs: {seen:?}");
    }

    /// Two star-shaped (non-convex) loops at random places in the upper hemisphere: whenever
    /// the test says they are separated about the normal, no sampled direction is in both,
    /// and it does say so for loops in clearly different directions.
    #[test]
    fn separation_about_the_normal_agrees_with_point_sampling() {
        let mut rng = Pcg32::new(9, 2);
        let (mut separated, mut far_apart) = (0usize, 0usize);
        for _ in 0..400 {
            let mut loops = [SphericalPolygon::new(), SphericalPolygon::new()];
            let mut centres = [DVec3::ZERO; 2];
            for (l, c) in loops.iter_mut().zip(&mut centres) {
                let phi = rng.range(0.0, std::f64::consts::TAU);
                // Elevation ≥ 0.30 rad, star radius ≤ atan(0.25) = 0.245 rad: above the
                // horizon.
                let z = rng.range(0.3, 0.9);
                let r = (1.0 - z * z).sqrt();
                *c = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                random_star_loop(l, &Frame::from_z(*c), 7, rng.range(0.05, 0.25), &mut rng);
            }
            let (a, b) = (&loops[0], &loops[1]);
            let sep = separated_about_normal(a.vertices(), b.vertices());
            if sep {
                separated += 1;
                for _ in 0..2000 {
                    let mut d = rng.unit_vector();
                    d.z = d.z.abs();
                    assert!(!(contains(a, d, -DVec3::Z) && contains(b, d, -DVec3::Z)));
                }
            }
            // A cap of radius 0.245 rad at elevation ≤ asin(0.6) spans at most
            // asin(sin 0.245 / 0.8) = 0.31 rad of azimuth each side of its centre: centres
            // more than 1 rad apart in azimuth must be found separated.
            let az = |c: DVec3| c.y.atan2(c.x);
            let mut d = (az(centres[0]) - az(centres[1])).abs();
            d = d.min(std::f64::consts::TAU - d);
            if d > 1.0 && centres.iter().all(|c| c.z < 0.6) {
                far_apart += 1;
                assert!(sep, "loops {d} rad apart in azimuth not separated");
            }
        }
        assert!(separated > 50 && far_apart > 20, "{separated} {far_apart}");
    }
}
