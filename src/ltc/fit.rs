//! Fitting the LTC table (Heitz, Dupuy, Hill, Neubelt 2016, Sect. 4 and their fitting code
//! as described in 001 Sect. 3.4), written from the equations:
//!
//! * per cell `(θv, α)`: the moments `norm = ∫ brdf_cos dω`, `fresnel = ∫ brdf_cos (1 − v·h)⁵
//!   dω` and the average direction `∫ brdf_cos l dω` by a midpoint rule on the VNDF sample
//!   square ([`lobe_moments`]);
//! * the LTC `M = B · K`, `B = [X Y Z]` the rotation taking `z` to the lobe's average
//!   direction `Z` (in the xz-plane), `K = [[m11, 0, m13], [0, m22, 0], [m31, 0, 1]]` — the
//!   general y-symmetric matrix up to scale (4 degrees of freedom, the form
//!   `[[a, 0, b], [0, c, 0], [d, 0, 1]]` of the LTC paper, expressed around the lobe axis so
//!   that the initial guess `K = diag(α, α, 1)` is already close);
//! * parameters `q = [ln m11, ln m22, m13/m11, m31]` (scale-free in α, positive-definite
//!   diagonal by construction), minimised with [`super::nelder_mead`] for the L3 error
//!   `∫ |brdf_cos/norm − D̂_M|³ dω`, estimated with both distributions as importance samplers
//!   and the balance heuristic (see `L3Error`);
//! * warm start: the normal-incidence column (a one-parameter fit `K = diag(m, m, 1)`, exact
//!   by symmetry) from rough to smooth, then every row (fixed α) independently and in parallel
//!   from normal to grazing incidence, each cell starting from its fitted neighbour.

use super::ggx::{self, brdf_cos_and_pdf};
use super::nelder_mead::{self, Options};
use super::table::{ALPHA_MIN, COS_THETA_MIN, LtcEntry, LtcTable, nodes};
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Samples per axis of each of the two stratified sample sets of the error estimate
/// (`FIT_SAMPLES²` from the BRDF and as many from the LTC).
pub(crate) const FIT_SAMPLES: usize = 64;
/// Oracle strata per axis of [`Objective::Polygons`].
pub(crate) const POLYGON_ORACLE_SAMPLES: usize = 512;
/// Samples per axis of the midpoint rule for `norm`, `fresnel` and the average direction.
pub const MOMENT_SAMPLES: usize = 1024;

crate::choice! {
    /// What the fitter minimises (docs/ltc.md, "Fitting" and "Candidates").
    #[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
    pub enum Objective {
        /// `∫_{S²} |f − D̂_M|³ dω` (the LTC paper's metric; the first committed table).
        L3Sphere = "l3-sphere",
        /// `∫_{z>0} |f − D̂_M/H(M)|³ dω`: the error of the horizon-renormalised LTC over the
        /// upper hemisphere only (what a renderer integrates).
        L3Upper = "l3-upper",
        /// As `L3Upper` with the squared error.
        L2Upper = "l2-upper",
        /// The mean squared error of the renormalised LTC's integrals over a fixed set of
        /// polygons (`FitPolygons`: quads of three sizes on a grid of directions over the
        /// upper hemisphere) against a Monte Carlo oracle, in units of the albedo.
        Polygons = "polygons",
        /// `Polygons` and `L3Upper` together, each relative: the polygons' weighted squared
        /// error over their weighted squared targets plus `(L3 / ∫ f³)^(2/3)`. The L3 term
        /// keeps the lobe's shape where it is large (lights near the highlight), the polygon
        /// term its integrals everywhere else.
        Combined = "combined",
    }
}

/// The polygon set and oracle values of [`Objective::Polygons`] for one cell.
pub(crate) struct FitPolygons {
    pieces: Vec<Vec<DVec3>>,
    /// `E(P)` per polygon: the integral of the cosine tail ([`LtcEntry::cosine`]).
    cos_form_factors: Vec<f64>,
    /// Oracle `∫_P brdf_cos dω / norm` per polygon.
    targets: Vec<f64>,
    /// Weight of each polygon's squared error (summing to 1).
    weights: Vec<f64>,
}

