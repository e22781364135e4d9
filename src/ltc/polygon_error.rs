//! The error of an LTC table on *integrals over polygons* (docs/ltc.md, "Error on polygon
//! integrals"): what a renderer computes, as opposed to the fitter's lobe L3 error.
//!
//! For a configuration `(θv, α)` a fixed, deterministic set of convex spherical polygons
//! ([`test_polygons`]: small, medium and large quads and triangles at the reflection
//! direction, beside it, high up, near and straddling the horizon, and the whole hemisphere)
//! is integrated twice:
//!
//! * the LTC: `s(1) · E(clip(M⁻¹ clip(P)))` ([`ltc_integral`], the renderer's
//!   `integrate_lobes` with `F0 = 1`, `s = LtcEntry::specular_scale`);
//! * the oracle `∫_P brdf_cos dω` ([`oracle_integrals`]): stratified Monte Carlo on the VNDF
//!   sample square, `∫_P brdf_cos dω = ∫∫ (G2/G1)(v, l(u)) 1[l(u) ∈ P] du`, one jittered
//!   sample in each of `k × k` strata (radial coordinate graded as in
//!   [`super::fit::lobe_moments`]), with the conservative *collapsed-strata* variance
//!   estimate `Var ≈ (1/N²) Σ_pairs (y_a − y_b)²` over pairs of adjacent strata (its bias
//!   `(μ_a − μ_b)² ≥ 0` only widens the interval).
//!
//! [`cell_error`] summarises one configuration: the RMS over the polygons of
//! `|LTC − oracle| / albedo`, the largest such error, the mean signed error and the largest
//! relative error `|LTC − oracle| / oracle` over polygons holding ≥ 10 % of the lobe.

use super::fit::view_dir;
use super::form_factor;
use super::ggx;
use super::table::{LtcEntry, LtcTable};
use glam::DVec3;
use std::f64::consts::PI;

/// Largest vertex count of a test polygon (before clipping).
pub(crate) const MAX_POLY: usize = 12;
/// Room for a convex polygon clipped twice by a plane.
const MAX_CLIPPED: usize = MAX_POLY + 4;

/// Two-sided 99.9 % standard normal quantile.
pub(crate) const Z999: f64 = 3.290_526_731_491_926;

/// One region of the test set: one or more disjoint convex spherical polygons (pieces),
/// each smaller than a hemisphere, already clipped to the upper hemisphere and
/// counter-clockwise seen from outside the sphere. A cap is two pieces (its halves `y >= 0`
/// and `y <= 0`, each closed through the zenith): a loop spanning a hemisphere would, once
/// mapped by `M⁻¹` and clipped, have a closing horizon edge between nearly antipodal points
/// whose shorter arc is not the right one.
#[derive(Clone, Debug)]
pub struct TestPolygon {
    pub name: &'static str,
    pub pieces: Vec<Vec<DVec3>>,
}

/// `(cos e cos a, cos e sin a, sin e)`.
fn dir(elevation: f64, azimuth: f64) -> DVec3 {
    let (se, ce) = elevation.sin_cos();
    let (sa, ca) = azimuth.sin_cos();
    DVec3::new(ce * ca, ce * sa, se)
}

/// A regular `sides`-gon of tangent half-size `s` around the unit direction `c`, as the
/// gnomonic image of a planar polygon in the tangent plane at `c` (convex for any `s`),
/// rotated by `phase` radians about `c`.
pub(crate) fn gnomonic(c: DVec3, s: f64, sides: usize, phase: f64) -> Vec<DVec3> {
    let t1 = if c.z.abs() > 0.999_999 {
        DVec3::Y
    } else {
        DVec3::Z.cross(c).normalize()
    };
    let t2 = c.cross(t1);
    (0..sides)
        .map(|k| {
            let a = phase + std::f64::consts::TAU * k as f64 / sides as f64;
            (c + s * (a.cos() * t1 + a.sin() * t2)).normalize()
        })
        .collect()
}

/// Sutherland–Hodgman clip of a convex loop to `z >= 0` into `out` (returns the length);
/// the crossing of the arc `a → b` is the positive combination `a.z b − b.z a`.
fn clip_into(poly: &[DVec3], out: &mut [DVec3; MAX_CLIPPED]) -> usize {
    let mut n = 0;
    for k in 0..poly.len() {
        let a = poly[k];
        let b = poly[(k + 1) % poly.len()];
        if a.z >= 0.0 {
            out[n] = a;
            n += 1;
        }
        if (a.z >= 0.0) != (b.z >= 0.0) {
            let p = if a.z >= 0.0 {
                b * a.z - a * b.z
            } else {
                a * b.z - b * a.z
            };
            out[n] = DVec3::new(p.x, p.y, 0.0).normalize();
            n += 1;
        }
    }
    n
}

