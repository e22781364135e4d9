//! `form_factor` against an independent oracle: Gauss–Legendre quadrature of `∫ cosθ/π dω`
//! over the *planar* triangle obtained by central projection of the spherical triangle onto
//! a tangent plane `n·p = 1` (`n` a direction inside the triangle), with the Jacobian of the
//! projection `dω = (n·p)/|p|³ dA = dA/(1 + r²)^{3/2}`.
//!
//! The planar integral is taken in polar coordinates `(r, φ)` around the tangent point, one
//! signed wedge per edge:
//! `∫ f dA = Σ_edges ∫_φ ∫_0^{R(φ)} f r dr dφ`, `R(φ)` the distance to the edge's line. The
//! radial substitution `r = tanψ` turns `cosθ/π · (n·p)/|p|³ · r dr` into the entire function
//! `(n.z sinψ cosψ + k(φ) sin²ψ) dψ / π` (`k = t1.z cosφ + t2.z sinφ`), integrated with a
//! 16-point rule on `[0, atan R]`. The angle is parameterised along each edge's line by
//! `s = h sinh u` (`h` the line's distance, `dφ = du/cosh u`) and integrated with an adaptive
//! 16-point rule (bisection, error estimate `|two halves − whole|`). This stays well
//! conditioned for far vertices (`R → ∞`, near-horizon and near-π cases) and for lines close
//! to the tangent point (slivers), where a Cartesian parameterisation of the plane through
//! the vertices has a near-singular integrand. The test tolerance is the oracle's
//! quadrature error estimate plus rounding bounds of both computations.

use crate::ltc_common;

use glam::{DVec2, DVec3};
use ltc_common::gauss_legendre;
use penumbra::ltc::{edge_integral, form_factor};
use penumbra::math::{Frame, Pcg32};
use std::f64::consts::PI;

struct Oracle {
    gl: Vec<(f64, f64)>,
    /// `p.z = tz + x · xz + y · yz` for the plane point `p = x t1 + y t2 + n`.
    xz: f64,
    yz: f64,
    tz: f64,
}

impl Oracle {
    /// `(1/π) ∫_0^{atan r} (tz sinψ cosψ + k sin²ψ) dψ` for direction `u`.
    fn radial(&self, u: DVec2, r: f64) -> f64 {
        let k = self.xz * u.x + self.yz * u.y;
        let psi = r.atan();
        let mut s = 0.0;
        for &(x, w) in &self.gl {
            let (sn, cs) = (psi * x).sin_cos();
            s += w * sn * (self.tz * cs + k * sn);
        }
        s * psi / PI
    }

    /// Wedge of one edge on `u ∈ [u0, u1]` with one 16-point rule. The edge's line is
    /// parameterised by `s = h sinh u` from the foot `F` of the perpendicular from the
    /// tangent point (`h = |F|`), so that `r = h cosh u` and `dφ = du / cosh u`: the integrand
    /// is smooth on the unit scale in `u` whether the line passes close to the tangent point
    /// (small `h`) or the vertex is far away (large `|s|`, the near-horizon and near-π cases).
    fn wedge_rule(&self, e: &Edge, u0: f64, u1: f64) -> f64 {
        let mut sum = 0.0;
        for &(x, w) in &self.gl {
            let u = u0 + (u1 - u0) * x;
            let (sh, ch) = (u.sinh(), u.cosh());
            let dir = (e.f_hat + e.dir * sh) / ch;
            sum += w * self.radial(dir, e.h * ch) / ch;
        }
        sum * (u1 - u0) * e.sign
    }

    fn wedge(&self, e: &Edge, u0: f64, u1: f64, whole: f64, tol: f64, depth: u32) -> (f64, f64) {
        let m = 0.5 * (u0 + u1);
        let (l, r) = (self.wedge_rule(e, u0, m), self.wedge_rule(e, m, u1));
        // `tol` is an absolute tolerance per interval (not split between the halves): the
        // rounding noise of an interval's rule shrinks with its value, so refinement always
        // terminates; the returned error is the sum of the leaves' actual mismatches.
        let err = (l + r - whole).abs();
        if err <= tol || depth == 0 {
            return (l + r, err);
        }
        let (vl, el) = self.wedge(e, u0, m, l, tol, depth - 1);
        let (vr, er) = self.wedge(e, m, u1, r, tol, depth - 1);
        (vl + vr, el + er)
    }
}