/// Smallest α fitted with the polygon objectives. Below it the lobe is narrower than the
/// smallest lobe quad (`w` floors at 0.02) and than the grid's, the polygons cannot resolve its
/// shape (at α = 0.004 and θv = 88° such a fit lands farther from GGX in L1 than the starting
/// cosine), and the cell is fitted with [`Objective::L3Upper`], without the tail.
pub(crate) const POLYGON_ALPHA_MIN: f64 = 0.02;

/// Share of the objective carried by the polygons placed where the lobe is (the rest by the
/// fixed grid over the hemisphere). Measured on the `glossy` scene's first image (docs/ltc.md,
/// "Candidates"): with lobe quads of w/2…2w, 0.5 gives 4.5 % and 0.8 gives 4.4 % relative RMSE;
/// with w/4…w and the cosine tail, 0.8 gives 4.03 % and 0.9 gives 3.91 % (published: 7.86 %).
pub(crate) const LOBE_POLYGON_SHARE: f64 = 0.9;

impl FitPolygons {
    /// Two sets, clipped to the horizon, with `k × k` oracle samples:
    ///
    /// * a fixed grid: gnomonic quads of tangent half-size 0.08, 0.25 and 0.6 centred at
    ///   elevations 2°, 8°, 18°, 32°, 50°, 75° and azimuths 180°, 155°, 125°, 90°, 45°, 0°
    ///   (the reflection direction is at azimuth 180°; by symmetry one side suffices);
    /// * where the lobe is: quads of half-size `w/2, w, 2w` (`w = clamp(α, 0.02, 0.5)`, the
    ///   lobe's width in tangent units) centred on the lobe's average direction `axis`, and
    ///   up to 49 of half-size `w/4, w/2, w` (cycling) centred at directions distributed like
    ///   the lobe (a 7 × 7 midpoint grid of VNDF samples, reflected; those below the horizon
    ///   dropped), so that lights count where the lobe sees them, at the sizes that resolve
    ///   its shape;
    ///
    /// each set carrying its share of the weight ([`LOBE_POLYGON_SHARE`]).
    pub fn new(cos_theta_v: f64, alpha: f64, axis: DVec3, k: usize) -> Self {
        use super::polygon_error::{TestPolygon, clip_vec, gnomonic, oracle_integrals};
        let deg = PI / 180.0;
        let mut grid = Vec::new();
        for &e in &[2.0, 8.0, 18.0, 32.0, 50.0, 75.0] {
            for &a in &[180.0, 155.0, 125.0, 90.0, 45.0, 0.0] {
                for &s in &[0.08, 0.25, 0.6] {
                    let c = DVec3::new(
                        (e * deg).cos() * (a * deg).cos(),
                        (e * deg).cos() * (a * deg).sin(),
                        (e * deg).sin(),
                    );
                    grid.push(clip_vec(&gnomonic(c, s, 4, PI / 4.0)));
                }
            }
        }
        let w = alpha.clamp(0.02, 0.5);
        let mut lobe = Vec::new();
        for s in [0.5 * w, w, 2.0 * w] {
            lobe.push(clip_vec(&gnomonic(axis.normalize(), s, 4, PI / 4.0)));
        }
        // Centres distributed like the lobe: the midpoints of a 7 × 7 grid on the VNDF sample
        // square, reflected; half-sizes cycling through w/2, w, 2w.
        let v = view_dir(cos_theta_v);
        let n = 7;
        for a in 0..n {
            for b in 0..n {
                let (u1, u2) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
                let c = ggx::reflect(v, ggx::sample_vndf(v, alpha, u1, u2));
                if c.z > 0.0 {
                    let size = [0.25 * w, 0.5 * w, w][(a * n + b) % 3];
                    lobe.push(clip_vec(&gnomonic(c, size, 4, PI / 4.0)));
                }
            }
        }
        grid.retain(|q| q.len() >= 3);
        lobe.retain(|q| q.len() >= 3);
        let mut weights = vec![(1.0 - LOBE_POLYGON_SHARE) / grid.len() as f64; grid.len()];
        weights.extend(vec![
            LOBE_POLYGON_SHARE / lobe.len().max(1) as f64;
            lobe.len()
        ]);
        let pieces: Vec<Vec<DVec3>> = grid.into_iter().chain(lobe).collect();
        let polys: Vec<TestPolygon> = pieces
            .iter()
            .map(|q| TestPolygon {
                name: "fit",
                pieces: vec![q.clone()],
            })
            .collect();
        let o = oracle_integrals(cos_theta_v, alpha, &polys, k, 0x00f1_7000);
        let norm = o.albedo.0;
        FitPolygons {
            cos_form_factors: pieces
                .iter()
                .map(|p| super::form_factor([p.as_slice()]).max(0.0))
                .collect(),
            pieces,
            targets: o.values.iter().map(|v| v.0 / norm).collect(),
            weights,
        }
    }

