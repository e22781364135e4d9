//! The environment light's math (paper 002): map convention and files, SH projection and
//! irradiance, the closed-form SH integral over spherical polygons, importance sampling.
//! Every check compares against an independent oracle (quadrature, Monte Carlo, an exact
//! identity); each tolerance says where it comes from.

use crate::ltc_common::gauss_legendre;
use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{DMat3, DQuat, DVec3};
use penumbra::environment::{
    EnvironmentMap, EnvironmentSampler, PolygonMoments, Sh9, cosine_weighted_integral,
    cosine_weighted_integral_local, sh_basis,
};

// ---------------------------------------------------------------------------------------------
// Helpers: a deterministic RNG, Gauss–Legendre nodes, spherical-triangle quadrature.

/// xorshift64*: deterministic, independent of the crate's own generators.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
    fn rotation(&mut self) -> DMat3 {
        let q = DQuat::from_xyzw(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
        .normalize();
        DMat3::from_quat(q)
    }
    fn unit(&mut self) -> DVec3 {
        self.rotation() * DVec3::Z
    }
    fn sh(&mut self) -> Sh9 {
        let mut coeffs = [DVec3::ZERO; 9];
        for c in &mut coeffs {
            *c = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
        }
        coeffs[0] += DVec3::splat(3.0);
        Sh9 { coeffs }
    }
}

/// ∫ f over the spherical triangle (a, b, c), signed: positive when counter-clockwise seen
/// from outside. The planar triangle is mapped from the unit square by the Duffy map
/// p = a + s(b − a) + st(c − b) and projected to the sphere, dω = (p·n_plane) s dA / |p|³.
fn triangle_integral(
    f: &dyn Fn(DVec3) -> DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
    gl: &[(f64, f64)],
) -> DVec3 {
    let cross = (b - a).cross(c - b);
    let mut sum = DVec3::ZERO;
    for &(s, ws) in gl {
        for &(t, wt) in gl {
            let p = a + s * (b - a) + s * t * (c - b);
            let r = p.length();
            let jac = s * cross.dot(p) / (r * r * r);
            sum += f(p / r) * (ws * wt * jac);
        }
    }
    sum
}

/// Points along the great arc a → b, at most `step` apart, b excluded.
fn arc_points(a: DVec3, b: DVec3, step: f64) -> Vec<DVec3> {
    let gamma = a.cross(b).length().atan2(a.dot(b));
    let k = (gamma / step).ceil().max(1.0) as usize;
    let e = (b - a.dot(b) * a).normalize_or_zero();
    (0..k)
        .map(|m| {
            let g = gamma * m as f64 / k as f64;
            a * g.cos() + e * g.sin()
        })
        .collect()
}

/// The oracle: ∫_P f(ω) dω by Gauss–Legendre over the fan of triangles (apex, arc pieces),
/// with the arcs cut into pieces of at most 0.25 rad. Signed, so holes and overlaps count as
/// their winding number, like the closed form.
fn polygon_quadrature(f: &dyn Fn(DVec3) -> DVec3, loops: &[Vec<DVec3>], apex: DVec3) -> DVec3 {
    let gl = gauss_legendre(24);
    let mut sum = DVec3::ZERO;
    for l in loops {
        for k in 0..l.len() {
            let (a, b) = (l[k], l[(k + 1) % l.len()]);
            let mut pts = arc_points(a, b, 0.25);
            pts.push(b);
            for w in pts.windows(2) {
                sum += triangle_integral(f, apex, w[0], w[1], &gl);
            }
        }
    }
    sum
}

fn closed_form(sh: &Sh9, world_to_local: DMat3, loops: &[Vec<DVec3>]) -> DVec3 {
    let m = PolygonMoments::of_loops(loops.iter().map(Vec::as_slice), DVec3::Z);
    cosine_weighted_integral_local(&sh.local_quadratic(world_to_local), &m)
}

/// The oracle for a local-frame polygon: the world SH evaluated directly (Eq. 8), not
/// through the quadratic form.
fn oracle(sh: &Sh9, world_to_local: DMat3, loops: &[Vec<DVec3>]) -> DVec3 {
    let local_to_world = world_to_local.transpose();
    let f = |w: DVec3| sh.eval(local_to_world * w) * w.z;
    polygon_quadrature(&f, loops, DVec3::Z)
}