/// The line of the planar edge `p → q` seen from the tangent point (the origin).
struct Edge {
    /// Unit direction `(q − p)/|q − p|`, unit foot direction `F/|F|`, distance `h = |F|`.
    dir: DVec2,
    f_hat: DVec2,
    h: f64,
    /// `±1`: orientation of the wedge (sign of `p × q`).
    sign: f64,
    u0: f64,
    u1: f64,
}

impl Edge {
    fn new(p: DVec2, q: DVec2) -> Option<Edge> {
        let dir = (q - p).normalize();
        let foot = p - dir * p.dot(dir);
        let h = foot.length();
        if h.is_nan() || h <= 0.0 {
            return None; // the line passes through the tangent point: an empty wedge
        }
        let f_hat = foot / h;
        Some(Edge {
            dir,
            f_hat,
            h,
            sign: f_hat.perp_dot(dir).signum(),
            u0: (p.dot(dir) / h).asinh(),
            u1: (q.dot(dir) / h).asinh(),
        })
    }
}

/// Oracle value and quadrature error estimate for the spherical triangle `a, b, c` (unit
/// vectors, counter-clockwise seen from outside). Refinement stops at `rel_tol` relative to
/// the value or at `abs_tol` (set well below the rounding bounds, which bound the achievable
/// agreement anyway).
fn oracle(a: DVec3, b: DVec3, c: DVec3, rel_tol: f64, abs_tol: f64) -> (f64, f64) {
    // Tangent point: the centroid direction (inside, all wedges positive) if every vertex
    // projects at a moderate distance; otherwise (triangles spanning most of the hemisphere)
    // the normal of the plane through the vertices (the circumcentre, a·n = b·n = c·n > 0),
    // which may lie outside the triangle: then some wedges are negative (the fan
    // decomposition holds for any centre, but a far-outside centre would cancel digits).
    let centroid = (a + b + c).normalize();
    let n = if [a, b, c].iter().all(|v| v.dot(centroid) > 1e-3) {
        centroid
    } else {
        (b - a).cross(c - a).normalize()
    };
    let f = Frame::from_z(n);
    let loc = |v: DVec3| {
        let s = 1.0 / v.dot(n);
        assert!(s > 0.0);
        DVec2::new(v.dot(f.x) * s, v.dot(f.y) * s)
    };
    let o = Oracle {
        gl: gauss_legendre(16),
        xz: f.x.z,
        yz: f.y.z,
        tz: n.z,
    };
    let pts = [loc(a), loc(b), loc(c)];
    let edges: Vec<Edge> = (0..3)
        .filter_map(|k| Edge::new(pts[k], pts[(k + 1) % 3]))
        .collect();
    let wholes: Vec<f64> = edges.iter().map(|e| o.wedge_rule(e, e.u0, e.u1)).collect();
    let tol = (rel_tol * wholes.iter().sum::<f64>().abs()).max(abs_tol);
    let (mut val, mut err) = (0.0, 0.0);
    for (e, &whole) in edges.iter().zip(&wholes) {
        let (v, de) = o.wedge(e, e.u0, e.u1, whole, tol, 60);
        val += v;
        err += de;
    }
    (val, err)
}

/// Rounding error bound of the oracle. Its vertex coordinates in the tangent plane carry
/// rounding equivalent to moving each vertex by a few ε (radians), which changes the
/// integral by at most `2ε · perimeter · max(cos/π)`; evaluating `p.z` cancels near the
/// horizon with an absolute error ~`2ε` per unit density, i.e. `≤ 4εΩ/π` in total.
fn oracle_rounding(t: &[DVec3; 3]) -> f64 {
    let perimeter: f64 = (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            a.cross(b).length().atan2(a.dot(b))
        })
        .sum();
    let omega = 2.0
        * t[0]
            .dot(t[1].cross(t[2]))
            .atan2(1.0 + t[0].dot(t[1]) + t[1].dot(t[2]) + t[2].dot(t[0]));
    4.0 * f64::EPSILON * (perimeter + omega.abs()) / PI
}

