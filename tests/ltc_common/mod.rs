//! Shared helpers of the LTC integration tests: Gauss–Legendre rules, a horizon clip for
//! convex loops, spherical point-in-polygon, chi-square critical values.
#![allow(dead_code)]

use glam::DVec3;

/// `n`-point Gauss–Legendre rule on `[0, 1]` (nodes by Newton on `P_n`, Golub–Welsch-free).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 1..=n {
        let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 - x), 0.5 * w));
    }
    out
}

/// `∫_a^b f` with the rule `gl` (from [`gauss_legendre`]).
pub fn gl_1d(gl: &[(f64, f64)], a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let h = b - a;
    gl.iter().map(|&(x, w)| w * f(a + h * x)).sum::<f64>() * h
}

/// Sutherland–Hodgman clip of a convex spherical loop to `z >= 0`; the crossing point of the
/// arc `a → b` is `(−b.z) a + a.z b` (positive combination, z = 0).
pub fn clip_convex_to_horizon(poly: &[DVec3]) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for k in 0..poly.len() {
        let a = poly[k];
        let b = poly[(k + 1) % poly.len()];
        if a.z >= 0.0 {
            out.push(a);
        }
        if (a.z >= 0.0) != (b.z >= 0.0) {
            let p = a * (-b.z) + b * a.z;
            let p = if a.z >= 0.0 { p } else { -p };
            out.push(DVec3::new(p.x, p.y, 0.0).normalize());
        }
    }
    out
}

/// Is `l` inside the convex spherical polygon `poly` (counter-clockwise from outside)?
#[inline]
pub fn inside_convex(poly: &[DVec3], l: DVec3) -> bool {
    let n = poly.len();
    (0..n).all(|k| poly[k].cross(poly[(k + 1) % n]).dot(l) >= 0.0)
}

/// Upper critical value of χ² with `df` degrees of freedom for the standard normal quantile
/// `z` (Wilson–Hilferty; accurate to < 1 % for df > 30).
pub fn chi2_critical(df: f64, z: f64) -> f64 {
    let k = 2.0 / (9.0 * df);
    df * (1.0 - k + z * k.sqrt()).powi(3)
}

/// Two-sided 99.9 % standard normal quantile.
pub const Z999: f64 = 3.290_526_731_491_926;