pub(crate) fn clip_vec(poly: &[DVec3]) -> Vec<DVec3> {
    let mut buf = [DVec3::ZERO; MAX_CLIPPED];
    let n = clip_into(poly, &mut buf);
    buf[..n].to_vec()
}

/// The fixed test polygons for the view `cosθv` (local frame, view in the xz-plane toward
/// `+x`, so the reflection direction is at azimuth π). Deterministic; already clipped to the
/// horizon; polygons entirely below it are dropped.
pub fn test_polygons(cos_theta_v: f64) -> Vec<TestPolygon> {
    let v = view_dir(cos_theta_v);
    let el_r = v.z.clamp(0.0, 1.0).asin(); // elevation of the reflection direction
    let r = dir(el_r, PI);
    let deg = PI / 180.0;
    let quad = |c: DVec3, s: f64| vec![gnomonic(c, s, 4, PI / 4.0)];
    let tri = |c: DVec3, s: f64| vec![gnomonic(c, s, 3, PI / 2.0)];
    let half_cap = |e: f64, from: usize| {
        let mut p: Vec<DVec3> = (from..=from + 6)
            .map(|k| dir(e, PI * k as f64 / 6.0))
            .collect();
        p.push(DVec3::Z);
        p
    };
    let cap = |e: f64| vec![half_cap(e, 0), half_cap(e, 6)];
    let raw: Vec<(&'static str, Vec<Vec<DVec3>>)> = vec![
        ("refl-quad-small", quad(r, 0.05)),
        ("refl-quad-medium", quad(r, 0.2)),
        ("refl-quad-large", quad(r, 0.6)),
        ("refl-tri-medium", tri(r, 0.3)),
        ("beside-quad-medium", quad(dir(el_r, PI - 40.0 * deg), 0.2)),
        (
            "beside-tri-large",
            tri(dir(el_r.max(20.0 * deg), PI / 2.0), 0.5),
        ),
        ("between-quad-small", quad(dir(0.5 * el_r, PI), 0.1)),
        (
            "above-quad-medium",
            quad(dir(0.5 * (el_r + PI / 2.0), PI), 0.2),
        ),
        ("high-quad-medium", quad(DVec3::Z, 0.3)),
        ("high-quad-large", quad(dir(60.0 * deg, PI), 0.8)),
        ("near-horizon-quad", quad(dir(8.0 * deg, PI), 0.12)),
        ("straddle-quad-medium", quad(dir(0.0, PI), 0.3)),
        ("straddle-quad-large", quad(dir(5.0 * deg, PI), 0.8)),
        ("straddle-tri-side", tri(dir(0.0, 0.75 * PI), 0.4)),
        ("view-side-quad", quad(dir(20.0 * deg, 0.0), 0.3)),
        ("cap-above-5deg", cap(5.0 * deg)),
        ("hemisphere", cap(0.0)),
    ];
    raw.into_iter()
        .map(|(name, pieces)| TestPolygon {
            name,
            // Built counter-clockwise about their centre (`t1 × t2 = c`, azimuth increasing
            // about `z`); clipping keeps the orientation.
            pieces: pieces
                .iter()
                .map(|p| {
                    debug_assert!(p.len() <= MAX_POLY);
                    clip_vec(p)
                })
                .filter(|p| p.len() >= 3)
                .collect(),
        })
        .filter(|p| !p.pieces.is_empty())
        .collect()
}

/// The LTC estimate of `∫_P brdf_cos dω` with `F0 = 1`: `s(1) · Σ_pieces E(clip(M⁻¹ P))`
/// for pieces already clipped to the horizon (as `shading::analytic::integrate_lobes`).
/// Allocation-free.
#[inline]
pub fn ltc_integral(entry: &LtcEntry, poly: &TestPolygon) -> f64 {
    entry.specular_scale(1.0)
        * poly
            .pieces
            .iter()
            .map(|p| ltc_form_factor(entry, p))
            .sum::<f64>()
}