/// Rounding bound of the closed form. Each component of `w = ½ (a + b) × (b − a)` is a
/// difference of two products and carries an absolute error of up to `3ε|b − a|` (for unit
/// `a`, `b`; not relative to `|w|`),
/// which the factor `θ/|w| >= 1` carries into the edge term; the remaining operations (sqrt,
/// atan2, division, the sum) add a few ulp relative to each term.
fn rounding_bound(poly: &[DVec3]) -> f64 {
    let mut b = 0.0;
    for k in 0..poly.len() {
        let (a, c) = (poly[k], poly[(k + 1) % poly.len()]);
        let w = a.cross(c);
        let theta_over_s = w.length().atan2(a.dot(c)) / w.length();
        b += 3.0 * f64::EPSILON * (c - a).length() * theta_over_s
            + 8.0 * f64::EPSILON * edge_integral(a, c).abs();
    }
    b / (2.0 * PI)
}

fn orient_ccw(mut t: [DVec3; 3]) -> [DVec3; 3] {
    if t[0].dot(t[1].cross(t[2])) < 0.0 {
        t.swap(1, 2);
    }
    t
}

fn upper(rng: &mut Pcg32) -> DVec3 {
    let v = rng.unit_vector();
    DVec3::new(v.x, v.y, v.z.abs())
}

