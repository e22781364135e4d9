//! The cosine-weighted integral of a 3-band SH radiance over a spherical polygon,
//! ∫_P L(ω) (N·ω) dω, in closed form (`/work/shared/notes/sh-polygon-integrals.md`, after
//! Arvo 1995). This is E^occluded of Eq. 3 of paper 002 when P is the occluded part of the
//! hemisphere, computed exactly instead of with the paper's ray samples.
//!
//! The geometry enters through 13 numbers ([`PolygonMoments`]) shared by the three colour
//! channels; the radiance through its quadratic form ([`super::sh::ShQuadratic`]).

use glam::{DMat3, DVec3};

use super::sh::{Quadratic, ShQuadratic};

/// Below this sine of an edge's arc, γ/s comes from its series 1 + s²/6: the next term,
/// 3s⁴/40, is under 1e-17 there, while atan2(s, co)/s loses digits for tiny s.
const TINY_SINE: f64 = 1e-4;
/// Below this arc length β = (γ − s·co)/2 comes from its series: the direct form cancels
/// catastrophically (β ~ γ³/3), the series' truncation error is about γ⁹/1000 < 1e-21.
const SMALL_ARC: f64 = 1e-2;

/// The polygon's moments for one normal N, accumulated edge by edge (per edge (A, B) of a
/// loop, cr = A×B, s = |cr|, co = A·B, γ = atan2(s, co), u = B − co·A):
///
/// * `tau1` = ∫_P ω dω = Σ ½ (γ/s) cr
/// * `g1` = Σ (N·cr) (A + u/(1 + co))
/// * `g2` = Σ (N·cr) [((γ/s + co)/2) AAᵀ + (β/s³) uuᵀ + ½(Auᵀ + uAᵀ)], β = (γ − s·co)/2
/// * `omega` = the signed solid angle, Σ 2 atan2(N·cr, 1 + N·A + co + N·B) (a fan from N)
///
/// All four are additive over edges and loops: counter-clockwise loops seen from outside
/// count positively, clockwise ones (holes) negatively.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolygonMoments {
    pub tau1: DVec3,
    pub g1: DVec3,
    pub g2: DMat3,
    pub omega: f64,
}

impl Default for PolygonMoments {
    fn default() -> Self {
        Self::ZERO
    }
}

impl PolygonMoments {
    /// The moments of the empty polygon.
    pub const ZERO: PolygonMoments = PolygonMoments {
        tau1: DVec3::ZERO,
        g1: DVec3::ZERO,
        g2: DMat3::ZERO,
        omega: 0.0,
    };

    /// Adds the great arc from `a` to `b` (the shorter one) for the normal `n`.
    ///
    /// `a`, `b`, `n` must be unit vectors; they are not normalised here (a rounding error of
    /// the caller's normalisation changes the result by as much, the formulas are smooth).
    /// Arcs longer than π/2 are split at their midpoint first, which keeps 1 + co ≥ 1 and the
    /// fan's denominator positive. A zero-length edge adds nothing; an edge between antipodal
    /// points has no defined great circle and is skipped too.
    pub fn accumulate_edge(&mut self, a: DVec3, b: DVec3, n: DVec3) {
        debug_assert!(
            (a.length_squared() - 1.0).abs() < 1e-6 && (b.length_squared() - 1.0).abs() < 1e-6,
            "polygon vertices must be unit vectors: {a} {b}"
        );
        let co = a.dot(b);
        if co < 0.0 {
            // Longer than π/2 (at most π): the midpoint is a cos(γ/2) + e sin(γ/2), e the unit
            // tangent at a towards b. Both halves are then at most π/2.
            let u = b - co * a;
            let s = u.length();
            if s == 0.0 {
                return;
            }
            let half = 0.5 * s.atan2(co);
            let mid = a * half.cos() + u * (half.sin() / s);
            self.add_short_arc(a, mid, n);
            self.add_short_arc(mid, b, n);
        } else {
            self.add_short_arc(a, b, n);
        }
    }