    /// `Σ weight · target²`: the objective of the zero function, the polygon term's unit in
    /// [`Objective::Combined`].
    pub(crate) fn energy(&self) -> f64 {
        self.targets
            .iter()
            .zip(&self.weights)
            .map(|(t, w)| w * t * t)
            .sum()
    }

    /// Weighted mean of `(mix(E(M⁻¹P), E(P))/H − target)²` for the distribution
    /// `(1 − c) D̂_M + c D_o`, renormalised to the upper hemisphere if `renormalize`
    /// (allocation-free).
    pub(crate) fn eval(&self, m: &DMat3, cosine: f64, renormalize: bool) -> f64 {
        let m_inv = m.inverse();
        if m_inv.determinant().is_nan() || m_inv.determinant() <= 0.0 {
            return f64::INFINITY;
        }
        let mut e = LtcEntry {
            m_inv,
            norm: 1.0,
            fresnel: 0.0,
            scale: 1.0,
            cosine,
        };
        let h = e.horizon_fraction();
        if h.is_nan() || h <= 1e-9 {
            return f64::INFINITY;
        }
        if renormalize {
            e.scale = 1.0 / h;
        }
        let mut sq = 0.0;
        for (((p, &t), &e_cos), &wt) in self
            .pieces
            .iter()
            .zip(&self.targets)
            .zip(&self.cos_form_factors)
            .zip(&self.weights)
        {
            let e_ltc = super::polygon_error::ltc_form_factor(&LtcEntry { cosine: 0.0, ..e }, p);
            let d = e.scale * e.mix(e_ltc, e_cos) - t;
            sq += wt * d * d;
        }
        sq
    }
}

/// Options of `fit_cell` and the table fits.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FitOptions {
    pub objective: Objective,
    /// Fit the share of a clamped cosine about the normal beside the LTC
    /// ([`LtcEntry::cosine`]; only with [`Objective::Polygons`]); otherwise the share is 0.
    pub cosine_tail: bool,
    /// Store `scale = 1/H(M)` (horizon renormalisation); otherwise `scale = 1`.
    pub renormalize: bool,
}

impl Default for FitOptions {
    /// The committed table's options.
    fn default() -> Self {
        FitOptions {
            objective: Objective::Polygons,
            renormalize: true,
            cosine_tail: true,
        }
    }
}

impl FitOptions {}

/// `H(M) = ∫_{z>0} D̂_M dω` for the LTC matrix `m` (see [`LtcEntry::horizon_fraction`]):
/// `(1 + cosβ)/2`, β the angle between `Mᵀz` and `z`.
#[inline]
pub(crate) fn horizon_fraction_of(m: &DMat3) -> f64 {
    let n = DVec3::new(m.x_axis.z, m.y_axis.z, m.z_axis.z);
    0.5 * (1.0 + n.z / n.length())
}

