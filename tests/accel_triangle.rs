//! The watertight ray–triangle test against an independent oracle (plane intersection and
//! Cramer's rule), on degenerate input, on extreme input (no NaN), and on shared edges and
//! vertices of fans.

use glam::DVec3;
use penumbra::accel::{PreparedRay, Ray, intersect_triangle, is_degenerate};
use penumbra::math::Pcg32;

/// Independent oracle: the ray meets the plane at t; barycentrics of that point by Cramer's
/// rule in the plane. Returns (t, b0, b1, b2) or None if the ray is parallel.
fn oracle(ray: &Ray, v0: DVec3, v1: DVec3, v2: DVec3) -> Option<(f64, f64, f64, f64)> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let n = e1.cross(e2);
    let denom = n.dot(ray.dir);
    if denom == 0.0 {
        return None;
    }
    let t = n.dot(v0 - ray.origin) / denom;
    let p = ray.origin + t * ray.dir - v0;
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (p1, p2) = (p.dot(e1), p.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let b1 = (d22 * p1 - d12 * p2) / det;
    let b2 = (d11 * p2 - d12 * p1) / det;
    Some((t, 1.0 - b1 - b2, b1, b2))
}

fn random_triangle(rng: &mut Pcg32, scale: f64) -> (DVec3, DVec3, DVec3) {
    let c = DVec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    );
    let r = rng.range(0.05, 1.0);
    (
        scale * (c + r * rng.unit_vector()),
        scale * (c + r * rng.unit_vector()),
        scale * (c + r * rng.unit_vector()),
    )
}

#[test]
fn agrees_with_plane_oracle_at_all_scales() {
    let mut rng = Pcg32::new(1, 1);
    let mut hits = 0;
    let mut misses = 0;
    for &scale in &[1e-4, 1.0, 1e4] {
        for _ in 0..20_000 {
            let (v0, v1, v2) = random_triangle(&mut rng, scale);
            if is_degenerate(v0, v1, v2) {
                continue;
            }
            let origin = scale * 3.0 * rng.unit_vector();
            // Aim at a random point of the triangle's plane, inside or outside.
            let (a, b) = (rng.range(-0.5, 1.5), rng.range(-0.5, 1.5));
            let target = v0 + a * (v1 - v0) + b * (v2 - v0);
            let len = rng.range(0.1, 10.0);
            let ray = Ray::new(origin, (target - origin) * len);
            let got = intersect_triangle(&ray, v0, v1, v2, 0.0, f64::INFINITY);
            let Some((t, b0, b1, b2)) = oracle(&ray, v0, v1, v2) else {
                continue;
            };
            // Skip ill-conditioned cases (grazing rays) and points near an edge.
            let n = (v1 - v0).cross(v2 - v0).normalize();
            let cos = n.dot(ray.dir.normalize()).abs();
            if cos < 1e-2 {
                continue;
            }
            let margin = 1e-6;
            let inside = b0 > margin && b1 > margin && b2 > margin && t > 0.0;
            let outside = b0 < -margin || b1 < -margin || b2 < -margin || t < 0.0;
            if inside {
                let h = got.unwrap_or_else(|| panic!("missed: {v0} {v1} {v2} {ray:?}"));
                assert!((h.t - t).abs() <= 1e-9 * t, "t {} vs {}", h.t, t);
                let want = DVec3::new(b0, b1, b2);
                assert!(
                    (h.bary - want).abs().max_element() < 1e-9,
                    "{} vs {want}",
                    h.bary
                );
                assert!((h.bary.element_sum() - 1.0).abs() < 1e-12);
                let p = h.point(v0, v1, v2);
                assert!(
                    (p - ray.at(h.t)).length() < 1e-9 * scale,
                    "{p} vs {}",
                    ray.at(h.t)
                );
                hits += 1;
            } else if outside {
                assert!(got.is_none(), "false hit {got:?}");
                misses += 1;
            }
        }
    }
    assert!(
        hits > 5_000 && misses > 10_000,
        "{hits} hits, {misses} misses"
    );
}

#[test]
fn t_range_is_open_and_both_sides_hit() {
    let (v0, v1, v2) = (
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    );
    let up = Ray::new(DVec3::new(0.25, 0.25, 0.0), DVec3::new(0.0, 0.0, 2.0));
    let h = intersect_triangle(&up, v0, v1, v2, 0.0, f64::INFINITY).unwrap();
    assert_eq!(h.t, 0.5);
    assert_eq!(h.bary, DVec3::new(0.5, 0.25, 0.25));
    assert!(intersect_triangle(&up, v0, v1, v2, 0.0, 0.5).is_none());
    assert!(intersect_triangle(&up, v0, v1, v2, 0.5, 1.0).is_none());
    assert!(intersect_triangle(&up, v0, v1, v2, 0.4999, 0.5001).is_some());
    // From the back (clockwise side) too.
    let down = Ray::new(DVec3::new(0.25, 0.25, 2.0), DVec3::new(0.0, 0.0, -1.0));
    assert_eq!(
        intersect_triangle(&down, v0, v1, v2, 0.0, f64::INFINITY)
            .unwrap()
            .t,
        1.0
    );
    // Behind the origin: no hit with t_min = 0, a hit with t_min = -inf.
    let away = Ray::new(DVec3::new(0.25, 0.25, 0.0), DVec3::new(0.0, 0.0, -1.0));
    assert!(intersect_triangle(&away, v0, v1, v2, 0.0, f64::INFINITY).is_none());
    assert_eq!(
        intersect_triangle(&away, v0, v1, v2, f64::NEG_INFINITY, f64::INFINITY)
            .unwrap()
            .t,
        -1.0
    );
}