/// `mix(E(clip(M⁻¹ P)), E(P))`: the fitted distribution's integral over `P` (already
/// clipped to the horizon), [`LtcEntry::mix`].
#[inline]
pub fn ltc_form_factor(entry: &LtcEntry, poly: &[DVec3]) -> f64 {
    let mut t = [DVec3::ZERO; MAX_CLIPPED];
    let n = poly.len().min(MAX_CLIPPED);
    for k in 0..n {
        t[k] = entry.transform(poly[k]);
    }
    if entry.m_inv.determinant() < 0.0 {
        t[..n].reverse();
    }
    let mut c = [DVec3::ZERO; MAX_CLIPPED];
    let m = clip_into(&t[..n], &mut c);
    let e_ltc = form_factor([&c[..m]]).max(0.0);
    if entry.cosine == 0.0 {
        return e_ltc;
    }
    let e_cos = form_factor([&poly[..n]]).max(0.0);
    entry.mix(e_ltc, e_cos)
}

/// Oracle values of one configuration.
#[derive(Clone, Debug)]
pub struct OracleIntegrals {
    /// `∫_P brdf_cos dω` per polygon, and its 99.9 % half-width.
    pub values: Vec<(f64, f64)>,
    /// The directional albedo `∫ brdf_cos dω` (same samples) and its half-width.
    pub albedo: (f64, f64),
    pub samples: usize,
}

/// SplitMix64: a small deterministic generator for the jitter.
struct SplitMix(u64);