/// Moments of the cosine-weighted GGX lobe (`F = 1`).
#[derive(Clone, Copy, Debug)]
pub struct LobeMoments {
    /// `∫ brdf_cos dω`.
    pub norm: f64,
    /// `∫ brdf_cos (1 − v·h)⁵ dω`.
    pub fresnel: f64,
    /// `normalize(∫ brdf_cos l dω)`.
    pub avg_dir: DVec3,
}

/// The view direction `(sinθv, 0, cosθv)` of the local frame.
#[inline]
pub fn view_dir(cos_theta_v: f64) -> DVec3 {
    let c = cos_theta_v.clamp(0.0, 1.0);
    DVec3::new(((1.0 - c) * (1.0 + c)).sqrt(), 0.0, c)
}

/// `norm`, `fresnel` and the average direction by the midpoint rule with `k × k` points on
/// the VNDF sample square: `∫ brdf_cos g dω = ∫∫ (G2/G1)(v, l(u)) g(l(u)) du`, where the
/// weight `G2/G1 ∈ [0, 1]` is smooth except where `l` crosses the horizon.
///
/// The radial sample coordinate is graded, `u1 = 1 − (1 − w)³` with `w` on the midpoint grid
/// (`du1 = 3 (1 − w)² dw`): `u1 → 1` maps to the tail of the NDF (`tanθh ∝ α/√(1 − u1)` at
/// normal incidence), where for small α the reflected direction sweeps through the horizon
/// within a sliver `1 − u1 ~ α²` of the square that a uniform grid does not resolve.
pub fn lobe_moments(v: DVec3, alpha: f64, k: usize) -> LobeMoments {
    let mut norm = 0.0;
    let mut fresnel = 0.0;
    let mut avg = DVec3::ZERO;
    let inv = 1.0 / k as f64;
    for a in 0..k {
        let w = (a as f64 + 0.5) * inv;
        let om = 1.0 - w;
        let u1 = 1.0 - om * om * om;
        let jac = 3.0 * om * om;
        let (mut row_n, mut row_f, mut row_a) = (0.0, 0.0, DVec3::ZERO);
        for b in 0..k {
            let u2 = (b as f64 + 0.5) * inv;
            let h = ggx::sample_vndf(v, alpha, u1, u2);
            let l = ggx::reflect(v, h);
            let wt = ggx::vndf_weight(v, l, alpha);
            if wt > 0.0 {
                row_n += wt;
                row_f += wt * ggx::schlick_weight(v.dot(h));
                row_a += wt * l;
            }
        }
        norm += jac * row_n;
        fresnel += jac * row_f;
        avg += jac * row_a;
    }
    let s = inv * inv;
    LobeMoments {
        norm: norm * s,
        fresnel: fresnel * s,
        avg_dir: avg.normalize(),
    }
}

/// The L3 fit error of an LTC against the normalised lobe `f = brdf_cos/norm`:
/// `∫ |f − D̂|³ dω ≈ (1/N) Σ_{l ~ f-sampler} |f − D̂|³/(p + D̂) + (1/N) Σ_{l ~ D̂} |f − D̂|³/(p + D̂)`
/// with `p = pdf_vndf_reflect` (balance heuristic; `D̂` is its own pdf). Both sample sets
/// are fixed midpoint grids, so the objective is deterministic in `M`.
///
/// With [`Objective::L3Upper`] / [`Objective::L2Upper`] the integral is over `z > 0` only
/// (samples below the horizon are dropped; the estimator stays unbiased for that domain)
/// and `D̂` is replaced by the renormalised `D̂/H(M)`; the sampling pdfs are unchanged.
pub(crate) struct L3Error {
    v: DVec3,
    alpha: f64,
    inv_norm: f64,
    upper: bool,
    square: bool,
    /// VNDF-reflected directions with `f` and the VNDF pdf, independent of `M`.
    brdf_samples: Vec<(DVec3, f64, f64)>,
    /// Cosine-distributed directions (to be mapped by `M`).
    cos_samples: Vec<DVec3>,
}