    /// One edge of at most π/2 (co ≥ 0).
    fn add_short_arc(&mut self, a: DVec3, b: DVec3, n: DVec3) {
        let cr = a.cross(b);
        let s = cr.length();
        if s == 0.0 {
            // a == b: every term below carries a factor cr or N·cr.
            return;
        }
        let co = a.dot(b);
        let gamma = s.atan2(co);
        let gamma_over_s = if s < TINY_SINE {
            1.0 + s * s / 6.0
        } else {
            gamma / s
        };
        let beta = if gamma < SMALL_ARC {
            let g2 = gamma * gamma;
            gamma * g2 * (1.0 / 3.0 - g2 * (1.0 / 15.0 - g2 * (2.0 / 315.0)))
        } else {
            0.5 * (gamma - s * co)
        };
        let u = b - co * a;
        let n_cr = n.dot(cr);

        self.tau1 += (0.5 * gamma_over_s) * cr;
        self.g1 += n_cr * (a + u / (1.0 + co));
        let aa = outer(a, a);
        let uu = outer(u, u);
        let au = outer(a, u);
        self.g2 += (0.5 * (gamma_over_s + co)) * n_cr * aa
            + (beta / (s * s * s)) * n_cr * uu
            + (0.5 * n_cr) * (au + au.transpose());
        self.omega += 2.0 * n_cr.atan2(1.0 + n.dot(a) + co + n.dot(b));
    }

    /// Adds a closed loop (the edge from the last vertex back to the first included).
    /// Loops with fewer than two vertices add nothing.
    pub(crate) fn accumulate_loop(&mut self, vertices: &[DVec3], n: DVec3) {
        if vertices.len() < 2 {
            return;
        }
        let mut prev = vertices[vertices.len() - 1];
        for &v in vertices {
            self.accumulate_edge(prev, v, n);
            prev = v;
        }
    }

    /// The moments of a polygon given as closed loops of unit vectors for the normal `n`:
    /// counter-clockwise loops seen from outside are filled, clockwise loops are holes.
    pub fn of_loops<'a>(loops: impl IntoIterator<Item = &'a [DVec3]>, n: DVec3) -> Self {
        let mut m = Self::ZERO;
        for l in loops {
            m.accumulate_loop(l, n);
        }
        m
    }
}

/// a bᵀ.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// M : G, the sum of the element-wise products.
fn frobenius(m: &DMat3, g: &DMat3) -> f64 {
    m.x_axis.dot(g.x_axis) + m.y_axis.dot(g.y_axis) + m.z_axis.dot(g.z_axis)
}

impl Quadratic {
    /// ∫_P L(ω) (N·ω) dω for this channel, L(ω) = c + b·ω + ωᵀMω (the notes' E):
    /// E = c (N·τ₁) + [(b·N) Ω + b·G₁]/3 + [2 NᵀMτ₁ + M : G₂]/4.
    /// `m` must have been accumulated for the same `n`, in the frame this quadratic is in.
    pub fn cosine_weighted_integral(&self, m: &PolygonMoments, n: DVec3) -> f64 {
        self.c * n.dot(m.tau1)
            + (self.b.dot(n) * m.omega + self.b.dot(m.g1)) / 3.0
            + (2.0 * n.dot(self.m * m.tau1) + frobenius(&self.m, &m.g2)) / 4.0
    }
}

/// ∫_P L(ω) (N·ω) dω per colour channel, from the polygon's moments for `n` and the
/// radiance's quadratic form in the same frame (see [`Quadratic::cosine_weighted_integral`]).
/// Over the occluded part of the hemisphere this is E^occluded of Eq. 3 (paper 002); over the
/// whole hemisphere it equals [`super::sh::Sh9::irradiance`] (Eq. 7). The result can be
/// negative where the band-limited radiance rings below zero; clamping is the caller's choice.
pub fn cosine_weighted_integral(q: &ShQuadratic, m: &PolygonMoments, n: DVec3) -> DVec3 {
    let [r, g, b] = &q.channels;
    DVec3::new(
        r.cosine_weighted_integral(m, n),
        g.cosine_weighted_integral(m, n),
        b.cosine_weighted_integral(m, n),
    )
}

/// The shading-frame form: polygons in a local frame whose z axis is the normal, radiance
/// from [`super::sh::Sh9::local_quadratic`]. Same as [`cosine_weighted_integral`] with N = z.
pub fn cosine_weighted_integral_local(q: &ShQuadratic, m: &PolygonMoments) -> DVec3 {
    cosine_weighted_integral(q, m, DVec3::Z)
}