/// A polygon star-shaped about `centre` in its gnomonic (tangent) plane: vertex k at angle
/// 2πk/n (jittered) and tangent-plane radius in [r0, r1]. Counter-clockwise seen from outside
/// when `ccw`. Equal radii give a convex polygon, random radii a non-convex one.
fn star(rng: &mut Rng, centre: DVec3, n: usize, r0: f64, r1: f64, ccw: bool) -> Vec<DVec3> {
    let t1 = centre.any_orthonormal_vector();
    let t2 = centre.cross(t1);
    let mut v: Vec<DVec3> = (0..n)
        .map(|k| {
            let psi = 2.0 * PI * (k as f64 + rng.range(-0.3, 0.3)) / n as f64;
            let r = rng.range(r0, r1);
            (centre + r * (psi.cos() * t1 + psi.sin() * t2)).normalize()
        })
        .collect();
    if !ccw {
        v.reverse();
    }
    v
}

fn above(elevation: f64, azimuth: f64) -> DVec3 {
    let (se, ce) = elevation.sin_cos();
    DVec3::new(ce * azimuth.cos(), ce * azimuth.sin(), se)
}

/// |got − want| ≤ tol · scale, per channel, with a message.
fn assert_close(got: DVec3, want: DVec3, tol: f64, scale: f64, what: &str) {
    let err = (got - want).abs().max_element();
    assert!(
        err <= tol * scale,
        "{what}: got {got}, want {want}, error {err:e} > {tol:e} x {scale:e}"
    );
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-environment-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

// ---------------------------------------------------------------------------------------------
// SH basis, projection, irradiance, quadratic form.

/// ∫ Y_a Y_b dω = δ_ab, by a rule exact for these polynomials: Gauss–Legendre (12 points,
/// exact to degree 23) in cos θ about the z axis times the trapezoid rule in φ (16 points,
/// exact for trigonometric degree < 16). Only rounding is left.
#[test]
fn sh_basis_is_orthonormal() {
    let gl = gauss_legendre(12);
    let nphi = 16;
    let mut gram = [[0.0; 9]; 9];
    for &(t, wt) in &gl {
        let z = 2.0 * t - 1.0;
        let r = (1.0 - z * z).sqrt();
        for k in 0..nphi {
            let phi = 2.0 * PI * k as f64 / nphi as f64;
            let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let y = sh_basis(d);
            let w = 2.0 * wt * 2.0 * PI / nphi as f64;
            for a in 0..9 {
                for b in 0..9 {
                    gram[a][b] += y[a] * y[b] * w;
                }
            }
        }
    }
    for (a, row) in gram.iter().enumerate() {
        for (b, &g) in row.iter().enumerate() {
            let want = if a == b { 1.0 } else { 0.0 };
            assert!((g - want).abs() < 1e-13, "<Y{a}, Y{b}> = {g}");
        }
    }
}

/// Projecting the band-limited map back gives its coefficients. The projection is the
/// midpoint rule over pixels with exact solid angles: exact in φ (the trapezoid rule on
/// trigonometric polynomials of degree ≤ 4 < W), O(Δθ²) in θ. Per row the error is
/// ∫ g − g(cos θ_c) Δz with cos θ_c ≠ the z-interval's midpoint by cos θ_c (1 − cos(Δθ/2)),
/// i.e. about |g'| Δθ²/8 = 1.9e-5 |g'| at H = 256, relative to the coefficients' size.
/// The measured worst error is 1.3e-5 of the largest coefficient (on L22); tolerance 5e-5.
#[test]
fn sh_projection_round_trip() {
    let mut rng = Rng::new(1);
    let sh = rng.sh();
    let map = EnvironmentMap::from_sh(&sh, 512, 256);
    let back = Sh9::project(&map);
    let scale = sh
        .coeffs
        .iter()
        .map(|c| c.abs().max_element())
        .fold(0.0, f64::max);
    for k in 0..9 {
        assert_close(
            back.coeffs[k],
            sh.coeffs[k],
            5e-5,
            scale,
            &format!("L[{k}]"),
        );
    }
}

/// The projection sees the radiance the renderer sees: scale multiplies, rotation turns the
/// function (checked by evaluating the projected SH at the rotated direction).
#[test]
fn sh_projection_applies_scale_and_rotation() {
    let mut rng = Rng::new(2);
    let sh = rng.sh();
    let map = EnvironmentMap::from_sh(&sh, 256, 128);
    let plain = Sh9::project(&map);
    let scaled = Sh9::project(&map.clone().with_scale(2.5));
    for k in 0..9 {
        assert_close(
            scaled.coeffs[k],
            plain.coeffs[k] * 2.5,
            1e-14,
            10.0,
            "scale",
        );
    }
    let rotated = Sh9::project(&map.clone().with_rotation(70.0));
    let r = DMat3::from_rotation_y(70f64.to_radians());
    for _ in 0..20 {
        let d = rng.unit();
        // The projection's error is all in θ (it is exact in φ), and a rotation about +y only
        // shifts φ: the two projections agree to rounding (measured 2e-15 of 5).
        assert_close(rotated.eval(r * d), plain.eval(d), 1e-12, 5.0, "rotation");
    }
}

/// Eq. 7 against the brute integral of L(ω) max(0, n·ω) over the hemisphere about n, for the
/// band-limited L. L·(n·ω) is a polynomial of degree 3 in ω; in (cos θ, φ) about n the odd
/// powers of sin θ come with odd trigonometric factors, which the 8-point trapezoid rule in φ
/// integrates to exactly zero, and 8-point Gauss–Legendre in cos θ is exact for the rest.
/// So the oracle is exact up to rounding: tolerance 1e-12 of the size of E (≈ 10).
#[test]
fn irradiance_matches_hemisphere_quadrature() {
    let mut rng = Rng::new(3);
    let gl = gauss_legendre(8);
    for _ in 0..10 {
        let sh = rng.sh();
        let frame = rng.rotation();
        let n = frame.z_axis;
        let mut brute = DVec3::ZERO;
        let nphi = 8;
        for &(z, wz) in &gl {
            let r = (1.0 - z * z).sqrt();
            for k in 0..nphi {
                let phi = 2.0 * PI * (k as f64 + 0.37) / nphi as f64;
                let w = frame * DVec3::new(r * phi.cos(), r * phi.sin(), z);
                brute += sh.eval(w) * (z * wz * 2.0 * PI / nphi as f64);
            }
        }
        assert_close(sh.irradiance(n), brute, 1e-12, 10.0, "irradiance");
    }
}

/// The quadratic form is the same function as Eq. 8, in world and in a random local frame
/// (only rounding differs: 1e-12 of coefficients of size ≈ 4).
#[test]
fn quadratic_matches_eval_world_and_local() {
    let mut rng = Rng::new(4);
    for _ in 0..10 {
        let sh = rng.sh();
        let world_to_local = rng.rotation();
        let q = sh.quadratic();
        let local = sh.local_quadratic(world_to_local);
        for _ in 0..20 {
            let d = rng.unit();
            assert_close(q.eval(d), sh.eval(d), 1e-12, 1.0, "world");
            assert_close(
                local.eval(world_to_local * d),
                sh.eval(d),
                1e-12,
                1.0,
                "local",
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The polygon integral.

/// Checks one configuration against the fan quadrature. The oracle's error is that of 24×24
/// Gauss–Legendre on analytic integrands over triangles with 0.25 rad bases, at rounding
/// level; the closed form's is rounding. Measured worst disagreement: 1.4e-15 absolute on
/// results of size ≈ 1–10. Tolerance 2e-12 absolute (1e-13 × 20).
fn check_polygon(sh: &Sh9, world_to_local: DMat3, loops: &[Vec<DVec3>], what: &str) {
    let got = closed_form(sh, world_to_local, loops);
    let want = oracle(sh, world_to_local, loops);
    assert!(got.is_finite(), "{what}: {got}");
    assert_close(got, want, 1e-13, 20.0, what);
}

#[test]
fn polygon_integral_matches_quadrature_convex_and_nonconvex() {
    let mut rng = Rng::new(5);
    for case in 0..40 {
        let sh = rng.sh();
        let frame = rng.rotation();
        // Centres high enough and radii small enough that every vertex stays above the horizon.
        let centre = above(rng.range(0.9, 1.5), rng.range(0.0, 2.0 * PI));
        let n = 3 + case % 9;
        let convex = case % 2 == 0;
        let (r0, r1) = if convex { (0.5, 0.5) } else { (0.1, 0.6) };
        let p = star(&mut rng, centre, n, r0, r1, true);
        assert!(p.iter().all(|v| v.z > 0.0));
        check_polygon(
            &sh,
            frame,
            &[p],
            &format!("case {case} convex {convex} n {n}"),
        );
    }
}

#[test]
fn polygon_integral_matches_quadrature_around_the_normal_and_on_the_horizon() {
    let mut rng = Rng::new(6);
    for case in 0..20 {
        let sh = rng.sh();
        let frame = rng.rotation();
        // Star about N with vertices down to (and on) the horizon: contains N, long edges.
        let n = 3 + case % 6;
        let p: Vec<DVec3> = (0..n)
            .map(|k| {
                let az = 2.0 * PI * (k as f64 + rng.range(-0.2, 0.2)) / n as f64;
                let el = if k % 2 == 0 {
                    0.0
                } else {
                    rng.range(0.05, 1.2)
                };
                above(el, az)
            })
            .collect();
        check_polygon(&sh, frame, &[p], &format!("around N, case {case}"));
    }
}

#[test]
fn polygon_integral_matches_quadrature_with_holes_touching_and_crossing() {
    let mut rng = Rng::new(7);
    for case in 0..10 {
        let sh = rng.sh();
        let frame = rng.rotation();
        let c = above(rng.range(0.9, 1.3), rng.range(0.0, 2.0 * PI));
        let outer = star(&mut rng, c, 7, 0.5, 0.6, true);
        let hole = star(&mut rng, c, 5, 0.1, 0.3, false);
        check_polygon(&sh, frame, &[outer.clone(), hole], "hole");

        // Two triangles touching at a vertex.
        let apex = above(0.8, 0.3);
        let t1 = vec![apex, above(0.3, 0.0), above(0.3, 0.4)];
        let t2 = vec![apex, above(1.3, 2.0), above(1.3, -1.0)];
        check_polygon(&sh, frame, &[t1, t2], "touching");

        // A bowtie (self-crossing): the two lobes have opposite orientation.
        let bowtie = vec![
            above(0.3, 0.0),
            above(1.2, 1.5),
            above(1.2, 0.0),
            above(0.3, 1.5),
        ];
        check_polygon(&sh, frame, &[bowtie], "bowtie");

        // Two overlapping loops: the overlap counts twice.
        let c2 = above(1.1, rng.range(0.0, 6.0));
        let other = star(&mut rng, c2, 6, 0.2, 0.5, true);
        check_polygon(&sh, frame, &[outer, other], "overlap");
        let _ = case;
    }
}

/// The four horizon points of the frame, as one loop, are the whole hemisphere: the result
/// is the unshadowed irradiance of Eq. 7 (to rounding, 1e-12). Also with three horizon
/// points, 2π/3 apart: every arc is longer than π/2 and is split.
#[test]
fn horizon_loop_gives_unshadowed_irradiance() {
    let mut rng = Rng::new(8);
    for _ in 0..10 {
        let sh = rng.sh();
        let frame = rng.rotation();
        let (x, y, n) = (frame.x_axis, frame.y_axis, frame.z_axis);
        let square = [x, y, -x, -y];
        let m = PolygonMoments::of_loops([&square[..]], n);
        assert!(
            (m.omega - 2.0 * PI).abs() < 1e-13,
            "solid angle {}",
            m.omega
        );
        let e = cosine_weighted_integral(&sh.quadratic(), &m, n);
        assert_close(e, sh.irradiance(n), 1e-12, 10.0, "four horizon points");

        let tri: Vec<DVec3> = (0..3)
            .map(|k| frame * above(0.0, 2.0 * PI * k as f64 / 3.0))
            .collect();
        let m = PolygonMoments::of_loops([tri.as_slice()], n);
        let e = cosine_weighted_integral(&sh.quadratic(), &m, n);
        assert_close(e, sh.irradiance(n), 1e-12, 10.0, "three horizon points");

        // The renderer's path: local frame, N = z.
        let local = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
        let m = PolygonMoments::of_loops([&local[..]], DVec3::Z);
        let e = cosine_weighted_integral_local(&sh.local_quadratic(frame.transpose()), &m);
        assert_close(e, sh.irradiance(n), 1e-12, 10.0, "local frame");
    }
}

/// A horizon arc of 3 rad (longer than π/2, split once): the triangle (N, A, B) with A, B on
/// the horizon against the quadrature.
#[test]
fn long_horizon_arc() {
    let mut rng = Rng::new(9);
    let sh = rng.sh();
    let frame = rng.rotation();
    let p = vec![DVec3::Z, above(0.0, 0.2), above(0.0, 3.2)];
    check_polygon(&sh, frame, &[p], "3 rad horizon arc");
    let p = vec![above(0.5, 1.0), above(0.0, -0.5), above(0.0, 2.5)];
    check_polygon(&sh, frame, &[p], "3 rad horizon arc, apex off N");
}

/// Exact identities: a vertex inserted mid-arc changes nothing, reversing the loop flips the
/// sign, and rotating polygon, N and radiance together changes nothing (rounding: 1e-13).
#[test]
fn polygon_integral_identities() {
    let mut rng = Rng::new(10);
    for _ in 0..20 {
        let sh = rng.sh();
        let frame = rng.rotation();
        let c = above(rng.range(0.9, 1.4), rng.range(0.0, 2.0 * PI));
        let p = star(&mut rng, c, 6, 0.1, 0.6, true);
        let e = closed_form(&sh, frame, std::slice::from_ref(&p));

        let mut split = p.clone();
        let mid = (p[2] + p[3]).normalize();
        split.insert(3, mid);
        assert_close(
            closed_form(&sh, frame, &[split]),
            e,
            1e-13,
            10.0,
            "mid-arc vertex",
        );

        let mut rev = p.clone();
        rev.reverse();
        assert_close(closed_form(&sh, frame, &[rev]), -e, 1e-13, 10.0, "reversed");

        // Rotate the local polygon and N by R and the radiance with them (b → Rb, M → RMRᵀ).
        let r = rng.rotation();
        let rotated: Vec<DVec3> = p.iter().map(|&v| r * v).collect();
        let n = r * DVec3::Z;
        let m = PolygonMoments::of_loops([rotated.as_slice()], n);
        let q = sh.local_quadratic(frame).in_frame(r);
        assert_close(
            cosine_weighted_integral(&q, &m, n),
            e,
            1e-13,
            10.0,
            "rotated",
        );
    }
}

/// Many edges of 1e-9 rad: each vertex of a hexagon replaced by a zig-zag chain of 100
/// vertices within 1e-9 rad of it, starting and ending at it. The long edges are unchanged and
/// the zig-zags enclose ~1e-18 sr, so the result must agree with the plain hexagon to the
/// rounding of a 600-term sum (relative 1e-12), with no NaN.
#[test]
fn tiny_edges_change_nothing() {
    let mut rng = Rng::new(11);
    let sh = rng.sh();
    let frame = rng.rotation();
    let c = above(1.2, 0.4);
    let p = star(&mut rng, c, 6, 0.3, 0.6, true);
    let mut tiny = Vec::new();
    for &v in &p {
        let t1 = v.any_orthonormal_vector();
        let t2 = v.cross(t1);
        tiny.push(v);
        for k in 1..99 {
            let jitter = if k % 2 == 0 { 1e-9 } else { -1e-9 };
            tiny.push((v + (k as f64 * 1e-11) * t1 + jitter * t2).normalize());
        }
        tiny.push(v);
    }
    let e = closed_form(&sh, frame, std::slice::from_ref(&p));
    let e_tiny = closed_form(&sh, frame, &[tiny]);
    assert!(e_tiny.is_finite());
    assert_close(e_tiny, e, 1e-12, e.abs().max_element(), "tiny edges");
    // A lone edge of 1e-9 rad and the degenerate ones contribute (almost) nothing, not NaN.
    let mut m = PolygonMoments::ZERO;
    let a = above(0.7, 0.1);
    m.accumulate_edge(a, a, DVec3::Z);
    assert_eq!(m, PolygonMoments::ZERO);
    m.accumulate_edge(
        a,
        (a + 1e-9 * a.any_orthonormal_vector()).normalize(),
        DVec3::Z,
    );
    assert!(m.tau1.is_finite() && m.g1.is_finite() && m.g2.is_finite() && m.omega.is_finite());
}

// ---------------------------------------------------------------------------------------------
// The map.

#[test]
fn map_convention() {
    let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-15;
    assert!(close(EnvironmentMap::direction_at(0.25, 0.5), DVec3::X));
    assert!(close(EnvironmentMap::direction_at(0.5, 0.5), DVec3::Z));
    assert!(close(EnvironmentMap::direction_at(0.0, 0.5), -DVec3::Z));
    assert!(close(EnvironmentMap::direction_at(0.75, 0.5), -DVec3::X));
    assert!(close(EnvironmentMap::direction_at(0.3, 0.0), DVec3::Y));
    assert!(close(EnvironmentMap::direction_at(0.3, 1.0), -DVec3::Y));

    let map = EnvironmentMap::sky(16, 8);
    // Row 0 is near +y, the last row near −y.
    assert!(map.direction(3, 0).y > 0.9 && map.direction(3, 7).y < -0.9);
    // Pixel centres: θ = π(j + ½)/H, φ = 2π(i + ½)/W.
    let d = map.direction(5, 2);
    let (theta, phi) = (PI * 2.5 / 8.0, 2.0 * PI * 5.5 / 16.0);
    let want = DVec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    );
    assert!(close(d, want));
    assert_eq!(map.pixel_of(DVec3::X), (4, 4));
    assert_eq!(map.pixel_of(-DVec3::Z), (0, 4));
    assert_eq!(map.pixel_of(DVec3::Z), (8, 4));

    for (w, h) in [(16, 8), (7, 5), (256, 128), (1, 1)] {
        let map = EnvironmentMap::sky(w, h);
        for j in 0..h {
            for i in 0..w {
                assert_eq!(map.pixel_of(map.direction(i, j)), (i, j), "{w}x{h}");
            }
        }
        let total: f64 = (0..h).map(|j| map.solid_angle(j) * w as f64).sum();
        assert!((total - 4.0 * PI).abs() < 1e-12, "{w}x{h}: {total}");
    }
}

/// rotate_deg = 90 moves what the map shows at +x to −z (and +z to +x); scale multiplies.
/// The probes sit just inside the pixels below and after +x and +z (whose corners those
/// directions are on an 8×4 map), away from pixel edges.
#[test]
fn map_rotation_and_scale() {
    let (w, h) = (8, 4);
    let mut px = vec![DVec3::ZERO; w * h];
    let probe = EnvironmentMap::new(w, h, px.clone()).unwrap();
    let near_x = DVec3::new(1.0, -0.05, 0.05).normalize();
    let near_z = DVec3::new(-0.05, -0.05, 1.0).normalize();
    let (i, j) = probe.pixel_of(near_x);
    assert_eq!((i, j), (2, 2));
    px[j * w + i] = DVec3::new(1.0, 2.0, 3.0);
    let (i, j) = probe.pixel_of(near_z);
    assert_eq!((i, j), (4, 2));
    px[j * w + i] = DVec3::new(5.0, 0.0, 0.0);
    let map = EnvironmentMap::new(w, h, px)
        .unwrap()
        .with_rotation(90.0)
        .with_scale(2.0);
    // Turning near_x by +90° about +y: (x, y, z) → (z, y, −x).
    let turn = |d: DVec3| DVec3::new(d.z, d.y, -d.x);
    assert!(turn(DVec3::X).abs_diff_eq(-DVec3::Z, 0.0));
    assert_eq!(map.radiance(turn(near_x)), DVec3::new(2.0, 4.0, 6.0));
    assert_eq!(map.radiance(turn(near_z)), DVec3::new(10.0, 0.0, 0.0));
    assert_eq!(map.radiance(near_z), DVec3::ZERO);
}

#[test]
fn sky_is_finite_sunny_and_darker_below() {
    let sky = EnvironmentMap::sky(256, 128);
    assert!(
        sky.pixels()
            .iter()
            .all(|p| p.is_finite() && p.min_element() > 0.0)
    );
    assert_eq!(sky, EnvironmentMap::sky(256, 128));
    let brightest = sky.pixels().iter().map(|p| p.y).fold(0.0, f64::max);
    let zenith = sky.pixel(0, 0).y;
    let ground = sky.pixel(0, 127).y;
    assert!(brightest > 20.0 * zenith, "a sun: {brightest} vs {zenith}");
    assert!(ground < 0.5 * zenith, "darker ground: {ground} vs {zenith}");
    // The sun is a lobe, not a delta: more than a handful of pixels are lit by it.
    let lit = sky.pixels().iter().filter(|p| p.y > 5.0 * zenith).count();
    assert!(lit > 10, "{lit} sun pixels");
}

// ---------------------------------------------------------------------------------------------
// Importance sampling.

/// Σ pdf ΔΩ over all pixels is 1, and the pdf of a sample is what `pdf` says.
#[test]
fn sampler_pdf_is_normalised_and_consistent() {
    let map = EnvironmentMap::sky(64, 32)
        .with_rotation(30.0)
        .with_scale(2.0);
    let sampler = EnvironmentSampler::new(&map);
    let mut total = 0.0;
    for j in 0..32 {
        for i in 0..64 {
            let d = map.rotation() * map.direction(i, j);
            let pdf = sampler.pdf(d);
            assert!(pdf > 0.0);
            total += pdf * map.solid_angle(j);
        }
    }
    assert!((total - 1.0).abs() < 1e-12, "{total}");
    let mut rng = Rng::new(12);
    for _ in 0..1000 {
        let (d, l, pdf) = sampler.sample(rng.next_f64(), rng.next_f64());
        assert!((d.length() - 1.0).abs() < 1e-12);
        assert!(
            (sampler.pdf(d) - pdf).abs() <= 1e-9 * pdf,
            "{} vs {pdf}",
            sampler.pdf(d)
        );
        assert_eq!(l, map.radiance(d));
    }
}

/// The MC estimate of ∫ L(ω) max(0, n·ω) dω with the sampler matches the integral within
/// 5 standard errors. For n = +y (invariant under the map's rotation) the oracle is exact:
/// ∫_pixel max(0, cos θ) dω = (2π/W)(cos²θ_top − cos²θ_bottom)/2 for rows above the horizon.
/// For a tilted n the oracle is a 16×16 midpoint rule inside every pixel, whose error
/// (≈ 1e-6 relative) is far below the MC standard error (≈ 1e-3).
#[test]
fn sampler_monte_carlo_matches_pixel_sum() {
    let (w, h) = (64, 32);
    let map = EnvironmentMap::sky(w, h)
        .with_rotation(30.0)
        .with_scale(2.0);
    let sampler = EnvironmentSampler::new(&map);

    let mut exact_up = DVec3::ZERO;
    for j in 0..h / 2 {
        let ct = (PI * j as f64 / h as f64).cos();
        let cb = (PI * (j + 1) as f64 / h as f64).cos();
        let weight = 2.0 * PI / w as f64 * 0.5 * (ct * ct - cb * cb);
        for i in 0..w {
            exact_up += map.scale * map.pixel(i, j) * weight;
        }
    }
    let n_tilted = DVec3::new(0.6, 0.3, -0.4).normalize();
    let sub = 16;
    let mut fine_tilted = DVec3::ZERO;
    let to_world = map.rotation();
    for j in 0..h * sub {
        let ct = (PI * j as f64 / (h * sub) as f64).cos();
        let cb = (PI * (j + 1) as f64 / (h * sub) as f64).cos();
        let dw = 2.0 * PI / (w * sub) as f64 * (ct - cb);
        for i in 0..w * sub {
            let d = EnvironmentMap::direction_at(
                (i as f64 + 0.5) / (w * sub) as f64,
                (j as f64 + 0.5) / (h * sub) as f64,
            );
            let cos = n_tilted.dot(to_world * d).max(0.0);
            fine_tilted += map.scale * map.pixel(i / sub, j / sub) * (cos * dw);
        }
    }

    let mut rng = Rng::new(13);
    for (n, want) in [(DVec3::Y, exact_up), (n_tilted, fine_tilted)] {
        let count = 200_000;
        let (mut sum, mut sum_sq) = (DVec3::ZERO, DVec3::ZERO);
        for _ in 0..count {
            let (d, l, pdf) = sampler.sample(rng.next_f64(), rng.next_f64());
            let f = l * n.dot(d).max(0.0) / pdf;
            sum += f;
            sum_sq += f * f;
        }
        let mean = sum / count as f64;
        let std_err = ((sum_sq / count as f64 - mean * mean) / count as f64).max(DVec3::ZERO);
        let std_err = DVec3::new(std_err.x.sqrt(), std_err.y.sqrt(), std_err.z.sqrt());
        for c in 0..3 {
            assert!(
                (mean[c] - want[c]).abs() < 5.0 * std_err[c] + 1e-9,
                "n {n}: channel {c}: MC {} ± {} vs {}",
                mean[c],
                std_err[c],
                want[c]
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Files.

#[test]
fn load_hdr_round_trip() {
    let (w, h) = (4u32, 3u32);
    // Values RGBE stores exactly: a shared exponent, 8-bit mantissas (multiples of max/256).
    let px: Vec<[f32; 3]> = (0..w * h)
        .map(|k| {
            let s = (1u32 << (k % 5)) as f32;
            [s, 0.5 * s, 0.25 * s]
        })
        .collect();
    let path = temp("tiny.hdr");
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let rgb: Vec<image::Rgb<f32>> = px.iter().map(|&p| image::Rgb(p)).collect();
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&rgb, w as usize, h as usize)
        .unwrap();
    // From the file, and from its content as the browser hands it over.
    let bytes = std::fs::read(&path).unwrap();
    for map in [
        EnvironmentMap::load(&path).unwrap(),
        EnvironmentMap::from_bytes(&bytes, "dropped.hdr").unwrap(),
    ] {
        assert_eq!((map.width(), map.height()), (w as usize, h as usize));
        for (k, p) in px.iter().enumerate() {
            let want = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            assert_eq!(map.pixels()[k], want, "pixel {k}");
        }
    }
}

#[test]
fn load_exr_round_trip_and_repairs() {
    let (w, h) = (5u32, 2u32);
    let px: Vec<[f32; 3]> = (0..w * h)
        .map(|k| [k as f32 * 0.1, 1.0 + k as f32, 1e-3 * (k as f32 + 1.0)])
        .collect();
    let path = temp("tiny.exr");
    penumbra::raster::io::write_exr(&path, w, h, &px).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    for map in [
        EnvironmentMap::load(&path).unwrap(),
        EnvironmentMap::from_bytes(&bytes, "dropped.exr").unwrap(),
    ] {
        assert_eq!((map.width(), map.height()), (5, 2));
        for (k, p) in px.iter().enumerate() {
            let want = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            assert_eq!(map.pixels()[k], want, "pixel {k}");
        }
    }

    // Negative pixels are clamped to zero (with a warning on stderr).
    let mut neg = px.clone();
    neg[3] = [-1.0, 0.5, -0.0];
    let path = temp("negative.exr");
    penumbra::raster::io::write_exr(&path, w, h, &neg).unwrap();
    let map = EnvironmentMap::load(&path).unwrap();
    assert_eq!(map.pixels()[3], DVec3::new(0.0, 0.5, 0.0));

    // Non-finite pixels are an error naming the file.
    let mut nan = px.clone();
    nan[7] = [f32::NAN, 0.0, 0.0];
    let path = temp("nan.exr");
    penumbra::raster::io::write_exr(&path, w, h, &nan).unwrap();
    let err = format!("{:#}", EnvironmentMap::load(&path).unwrap_err());
    assert!(
        err.contains("nan.exr") && err.contains("not finite"),
        "{err}"
    );
}

#[test]
fn load_errors_name_the_file() {
    for name in ["missing.hdr", "missing.exr"] {
        let path = temp(name);
        let err = format!("{:#}", EnvironmentMap::load(&path).unwrap_err());
        assert!(err.contains(name), "{err}");
    }
    for name in ["corrupt.hdr", "corrupt.exr"] {
        let path = temp(name);
        let corrupt = b"#?RADIANCE\nthis is not an image\n\x00\x01\x02";
        std::fs::write(&path, corrupt).unwrap();
        let err = format!("{:#}", EnvironmentMap::load(&path).unwrap_err());
        assert!(err.contains(name), "{err}");
        let err = format!(
            "{:#}",
            EnvironmentMap::from_bytes(corrupt, name).unwrap_err()
        );
        assert!(err.contains(name), "{err}");
    }
    let path = temp("sky.png");
    std::fs::write(&path, b"not used").unwrap();
    let err = format!("{:#}", EnvironmentMap::load(&path).unwrap_err());
    assert!(
        err.contains("sky.png") && err.contains("unsupported"),
        "{err}"
    );
    assert!(EnvironmentMap::new(0, 4, vec![]).is_err());
}