/// `k × k` midpoint grid of cosine-distributed directions.
fn cosine_grid(k: usize) -> Vec<DVec3> {
    let inv = 1.0 / k as f64;
    let mut out = Vec::with_capacity(k * k);
    for a in 0..k {
        for b in 0..k {
            let u1 = (a as f64 + 0.5) * inv;
            let u2 = (b as f64 + 0.5) * inv;
            let r = u1.sqrt();
            let (s, c) = (TAU * u2).sin_cos();
            out.push(DVec3::new(r * c, r * s, (1.0 - u1).sqrt()));
        }
    }
    out
}

impl L3Error {
    pub(crate) fn with_objective(
        v: DVec3,
        alpha: f64,
        norm: f64,
        k: usize,
        objective: Objective,
    ) -> Self {
        let inv_norm = 1.0 / norm;
        let inv = 1.0 / k as f64;
        let mut brdf_samples = Vec::with_capacity(k * k);
        for a in 0..k {
            for b in 0..k {
                let u1 = (a as f64 + 0.5) * inv;
                let u2 = (b as f64 + 0.5) * inv;
                let l = ggx::reflect(v, ggx::sample_vndf(v, alpha, u1, u2));
                let (f, p) = brdf_cos_and_pdf(v, l, alpha);
                if p > 0.0 {
                    brdf_samples.push((l, f * inv_norm, p));
                }
            }
        }
        L3Error {
            v,
            alpha,
            inv_norm,
            upper: objective != Objective::L3Sphere,
            square: objective == Objective::L2Upper,
            brdf_samples,
            cos_samples: cosine_grid(k),
        }
    }

    /// The error estimate for the LTC with matrix `m` (`+∞` if `m` is not orientation
    /// preserving).
    pub(crate) fn eval(&self, m: &DMat3) -> f64 {
        let m_inv = m.inverse();
        let det_inv = m_inv.determinant();
        if !(det_inv > 0.0 && det_inv.is_finite()) {
            return f64::INFINITY;
        }
        let k = det_inv / PI;
        // D̂ (the sampling pdf) and the compared distribution r · D̂.
        let r = if self.upper {
            let h = horizon_fraction_of(m);
            if h.is_nan() || h <= 1e-9 {
                return f64::INFINITY;
            }
            1.0 / h
        } else {
            1.0
        };
        let pw = |d: f64| if self.square { d * d } else { d * d * d };
        let mut e_brdf = 0.0;
        for &(l, f, p) in &self.brdf_samples {
            if self.upper && l.z <= 0.0 {
                continue;
            }
            let x = m_inv * l;
            let len2 = x.length_squared();
            let g = if x.z > 0.0 {
                x.z * k / (len2 * len2)
            } else {
                0.0
            };
            e_brdf += pw((f - r * g).abs()) / (p + g);
        }
        let mut e_ltc = 0.0;
        for &wo in &self.cos_samples {
            let y = *m * wo;
            let len = y.length();
            let l = y * (1.0 / len);
            if self.upper && l.z <= 0.0 {
                continue;
            }
            let g = wo.z * k * len * len * len;
            let (f, p) = brdf_cos_and_pdf(self.v, l, self.alpha);
            e_ltc += pw((f * self.inv_norm - r * g).abs()) / (p + g);
        }
        (e_brdf + e_ltc) / self.cos_samples.len() as f64
    }
}

/// `B = [X Y Z]` with `Z` the lobe's average direction, `Y = y`, `X = Y × Z`.
fn lobe_basis(avg: DVec3) -> DMat3 {
    let z = DVec3::new(avg.x, 0.0, avg.z).normalize();
    DMat3::from_cols(DVec3::new(z.z, 0.0, -z.x), DVec3::Y, z)
}

/// `K(q)`; `None` when `det K <= 0`.
fn k_matrix(q: &[f64; 4]) -> Option<DMat3> {
    let m11 = q[0].exp();
    let m22 = q[1].exp();
    let m13 = q[2] * m11;
    let m31 = q[3];
    if !(1.0 - q[2] * q[3] > 0.0 && m11.is_finite() && m22.is_finite() && m11 > 0.0) {
        return None;
    }
    Some(DMat3::from_cols(
        DVec3::new(m11, 0.0, m31),
        DVec3::new(0.0, m22, 0.0),
        DVec3::new(m13, 0.0, 1.0),
    ))
}