impl SplitMix {
    #[inline]
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[inline]
fn inside(poly: &[DVec3], l: DVec3) -> bool {
    let n = poly.len();
    let mut prev = poly[n - 1];
    for &p in poly {
        if prev.cross(p).dot(l) < 0.0 {
            return false;
        }
        prev = p;
    }
    true
}

/// `∫_P brdf_cos dω` for every polygon by stratified Monte Carlo on the VNDF sample square
/// (`k × k` strata, `k` even, one jittered sample each; `seed` picks the jitter), with 99.9 %
/// half-widths from the collapsed-strata variance estimate (see the module doc).
pub fn oracle_integrals(
    cos_theta_v: f64,
    alpha: f64,
    polys: &[TestPolygon],
    k: usize,
    seed: u64,
) -> OracleIntegrals {
    assert!(k >= 2 && k.is_multiple_of(2));
    let v = view_dir(cos_theta_v);
    let np = polys.len();
    let mut sum = vec![0.0; np + 1];
    let mut dsq = vec![0.0; np + 1];
    let mut rng = SplitMix(seed ^ 0x5851_f42d_4c95_7f2d);
    let inv = 1.0 / k as f64;
    let mut y = [vec![0.0; np + 1], vec![0.0; np + 1]];
    // Bounding caps `c·l >= cmin` of the pieces (a rejection test only: for an arc shorter
    // than π whose great circle's farthest point from `c` lies outside the polygon, `c·l` is
    // smallest at a vertex; used only for pieces within 90° of their centre, with a margin).
    let caps: Vec<Vec<(DVec3, f64)>> = polys
        .iter()
        .map(|p| {
            p.pieces
                .iter()
                .map(|q| {
                    let c = q.iter().copied().sum::<DVec3>().normalize();
                    let cmin = q.iter().map(|v| c.dot(*v)).fold(1.0, f64::min);
                    if cmin > 0.05 {
                        (c, cmin - 1e-6)
                    } else {
                        (c, -2.0)
                    }
                })
                .collect()
        })
        .collect();
    for a in 0..k {
        for b in (0..k).step_by(2) {
            for (q, yq) in y.iter_mut().enumerate() {
                yq.iter_mut().for_each(|x| *x = 0.0);
                let w = (a as f64 + rng.next_f64()) * inv;
                let u2 = ((b + q) as f64 + rng.next_f64()) * inv;
                let om = 1.0 - w;
                let u1 = 1.0 - om * om * om;
                let jac = 3.0 * om * om;
                let h = ggx::sample_vndf(v, alpha, u1, u2);
                let l = ggx::reflect(v, h);
                let wt = ggx::vndf_weight(v, l, alpha) * jac;
                if wt > 0.0 && l.z > 0.0 {
                    yq[np] = wt;
                    for (p, poly) in polys.iter().enumerate() {
                        if poly
                            .pieces
                            .iter()
                            .zip(&caps[p])
                            .any(|(q, &(c, cmin))| c.dot(l) >= cmin && inside(q, l))
                        {
                            yq[p] = wt;
                        }
                    }
                }
            }
            for p in 0..=np {
                sum[p] += y[0][p] + y[1][p];
                let d = y[0][p] - y[1][p];
                dsq[p] += d * d;
            }
        }
    }
    let n = (k * k) as f64;
    let est = |p: usize| (sum[p] / n, Z999 * dsq[p].sqrt() / n);
    OracleIntegrals {
        values: (0..np).map(est).collect(),
        albedo: est(np),
        samples: k * k,
    }
}

/// Summary of a table's error at one configuration.
#[derive(Clone, Debug)]
pub struct CellError {
    pub cos_theta_v: f64,
    pub alpha: f64,
    /// Oracle albedo (the normalisation of the absolute errors).
    pub albedo: f64,
    /// RMS over the polygons of `|LTC − oracle| / albedo`.
    pub rms: f64,
    /// Largest `|LTC − oracle| / albedo`, and the polygon.
    pub max_abs: f64,
    pub max_abs_polygon: &'static str,
    /// Mean over the polygons of `(LTC − oracle) / albedo` (negative: too dark).
    pub mean_signed: f64,
    /// Largest `|LTC − oracle| / oracle` over polygons with `oracle >= 0.1 · albedo`.
    pub max_rel_big: f64,
    /// `(LTC − oracle)/albedo` for the whole hemisphere.
    pub hemisphere: f64,
    /// Largest oracle half-width over the polygons, in units of the albedo.
    pub max_ci: f64,
}

/// Per polygon `(LTC, oracle, half-width)` for the LTC `e`.
pub(crate) fn polygon_values(
    e: &LtcEntry,
    polys: &[TestPolygon],
    oracle: &OracleIntegrals,
) -> Vec<(f64, f64, f64)> {
    polys
        .iter()
        .zip(&oracle.values)
        .map(|(p, &(o, ci))| (ltc_integral(e, p), o, ci))
        .collect()
}

/// Summarise `polygon_values` of `table.lookup(cosθv, α)` (see [`CellError`]).
pub fn cell_error(
    table: &LtcTable,
    cos_theta_v: f64,
    alpha: f64,
    polys: &[TestPolygon],
    oracle: &OracleIntegrals,
) -> CellError {
    entry_error(
        &table.lookup(cos_theta_v, alpha),
        cos_theta_v,
        alpha,
        polys,
        oracle,
    )
}

/// [`cell_error`] of the LTC `e` fitted at `(cosθv, α)`.
pub(crate) fn entry_error(
    e: &LtcEntry,
    cos_theta_v: f64,
    alpha: f64,
    polys: &[TestPolygon],
    oracle: &OracleIntegrals,
) -> CellError {
    let vals = polygon_values(e, polys, oracle);
    let albedo = oracle.albedo.0;
    let mut c = CellError {
        cos_theta_v,
        alpha,
        albedo,
        rms: 0.0,
        max_abs: 0.0,
        max_abs_polygon: "",
        mean_signed: 0.0,
        max_rel_big: 0.0,
        hemisphere: 0.0,
        max_ci: 0.0,
    };
    let mut sq = 0.0;
    for (p, &(ltc, o, ci)) in polys.iter().zip(&vals) {
        let e = (ltc - o) / albedo;
        sq += e * e;
        c.mean_signed += e;
        if e.abs() > c.max_abs {
            c.max_abs = e.abs();
            c.max_abs_polygon = p.name;
        }
        if o >= 0.1 * albedo {
            c.max_rel_big = c.max_rel_big.max((ltc - o).abs() / o);
        }
        if p.name == "hemisphere" {
            c.hemisphere = e;
        }
        c.max_ci = c.max_ci.max(ci / albedo);
    }
    let n = vals.len().max(1) as f64;
    c.rms = (sq / n).sqrt();
    c.mean_signed /= n;
    c
}

/// The map's configurations: `√α = (i + ½)/m`, `√(1 − cosθv) = (j + ½)/m` for
/// `i, j ∈ [0, m)` (between the 64 × 64 table's nodes for every `m` that is a power of 2),
/// as `(i, j, cosθv, α)`.
pub fn map_grid(m: usize) -> Vec<(usize, usize, f64, f64)> {
    let mut out = Vec::with_capacity(m * m);
    for i in 0..m {
        for j in 0..m {
            let sa = (i as f64 + 0.5) / m as f64;
            let x = (j as f64 + 0.5) / m as f64;
            out.push((i, j, 1.0 - x * x, sa * sa));
        }
    }
    out
}
