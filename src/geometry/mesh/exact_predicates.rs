//! The orientation of four points with an exact sign, for the convex hull (prepare time).
//!
//! `orient3d(a, b, c, d)` is the sign of det[b − a, c − a, d − a]: positive when `d` lies on the
//! side of the plane through `a, b, c` that (b − a) × (c − a) points to. It is evaluated in
//! floating point first and trusted when its magnitude exceeds Shewchuk's forward error bound
//! ("Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997:
//! (7 + 56ε)ε times the permanent); otherwise it is evaluated again exactly, on floating-point
//! expansions (sums of non-overlapping doubles) built from error-free sums and products. The
//! exact path allocates, which is fine where it runs: coplanar points of caps and boxes while a
//! hull is built.

use glam::DVec3;

const EPS: f64 = f64::EPSILON * 0.5;
const O3D_ERRBOUND: f64 = (7.0 + 56.0 * EPS) * EPS;

/// `a + b = s + e` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// `a · b = p + e` exactly (barring underflow), by a fused multiply-add.
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// An exact sum of doubles, smallest magnitude first, non-overlapping.
#[derive(Clone, Debug, Default)]
struct Expansion(Vec<f64>);

impl Expansion {
    fn from_diff(a: f64, b: f64) -> Self {
        let (s, e) = two_sum(a, -b);
        Expansion(vec![e, s])
    }

    /// Shewchuk's Grow-Expansion: adds one double, keeping the terms non-overlapping.
    fn grow(&mut self, b: f64) {
        let mut q = b;
        for h in &mut self.0 {
            let (s, e) = two_sum(q, *h);
            *h = e;
            q = s;
        }
        self.0.push(q);
        self.0.retain(|&x| x != 0.0);
    }

    fn add(&self, other: &Expansion) -> Expansion {
        let mut out = self.clone();
        for &b in &other.0 {
            out.grow(b);
        }
        out
    }

    fn neg(&self) -> Expansion {
        Expansion(self.0.iter().map(|&x| -x).collect())
    }

    fn mul(&self, other: &Expansion) -> Expansion {
        let mut out = Expansion::default();
        for &a in &self.0 {
            for &b in &other.0 {
                let (p, e) = two_product(a, b);
                out.grow(e);
                out.grow(p);
            }
        }
        out
    }

    /// The sign of the sum: that of its largest term, since the terms do not overlap.
    fn sign(&self) -> f64 {
        self.0.last().map_or(0.0, |&x| x.signum())
    }
}

/// The sign (−1, 0 or +1) of det[b − a, c − a, d − a], exact for any finite inputs.
pub(crate) fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let (u, v, w) = (b - a, c - a, d - a);
    let det = u.x * (v.y * w.z - v.z * w.y) - u.y * (v.x * w.z - v.z * w.x)
        + u.z * (v.x * w.y - v.y * w.x);
    let permanent = u.x.abs() * ((v.y * w.z).abs() + (v.z * w.y).abs())
        + u.y.abs() * ((v.x * w.z).abs() + (v.z * w.x).abs())
        + u.z.abs() * ((v.x * w.y).abs() + (v.y * w.x).abs());
    // The differences are rounded too: the bound covers the determinant of rounded
    // differences only, so inputs far from each other's magnitude go to the exact path.
    if det.abs() > O3D_ERRBOUND * permanent * 4.0 {
        return det.signum();
    }
    orient3d_exact(a, b, c, d)
}

#[cold]
fn orient3d_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let diff = |p: DVec3| {
        [
            Expansion::from_diff(p.x, a.x),
            Expansion::from_diff(p.y, a.y),
            Expansion::from_diff(p.z, a.z),
        ]
    };
    let (u, v, w) = (diff(b), diff(c), diff(d));
    let minor = |i: usize, j: usize| v[i].mul(&w[j]).add(&v[j].mul(&w[i]).neg());
    let det = u[0]
        .mul(&minor(1, 2))
        .add(&u[1].mul(&minor(0, 2)).neg())
        .add(&u[2].mul(&minor(0, 1)));
    det.sign()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_sign_on_coplanar_and_nearly_coplanar_points() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        let b = DVec3::new(1.1, 0.2, 0.3);
        let c = DVec3::new(0.1, 1.2, 0.3);
        assert_eq!(orient3d(a, b, c, DVec3::new(0.7, 0.9, 0.3)), 0.0);
        // One ulp above and below the plane z = 0.3.
        let up = DVec3::new(0.7, 0.9, f64::from_bits(0.3f64.to_bits() + 1));
        let down = DVec3::new(0.7, 0.9, f64::from_bits(0.3f64.to_bits() - 1));
        assert_eq!(orient3d(a, b, c, up), 1.0);
        assert_eq!(orient3d(a, b, c, down), -1.0);
        assert_eq!(orient3d(b, a, c, up), -1.0);
    }

    #[test]
    fn agrees_with_integer_arithmetic() {
        // Points on an integer grid scaled by a power of two: the determinant is an exact
        // integer (i128) times a power of two, an independent oracle.
        let mut rng = crate::math::Pcg32::new(7, 1);
        for _ in 0..20_000 {
            let mut p = [[0i64; 3]; 4];
            for q in &mut p {
                for x in q.iter_mut() {
                    // Small range: many exactly coplanar quadruples.
                    *x =
                        (rng.next_u32() % 5) as i64 - 2 + ((rng.next_u32() % 3) as i64) * (1 << 40);
                }
            }
            let f =
                |q: [i64; 3]| DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64) * 2f64.powi(-30);
            let sub = |x: [i64; 3], y: [i64; 3]| {
                [x[0] - y[0], x[1] - y[1], x[2] - y[2]].map(|v| v as i128)
            };
            let (u, v, w) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
            let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]);
            let got = orient3d(f(p[0]), f(p[1]), f(p[2]), f(p[3]));
            assert_eq!(got, det.signum() as f64, "{p:?}");
        }
    }
}