/// Direction at polar angle `theta`, azimuth `phi`.
fn dir(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

fn check(name: &str, tri: [DVec3; 3], worst: &mut f64) {
    let tri = orient_ccw(tri.map(|v| v.normalize()));
    let rounding = rounding_bound(&tri) + oracle_rounding(&tri);
    let (val, qerr) = oracle(tri[0], tri[1], tri[2], 1e-13, 1e-3 * rounding);
    let got = form_factor([tri.as_slice()]);
    let tol = qerr + rounding + 4.0 * f64::EPSILON * val.abs();
    let diff = (got - val).abs();
    if val.abs() > tol {
        *worst = worst.max(diff / val.abs());
    }
    assert!(
        diff <= tol,
        "{name}: form_factor {got:e} vs oracle {val:e} ± {qerr:e} (diff {diff:e}, tol {tol:e}) for {tri:?}"
    );
    assert!(
        got > 0.0 || val <= tol,
        "{name}: counter-clockwise triangle must be positive"
    );
    // Exact antisymmetry of edge_integral: the reversed loop gives exactly −got up to the
    // order of summation.
    let rev = [tri[0], tri[2], tri[1]];
    let terms: f64 = (0..3)
        .map(|k| edge_integral(tri[k], tri[(k + 1) % 3]).abs())
        .sum();
    assert!((form_factor([rev.as_slice()]) + got).abs() <= 4.0 * f64::EPSILON * terms);
}

#[test]
fn ltc_random_triangles_in_upper_hemisphere() {
    let mut rng = Pcg32::new(2024, 1);
    let mut worst = 0.0f64;
    let mut count = 0;
    while count < 300 {
        let t = [upper(&mut rng), upper(&mut rng), upper(&mut rng)];
        if t[0].dot(t[1].cross(t[2])).abs() < 1e-3 {
            continue; // nearly degenerate: covered by the dedicated cases below
        }
        check("random", t, &mut worst);
        count += 1;
    }
    println!("random triangles: max relative deviation {worst:.2e}");
}

#[test]
fn ltc_tiny_and_thin_triangles() {
    let mut rng = Pcg32::new(77, 2);
    let mut worst = 0.0f64;
    for &size in &[1e-2, 1e-4, 1e-6] {
        for _ in 0..40 {
            let c = upper(&mut rng);
            if c.z < 0.05 {
                continue;
            }
            let f = penumbra::math::Frame::from_z(c);
            let p = |x: f64, y: f64| c + size * (x * f.x + y * f.y);
            // Roughly equilateral tiny triangle.
            check(
                "tiny",
                [p(1.0, 0.0), p(-0.5, 0.8), p(-0.5, -0.8)],
                &mut worst,
            );
            // Sliver: aspect ratio 1000.
            check(
                "thin",
                [p(-1.0, 0.0), p(1.0, 0.0), p(0.1, 2e-3)],
                &mut worst,
            );
        }
    }
    // Long thin slivers (large arcs, tiny width).
    for _ in 0..40 {
        let a = upper(&mut rng);
        let b = upper(&mut rng);
        let m = (a + b).normalize();
        let off = a.cross(b).normalize();
        check(
            "long sliver",
            [a, b, (m + 1e-4 * off).normalize()],
            &mut worst,
        );
    }
    println!("tiny/thin triangles: max relative deviation {worst:.2e}");
}

#[test]
fn ltc_near_horizon_and_near_pi_edges() {
    let mut rng = Pcg32::new(5, 5);
    let mut worst = 0.0f64;
    for &eps in &[1e-3, 1e-6, 1e-9] {
        for _ in 0..20 {
            // All three vertices just above the horizon.
            let t = [0, 1, 2].map(|_| {
                dir(
                    std::f64::consts::FRAC_PI_2 - eps * rng.range(0.5, 1.0),
                    rng.range(0.0, std::f64::consts::TAU),
                )
            });
            if t[0].dot(t[1].cross(t[2])).abs() < 1e-12 {
                continue;
            }
            check("near horizon", t, &mut worst);
            // Two near-horizon vertices and one high up.
            let phi = rng.range(0.0, std::f64::consts::TAU);
            let t = [
                dir(std::f64::consts::FRAC_PI_2 - eps, phi),
                dir(std::f64::consts::FRAC_PI_2 - eps, phi + rng.range(0.1, 2.5)),
                dir(rng.range(0.0, 1.2), phi + rng.range(-3.0, 3.0)),
            ];
            check("horizon base", t, &mut worst);
        }
    }
    // Edges of length π − δ: nearly antipodal vertices just above the horizon.
    for &delta in &[1e-1, 1e-2, 1e-3] {
        for _ in 0..10 {
            let phi = rng.range(0.0, std::f64::consts::TAU);
            let a = dir(std::f64::consts::FRAC_PI_2 - delta * 0.3, phi);
            let b = dir(std::f64::consts::FRAC_PI_2 - delta * 0.3, phi + PI - delta);
            let c = dir(rng.range(0.0, 1.4), phi + rng.range(0.2, 3.0));
            let arc = a.dot(b).clamp(-1.0, 1.0).acos();
            assert!(arc > PI - 2.0 * delta);
            check("near-pi edge", [a, b, c], &mut worst);
        }
    }
    println!("near-horizon / near-pi triangles: max relative deviation {worst:.2e}");
}

#[test]
fn ltc_loops_with_holes_and_reference_values() {
    // Octant minus a small clockwise triangle inside it.
    let outer = [DVec3::X, DVec3::Y, DVec3::Z];
    let inner_ccw = orient_ccw([
        DVec3::new(0.5, 0.4, 0.6).normalize(),
        DVec3::new(0.4, 0.5, 0.6).normalize(),
        DVec3::new(0.45, 0.45, 0.8).normalize(),
    ]);
    let inner_cw = [inner_ccw[0], inner_ccw[2], inner_ccw[1]];
    let (hole, herr) = oracle(inner_ccw[0], inner_ccw[1], inner_ccw[2], 1e-13, 0.0);
    let got = form_factor([outer.as_slice(), inner_cw.as_slice()]);
    assert!(
        (got - (0.25 - hole)).abs()
            <= herr + oracle_rounding(&inner_ccw) + rounding_bound(&inner_ccw) + 1e-16,
        "{got} vs {}",
        0.25 - hole
    );
    // Disk of angular radius β around the normal: ∫ cos/π = sin²β; as a 4096-gon the
    // inscribed polygon's value converges to it.
    let beta: f64 = 0.7;
    let n = 4096;
    let ring: Vec<DVec3> = (0..n)
        .map(|k| dir(beta, std::f64::consts::TAU * k as f64 / n as f64))
        .collect();
    let got = form_factor([ring.as_slice()]);
    assert!((got - beta.sin().powi(2)).abs() < 2e-6, "{got}");
    // Degenerate input.
    assert_eq!(form_factor(std::iter::empty::<&[DVec3]>()), 0.0);
    let two = [DVec3::X, DVec3::Y];
    assert_eq!(form_factor([two.as_slice()]), 0.0);
}