/// A fitted cell.
#[derive(Clone, Copy, Debug)]
pub struct CellFit {
    pub entry: LtcEntry,
    /// Fit parameters `[ln m11, ln m22, m13/m11, m31, logit c]` in the lobe basis (warm
    /// start; the last only with [`FitOptions::cosine_tail`]).
    pub params: [f64; 5],
    /// The minimised L3 error estimate, and the same for the lobe itself against the
    /// zero function (`∫ f³ dω`), so that `(error / lobe_l3)^(1/3)` is a relative L3 error.
    pub l3_error: f64,
    pub lobe_l3: f64,
    pub evals: usize,
}

/// Starting `logit c` of the cosine tail: a share of 5 %.
pub(crate) const COSINE_TAIL_START: f64 = -2.944;

/// A neighbour's tail parameter as a starting point, kept off the logistic's flat ends
/// (`c ∈ [0.0025, 0.88]`), from where the simplex could not come back.
#[inline]
fn warm_tail(t: f64) -> f64 {
    t.clamp(-6.0, 2.0)
}

/// The cosine tail's share from its parameter: the logistic function, so that every real
/// parameter is a share in `(0, 1)`.
#[inline]
fn cosine_share(t: f64) -> f64 {
    1.0 / (1.0 + (-t).exp())
}

fn nm_options() -> Options {
    Options {
        max_evals: 4000,
        f_rel: 1e-7,
        f_abs: 0.0,
        x_tol: 1e-5,
        restarts: 3,
    }
}

/// Fit one cell from the starting parameters `start` (see [`CellFit::params`]). At normal
/// incidence (`cosθv == 1`) the lobe is rotationally symmetric and the fit is the
/// one-parameter `K = diag(m, m, 1)` (two with the cosine tail).
pub(crate) fn fit_cell(cos_theta_v: f64, alpha: f64, start: [f64; 5], fo: &FitOptions) -> CellFit {
    let v = view_dir(cos_theta_v);
    let mom = lobe_moments(v, alpha, MOMENT_SAMPLES);
    let err = L3Error::with_objective(v, alpha, mom.norm, FIT_SAMPLES, fo.objective);
    let polys = (matches!(fo.objective, Objective::Polygons | Objective::Combined)
        && alpha >= POLYGON_ALPHA_MIN)
        .then(|| FitPolygons::new(cos_theta_v, alpha, mom.avg_dir, POLYGON_ORACLE_SAMPLES));
    let tail = fo.cosine_tail && polys.is_some();
    let lobe_l3 = lobe_l3(&err);
    let objective = |m: &DMat3, t: f64| match (&polys, fo.objective) {
        (Some(p), Objective::Combined) => {
            p.eval(m, if tail { cosine_share(t) } else { 0.0 }, fo.renormalize) / p.energy()
                + (err.eval(m) / lobe_l3).powf(2.0 / 3.0)
        }
        (Some(p), _) => p.eval(m, if tail { cosine_share(t) } else { 0.0 }, fo.renormalize),
        (None, _) => err.eval(m),
    };
    let opts = nm_options();
    let normal = v.x == 0.0;
    let basis = if normal {
        DMat3::IDENTITY
    } else {
        lobe_basis(mom.avg_dir)
    };
    let at = |q: [f64; 4], t: f64| match k_matrix(&q) {
        Some(k) => objective(&(basis * k), t),
        None => f64::INFINITY,
    };
    let (params, l3, evals) = match (normal, tail) {
        (true, false) => {
            let r = nelder_mead::minimize(
                |p: &[f64; 1]| at([p[0], p[0], 0.0, 0.0], 0.0),
                [start[0]],
                [0.1],
                &opts,
            );
            ([r.x[0], r.x[0], 0.0, 0.0, start[4]], r.f, r.evals)
        }
        (true, true) => {
            let r = nelder_mead::minimize(
                |p: &[f64; 2]| at([p[0], p[0], 0.0, 0.0], p[1]),
                [start[0], start[4]],
                [0.1, 0.5],
                &opts,
            );
            ([r.x[0], r.x[0], 0.0, 0.0, r.x[1]], r.f, r.evals)
        }
        (false, false) => {
            let r = nelder_mead::minimize(
                |q: &[f64; 4]| at(*q, 0.0),
                [start[0], start[1], start[2], start[3]],
                [0.1, 0.1, 0.05, 0.05],
                &opts,
            );
            ([r.x[0], r.x[1], r.x[2], r.x[3], start[4]], r.f, r.evals)
        }
        (false, true) => {
            let r = nelder_mead::minimize(
                |q: &[f64; 5]| at([q[0], q[1], q[2], q[3]], q[4]),
                start,
                [0.1, 0.1, 0.05, 0.05, 0.5],
                &opts,
            );
            (r.x, r.f, r.evals)
        }
    };
    let m = basis
        * k_matrix(&[params[0], params[1], params[2], params[3]]).expect("the minimum is feasible");
    let m_inv = m.inverse();
    let mut entry = LtcEntry {
        m_inv: m_inv * (1.0 / m_inv.y_axis.y),
        norm: mom.norm,
        fresnel: mom.fresnel,
        scale: 1.0,
        cosine: if tail { cosine_share(params[4]) } else { 0.0 },
    };
    if fo.renormalize {
        entry.scale = 1.0 / entry.horizon_fraction();
    }
    CellFit {
        entry,
        params,
        // The fit's own L3-type error (for the polygon objective: the upper-hemisphere L3
        // of the renormalised LTC), so that the report compares like with like.
        l3_error: if polys.is_some() { err.eval(&m) } else { l3 },
        lobe_l3,
        evals,
    }
}

