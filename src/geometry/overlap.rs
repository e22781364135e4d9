//! Exact fast paths before a set difference with a convex clip polygon.
//!
//! Most occluders that survive `GetBetween` either miss the light polygon or hide all of it;
//! both are decided with orientation determinants in O(|subject|·|clip|), far cheaper than the
//! three phases of Greiner–Hormann.

use super::{PolygonLoops, orient};
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
pub fn is_convex_loop(lp: &[DVec3]) -> bool {
    let n = lp.len();
    n >= 3 && (0..n).all(|i| orient(lp[(i + n - 1) % n], lp[i], lp[(i + 1) % n]) >= 0.0)
}

/// Classifies `subject` against the convex loop `clip` (positively oriented, within a
/// hemisphere). Returns [`Overlap::Unknown`] when `clip` is not convex.
pub fn classify(subject: &PolygonLoops, clip: &[DVec3]) -> Overlap {
    if !is_convex_loop(clip) {
        return Overlap::Unknown;
    }
    let verts = subject.vertices();
    let n = clip.len();
    let mut all_inside = true;
    for i in 0..n {
        let (a, b) = (clip[i], clip[(i + 1) % n]);
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
}