#[test]
fn degenerate_triangles_are_never_hit() {
    let p = DVec3::new(0.3, -0.2, 0.1);
    let q = DVec3::new(1.0, 2.0, 3.0);
    let cases = [
        (p, p, p),
        (p, p, q),
        (p, q, q),
        (q, p, q),
        // Exactly collinear.
        (
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(2.0, 2.0, 2.0),
        ),
        // Collinear up to the rounding of the decimal coordinates.
        (
            DVec3::ZERO,
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(0.3, 0.6, 0.9),
        ),
        // Exactly collinear, small and far from the origin (offsets exact in f64).
        (
            DVec3::splat(1e4),
            DVec3::splat(1e4) + DVec3::new(1.0, 2.0, 3.0) / 4096.0,
            DVec3::splat(1e4) + DVec3::new(3.0, 6.0, 9.0) / 4096.0,
        ),
    ];
    let mut rng = Pcg32::new(2, 2);
    for (v0, v1, v2) in cases {
        assert!(is_degenerate(v0, v1, v2), "{v0} {v1} {v2}");
        for _ in 0..2000 {
            // Aim at the vertices, at points on the segment, and from random places.
            let s = rng.next_f64();
            let target = match rng.below(3) {
                0 => v0,
                1 => v1.lerp(v2, s),
                _ => v0.lerp(v2, s),
            };
            let origin = target + rng.range(0.1, 10.0) * rng.unit_vector();
            let ray = Ray::new(origin, target - origin);
            assert!(
                intersect_triangle(&ray, v0, v1, v2, f64::NEG_INFINITY, f64::INFINITY).is_none()
            );
        }
    }
    // A thin but honest sliver is not degenerate.
    assert!(!is_degenerate(
        DVec3::ZERO,
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.5, 1e-9, 0.0)
    ));
}

#[test]
fn no_nan_for_finite_input() {
    let mut rng = Pcg32::new(3, 3);
    let mags = [
        0.0,
        1e-300,
        1e-30,
        1e-4,
        1.0,
        1e4,
        1e30,
        1e150,
        1e300,
        f64::MAX,
    ];
    let pick = |rng: &mut Pcg32| -> DVec3 {
        let mut v = DVec3::ZERO;
        for k in 0..3 {
            let m = mags[rng.below(mags.len() as u32) as usize];
            let s = if rng.below(2) == 0 { -1.0 } else { 1.0 };
            v[k] = s * m * rng.range(0.5, 1.0);
        }
        v
    };
    for _ in 0..200_000 {
        let (v0, v1, v2) = (pick(&mut rng), pick(&mut rng), pick(&mut rng));
        let ray = Ray::new(pick(&mut rng), pick(&mut rng));
        if let Some(h) = intersect_triangle(&ray, v0, v1, v2, f64::NEG_INFINITY, f64::INFINITY) {
            assert!(h.t.is_finite() && h.bary.is_finite(), "{h:?}");
            assert!(h.bary.min_element() >= 0.0 && h.bary.max_element() <= 1.0);
        }
        let pre = PreparedRay::new(&ray);
        if let Some(h) = pre.intersect(v0, v1, v2, f64::NEG_INFINITY, f64::INFINITY) {
            assert!(h.t.is_finite() && h.bary.is_finite(), "{h:?}");
        }
    }
    // A zero direction hits nothing.
    let ray = Ray::new(DVec3::ZERO, DVec3::ZERO);
    assert!(
        intersect_triangle(
            &ray,
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            f64::NEG_INFINITY,
            f64::INFINITY
        )
        .is_none()
    );
}

/// A fan of `n` triangles around `center` (a closed disc): rays aimed exactly at the center
/// and at points on the shared spokes must hit at least one triangle.
#[test]
fn fans_are_watertight_at_shared_vertices_and_edges() {
    let mut rng = Pcg32::new(4, 4);
    let mut edge_rays = 0;
    for case in 0..3000 {
        let scale = [1e-4, 1.0, 1e4][case % 3];
        let center = scale
            * DVec3::new(
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
            );
        let normal = rng.unit_vector();
        let u = normal.any_orthonormal_vector();
        let w = normal.cross(u);
        let n = 4 + rng.below(8) as usize;
        let rim: Vec<DVec3> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + rng.range(-0.2, 0.2)) / n as f64;
                let r = scale * rng.range(0.5, 2.0);
                // Slightly non-planar on purpose (but no silhouette from the origin).
                center
                    + r * (a.cos() * u + a.sin() * w)
                    + scale * 0.02 * rng.range(-1.0, 1.0) * normal
            })
            .collect();
        let origin = center + scale * rng.range(0.5, 5.0) * (normal + 0.3 * rng.unit_vector());
        let mut targets = vec![center];
        for r in &rim {
            targets.push(center.lerp(*r, rng.next_f64()));
        }
        for target in targets {
            // Axis-aligned rays too (directions with exact zeros), when not grazing.
            let mut dirs = vec![target - origin];
            if normal.z.abs() > 0.5 {
                dirs.push(DVec3::new(0.0, 0.0, -normal.z * scale));
            }
            for dir in dirs {
                let ray = Ray::new(if dir.x == 0.0 { target - dir } else { origin }, dir);
                let hit = (0..n).any(|i| {
                    intersect_triangle(&ray, center, rim[i], rim[(i + 1) % n], 0.0, f64::INFINITY)
                        .is_some()
                });
                // A ray within the fan's plane may legitimately miss (all determinants zero).
                let in_plane = (0..n).all(|i| {
                    let nn = (rim[i] - center).cross(rim[(i + 1) % n] - center);
                    nn.dot(dir).abs() < 1e-9 * nn.length() * dir.length()
                });
                assert!(hit || in_plane, "ray {ray:?} escaped fan at {center}");
                edge_rays += 1;
            }
        }
    }
    assert!(edge_rays > 10_000);
}