/// `∫ f³ dω` (`∫ f² dω` for [`Objective::L2Upper`]) estimated with the BRDF samples of
/// `err`.
fn lobe_l3(err: &L3Error) -> f64 {
    err.brdf_samples
        .iter()
        .map(|&(_, f, p)| if err.square { f * f / p } else { f * f * f / p })
        .sum::<f64>()
        / err.cos_samples.len() as f64
}

/// Fit the `n × n` table (docs/ltc.md for the grid). `progress(done, total)` is called after
/// every cell, from the worker threads. The committed table is `fit_table(64, ..)`.
pub fn fit_table(n: usize, progress: impl Fn(usize, usize) + Sync) -> LtcTable {
    fit_table_cells(n, progress).0
}

/// [`fit_table_cells`] with the default [`FitOptions`].
pub fn fit_table_cells(
    n: usize,
    progress: impl Fn(usize, usize) + Sync,
) -> (LtcTable, Vec<CellFit>) {
    fit_table_cells_with(n, &FitOptions::default(), progress)
}

/// [`fit_table`] with options `fo` that also returns every [`CellFit`] (`cells[i * n + j]`).
pub fn fit_table_cells_with(
    n: usize,
    fo: &FitOptions,
    progress: impl Fn(usize, usize) + Sync,
) -> (LtcTable, Vec<CellFit>) {
    assert!(n >= 2);
    let (alphas, cosines) = nodes(n, ALPHA_MIN, COS_THETA_MIN);
    let cells = fit_grid(&alphas, &cosines, fo, progress);
    let entries: Vec<LtcEntry> = cells.iter().map(|c| c.entry).collect();
    (
        LtcTable::from_entries(n, ALPHA_MIN, COS_THETA_MIN, &entries),
        cells,
    )
}

/// `base` with its rows `first..=last` (roughness nodes) fitted again with `fo` at the table's
/// own nodes, and every other row kept as it is (`penumbra fit-ltc --rows FIRST-LAST --base`).
pub fn refit_rows(
    base: &LtcTable,
    first: usize,
    last: usize,
    fo: &FitOptions,
) -> crate::Result<LtcTable> {
    let n = base.size();
    if last >= n || first > last {
        return Err(crate::Error::from(format!(
            "--rows {first}-{last} outside the table's 0-{}",
            n - 1
        )));
    }
    let alphas: Vec<f64> = (first..=last).map(|i| base.alpha_at(i)).collect();
    let mut cosines: Vec<f64> = (0..n).map(|j| base.cos_theta_at(j)).collect();
    cosines[0] = 1.0;
    let cells = fit_grid(&alphas, &cosines, fo, |_, _| {});
    Ok(base.map_entries_indexed(|i, j, e| {
        if (first..=last).contains(&i) {
            cells[(i - first) * n + j].entry
        } else {
            e
        }
    }))
}

/// Fit every `(alphas[i], cosines[j])`, `cells[i * cosines.len() + j]`, with the warm start
/// of the module doc; `alphas` increasing, `cosines` decreasing with `cosines[0] == 1`
/// (the table's nodes, or any other grid: `penumbra ltc-error --fit`).
pub fn fit_grid(
    alphas: &[f64],
    cosines: &[f64],
    fo: &FitOptions,
    progress: impl Fn(usize, usize) + Sync,
) -> Vec<CellFit> {
    assert!(cosines[0] == 1.0);
    let n = alphas.len();
    let total = n * cosines.len();
    let done = AtomicUsize::new(0);
    let tick = || progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);

    // Normal incidence, from rough to smooth; the LTC width scales like α for small α.
    let mut col0: Vec<Option<CellFit>> = vec![None; n];
    let mut ln_m = 0.0;
    let mut t = COSINE_TAIL_START;
    for i in (0..n).rev() {
        if i + 1 < n {
            ln_m += (alphas[i] / alphas[i + 1]).ln();
        }
        let fit = fit_cell(1.0, alphas[i], [ln_m, ln_m, 0.0, 0.0, t], fo);
        t = warm_tail(fit.params[4]);
        ln_m = fit.params[0];
        col0[i] = Some(fit);
        tick();
    }

    // Rows (fixed α) are independent: sweep from normal to grazing incidence.
    let rows: Vec<Vec<CellFit>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let first = col0[i].expect("fitted above");
            let mut row = Vec::with_capacity(cosines.len());
            row.push(first);
            let mut q = first.params;
            for &cos_theta in &cosines[1..] {
                let fit = fit_cell(cos_theta, alphas[i], q, fo);
                q = fit.params;
                q[4] = warm_tail(q[4]);
                row.push(fit);
                tick();
            }
            row
        })
        .collect();
    rows.into_iter().flatten().collect()
}

/// The per-cell fit report (`assets/ltc/fit_report.tsv`): per cell its row, column, α, cosθv,
/// `norm`, `fresnel`, the relative L3 error over the upper hemisphere of the LTC part, the
/// objective evaluations, the stored matrix and `scale`, `cosine`.
pub fn report_tsv(table: &LtcTable, cells: &[CellFit]) -> String {
    use std::fmt::Write as _;
    let n = table.size();
    let mut tsv = String::from(
        "# i\tj\talpha\tcos_theta_v\tnorm\tfresnel\trel_l3_upper_ltc_part\tevals\tm00\tm02\tm20\tm22\tscale\tcosine\n",
    );
    for i in 0..n {
        for j in 0..n {
            let c = &cells[i * n + j];
            let r = c.entry.to_record();
            let _ = writeln!(
                tsv,
                "{i}\t{j}\t{:.6e}\t{:.6e}\t{:.8}\t{:.8}\t{:.5}\t{}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.8}\t{:.6}",
                table.alpha_at(i),
                table.cos_theta_at(j),
                r[4],
                r[5],
                (c.l3_error / c.lobe_l3).cbrt(),
                c.evals,
                r[0],
                r[1],
                r[2],
                r[3],
                r[6],
                r[7]
            );
        }
    }
    tsv
}
