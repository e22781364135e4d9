//! The LTC lookup table: per (roughness, view angle) the inverse LTC matrix `M⁻¹` of the
//! isotropic GGX lobe, its directional albedo `norm` and the Schlick Fresnel moment
//! `fresnel`. Layout and interpolation are specified in docs/ltc.md.
//!
//! Grid: row `i` (0..n) has `√α = i/(n−1)` (α = `Pr²`), column `j` has
//! `√(1 − cosθv) = j/(n−1)` (Heitz et al. 2016). The nodes are clamped to
//! `α >= ALPHA_MIN` and `cosθv >= COS_THETA_MIN`: row 0 is fitted at `α = ALPHA_MIN` and
//! column `n−1` at `cosθv = COS_THETA_MIN`.
//!
//! `M⁻¹` is stored normalised so that its `(y, y)` entry is 1:
//! `M⁻¹ = [[m00, 0, m02], [0, 1, 0], [m20, 0, m22]]`.
//!
//! Format version 3 stores per entry a `scale` (the horizon renormalisation, docs/ltc.md)
//! and the share `cosine` of a second lobe, the clamped cosine about the normal: the specular
//! integral is `scale · (F0 (norm − fresnel) + fresnel) · ((1 − cosine) E(M⁻¹P) + cosine E(P))`
//! (docs/ltc.md, "The cosine tail").

use crate::TableFormatError;
use glam::{DMat3, DVec3};
use std::io;
use std::path::Path;
use std::sync::OnceLock;

/// Side of the committed table.
pub const LTC_TABLE_SIZE: usize = 64;
/// Smallest roughness represented; lookups with smaller α use this one (see docs/ltc.md).
pub const ALPHA_MIN: f64 = 1e-4;
/// Smallest `cosθv` represented (θv ≈ 89.94°); the last column is fitted here.
pub const COS_THETA_MIN: f64 = 1e-3;

/// File magic of the binary table format (docs/ltc.md).
pub const MAGIC: [u8; 8] = *b"PNBRLTC\x01";
const VERSION: u32 = 3;
const HEADER_LEN: usize = 32;
/// Values per entry: `m00, m02, m20, m22, norm, fresnel, scale, cosine`.
pub(crate) const RECORD_VALUES: usize = 8;
const RECORD_LEN: usize = RECORD_VALUES * 8;

/// One fitted LTC.
#[derive(Clone, Copy, Debug)]
pub struct LtcEntry {
    /// Inverse LTC matrix (any positive multiple is equivalent; the table's is normalised
    /// to `m_inv.y_axis.y == 1`).
    pub m_inv: DMat3,
    /// Directional albedo of the GGX lobe with `F = 1`: `∫ brdf_cos dω`.
    pub norm: f64,
    /// `∫ brdf_cos · (1 − v·h)⁵ dω`.
    pub fresnel: f64,
    /// Factor of the whole specular integral: `1/H` with `H` the part of the distribution
    /// above the horizon ([`LtcEntry::horizon_fraction`]; horizon renormalisation,
    /// docs/ltc.md), or 1.
    pub scale: f64,
    /// Share `c ∈ [0, 1)` of the clamped cosine about the normal in the fitted distribution
    /// `D̂ = (1 − c) D̂_M + c D_o`: the GGX lobe's broad upper tail at grazing views, which no
    /// single LTC follows. Its polygon integral is the diffuse form factor the renderer
    /// computes anyway, so the second lobe costs nothing (docs/ltc.md, "The cosine tail").
    pub cosine: f64,
}

impl LtcEntry {
    /// `normalize(M⁻¹ w)`: a light direction mapped into the clamped-cosine space. The
    /// caller clips the transformed polygon to the horizon before [`super::form_factor`].
    /// `M⁻¹` has a positive determinant, so loop orientation is preserved.
    #[inline]
    pub fn transform(&self, w: DVec3) -> DVec3 {
        let x = self.m_inv * w;
        x * (1.0 / x.length())
    }

    /// Every field times `k`: a rate in `cosθv` ([`LtcTable::lookup_rate`]) made a rate in θ.
    pub fn scaled(&self, k: f64) -> LtcEntry {
        LtcEntry {
            m_inv: self.m_inv * k,
            norm: self.norm * k,
            fresnel: self.fresnel * k,
            scale: self.scale * k,
            cosine: self.cosine * k,
        }
    }

    /// The distribution's integral over a horizon-clipped polygon `P` from its two parts:
    /// `e_ltc = E(clip(M⁻¹P))` and `e_cos = E(P)`.
    #[inline]
    pub fn mix(&self, e_ltc: f64, e_cos: f64) -> f64 {
        (1.0 - self.cosine) * e_ltc + self.cosine * e_cos
    }

    /// Scale of the specular integral for Schlick reflectance `f0`:
    /// `∫_P ρ F cosθl dω ≈ mix(E(M⁻¹P), E(P)) · scale · (f0 (norm − fresnel) + fresnel)`.
    #[inline]
    pub fn specular_scale(&self, f0: f64) -> f64 {
        self.scale * (f0 * (self.norm - self.fresnel) + self.fresnel)
    }

    /// `H = ∫_{z>0} D̂ dω = (1 − c) H_M + c`, the part of the distribution above the
    /// horizon. For the LTC part the half-space `z > 0` is `{ω' : (Mᵀz)·ω' > 0}` in the
    /// cosine's space, and the clamped cosine's integral over the half-space whose normal
    /// makes the angle β with `z` is `H_M = (1 + cosβ)/2` (the view factor of a tilted plane;
    /// 001 Eq. 3.12 with `P` the hemisphere); the cosine about the normal lies wholly above.
    pub fn horizon_fraction(&self) -> f64 {
        let m = self.m_inv.inverse();
        let n = DVec3::new(m.x_axis.z, m.y_axis.z, m.z_axis.z);
        self.mix(0.5 * (1.0 + n.z / n.length()), 1.0)
    }

    /// The rate of [`LtcEntry::horizon_fraction`] when the entry changes at `rate` (a field's
    /// rate in each field): `H = (1 − c)(1 + k)/2 + c` with `k = n_z/|n|`, `n` the third row of
    /// `M = (M⁻¹)⁻¹`, and `dM = −M dM⁻¹ M`.
    pub(crate) fn horizon_fraction_rate(&self, rate: &LtcEntry) -> f64 {
        let m = self.m_inv.inverse();
        let dm = -(m * rate.m_inv * m);
        let row = |a: &DMat3| DVec3::new(a.x_axis.z, a.y_axis.z, a.z_axis.z);
        let (n, dn) = (row(&m), row(&dm));
        let len = n.length();
        let k = n.z / len;
        let dk = (dn.z * len * len - n.z * n.dot(dn)) / (len * len * len);
        let c = self.cosine;
        -rate.cosine * 0.5 * (1.0 + k) + (1.0 - c) * 0.5 * dk + rate.cosine
    }

    /// `[m00, m02, m20, m22, norm, fresnel, scale, cosine]` of `M⁻¹ / M⁻¹[y][y]` (`mRC` =
    /// row R, column C).
    pub fn to_record(&self) -> [f64; RECORD_VALUES] {
        let m = self.m_inv * (1.0 / self.m_inv.y_axis.y);
        [
            m.x_axis.x,
            m.z_axis.x,
            m.x_axis.z,
            m.z_axis.z,
            self.norm,
            self.fresnel,
            self.scale,
            self.cosine,
        ]
    }

    /// Inverse of [`LtcEntry::to_record`].
    #[inline]
    pub(crate) fn from_record(r: &[f64; RECORD_VALUES]) -> Self {
        LtcEntry {
            m_inv: DMat3::from_cols(
                DVec3::new(r[0], 0.0, r[2]),
                DVec3::Y,
                DVec3::new(r[1], 0.0, r[3]),
            ),
            norm: r[4],
            fresnel: r[5],
            scale: r[6],
            cosine: r[7],
        }
    }
}

/// The `n × n` table (`n = LTC_TABLE_SIZE` for the committed one).
#[derive(Clone, Debug)]
pub struct LtcTable {
    n: usize,
    alpha_min: f64,
    cos_theta_min: f64,
    /// Node abscissae: `alphas[i] = max((i/(n−1))², alpha_min)`,
    /// `cosines[j] = max(1 − (j/(n−1))², cos_theta_min)`.
    alphas: Vec<f64>,
    cosines: Vec<f64>,
    /// `records[i * n + j]`, see [`LtcEntry::to_record`].
    records: Vec<[f64; RECORD_VALUES]>,
    /// Every stored `scale` is the horizon renormalisation `1/H` of its entry: lookups then
    /// renormalise the *interpolated* entry (`1/H` of the blend), since a blend of `1/H` values
    /// is not `1/H` of the blend — between neighbours whose LTCs lie partly below the horizon
    /// by very different amounts it can be far off.
    renormalized: bool,
}

/// Is every record's `scale` its entry's `1/H` (to rounding)?
fn all_renormalized(records: &[[f64; RECORD_VALUES]]) -> bool {
    records.iter().all(|r| {
        let e = LtcEntry::from_record(r);
        (e.scale * e.horizon_fraction() - 1.0).abs() <= 1e-9
    })
}

/// FNV-1a, 64 bit.
fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn f64_at(bytes: &[u8], off: usize) -> f64 {
    f64::from_le_bytes(bytes[off..off + 8].try_into().unwrap())
}

fn u32_at(bytes: &[u8], off: usize) -> u32 {
    u32::from_le_bytes(bytes[off..off + 4].try_into().unwrap())
}

/// Node values `(alphas, cosines)` of the `n × n` grid (see [`LtcTable::alpha_at`],
/// [`LtcTable::cos_theta_at`]).
pub(crate) fn nodes(n: usize, alpha_min: f64, cos_theta_min: f64) -> (Vec<f64>, Vec<f64>) {
    let step = 1.0 / (n - 1) as f64;
    let alphas = (0..n)
        .map(|i| {
            let r = i as f64 * step;
            (r * r).max(alpha_min)
        })
        .collect();
    let cosines = (0..n)
        .map(|j| {
            let x = j as f64 * step;
            (1.0 - x * x).max(cos_theta_min)
        })
        .collect();
    (alphas, cosines)
}

/// Bracketing node `k0` (`k0 + 1 <= n − 1`) and weight `t ∈ [0, 1]` of the upper node,
/// linear in the node values `vals` (monotone), with the index guessed from the uniform
/// abscissa `u ∈ [0, 1]`. Exact (t = 0 or 1) when `value` is a node value.
#[inline]
fn bracket(vals: &[f64], u: f64, value: f64) -> (usize, f64) {
    let n1 = vals.len() - 1;
    let k0 = ((u * n1 as f64) as usize).min(n1 - 1);
    let (v0, v1) = (vals[k0], vals[k0 + 1]);
    let den = v1 - v0;
    let t = if den != 0.0 {
        ((value - v0) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (k0, t)
}

impl LtcTable {
    /// Assemble a table from `n × n` entries, `entries[i * n + j]` for row `i` (roughness)
    /// and column `j` (view angle); `m_inv` is renormalised to `m_inv[y][y] = 1`.
    pub(crate) fn from_entries(
        n: usize,
        alpha_min: f64,
        cos_theta_min: f64,
        entries: &[LtcEntry],
    ) -> Self {
        assert!(n >= 2 && entries.len() == n * n);
        let (alphas, cosines) = nodes(n, alpha_min, cos_theta_min);
        let records: Vec<_> = entries.iter().map(LtcEntry::to_record).collect();
        LtcTable {
            n,
            alpha_min,
            cos_theta_min,
            alphas,
            cosines,
            renormalized: all_renormalized(&records),
            records,
        }
    }

    /// The committed 64 × 64 table (assets/ltc/ggx_ltc_64.bin), parsed once.
    pub fn embedded() -> &'static LtcTable {
        static BYTES: &[u8] = include_bytes!("../../assets/ltc/ggx_ltc_64.bin");
        static TABLE: OnceLock<LtcTable> = OnceLock::new();
        TABLE.get_or_init(|| {
            LtcTable::from_bytes(BYTES).expect("the embedded LTC table is a valid table file")
        })
    }

    /// Grid side `n`.
    pub fn size(&self) -> usize {
        self.n
    }

    pub fn alpha_min(&self) -> f64 {
        self.alpha_min
    }

    pub fn cos_theta_min(&self) -> f64 {
        self.cos_theta_min
    }

    /// Roughness of row `i`: `max((i/(n−1))², alpha_min)`.
    pub fn alpha_at(&self, i: usize) -> f64 {
        self.alphas[i]
    }

    /// `cosθv` of column `j`: `max(1 − (j/(n−1))², cos_theta_min)`.
    pub fn cos_theta_at(&self, j: usize) -> f64 {
        self.cosines[j]
    }

    /// The stored entry of row `i`, column `j`.
    pub fn entry(&self, i: usize, j: usize) -> LtcEntry {
        LtcEntry::from_record(&self.records[i * self.n + j])
    }

    /// Bilinear interpolation of the stored records, linear in `α` and in `cosθv` between
    /// the bracketing nodes (the nodes themselves are uniform in `√α` and `√(1 − cosθv)`).
    /// Inputs are clamped to `[alpha_min, 1]` and `[cos_theta_min, 1]` (NaN → the minimum).
    /// Returns the stored entry bit for bit at the nodes (for a renormalised table, whose
    /// interpolated entry gets `scale = 1/H` of itself, to rounding). Allocation-free.
    #[inline]
    pub fn lookup(&self, cos_theta_v: f64, alpha: f64) -> LtcEntry {
        let a = if alpha > self.alpha_min {
            alpha.min(1.0)
        } else {
            self.alpha_min
        };
        let c = if cos_theta_v > self.cos_theta_min {
            cos_theta_v.min(1.0)
        } else {
            self.cos_theta_min
        };
        let (i0, ta) = bracket(&self.alphas, a.sqrt(), a);
        // The column nodes decrease in cosθ; bracket in −cosθ.
        let (j0, tc) = bracket_desc(&self.cosines, (1.0 - c).sqrt(), c);
        let n = self.n;
        let r00 = &self.records[i0 * n + j0];
        let r01 = &self.records[i0 * n + j0 + 1];
        let r10 = &self.records[(i0 + 1) * n + j0];
        let r11 = &self.records[(i0 + 1) * n + j0 + 1];
        let (w00, w01, w10, w11) = (
            (1.0 - ta) * (1.0 - tc),
            (1.0 - ta) * tc,
            ta * (1.0 - tc),
            ta * tc,
        );
        let mut r = [0.0; RECORD_VALUES];
        for k in 0..RECORD_VALUES {
            r[k] = w00 * r00[k] + w01 * r01[k] + w10 * r10[k] + w11 * r11[k];
        }
        let mut e = LtcEntry::from_record(&r);
        if self.renormalized {
            e.scale = 1.0 / e.horizon_fraction();
        }
        e
    }

    /// The rate of [`LtcTable::lookup`] in `cosθv` at fixed `α`: each field of the returned
    /// entry is the derivative of that field of the lookup (`m_inv` the matrix of derivatives),
    /// and the distance in `cosθv` from `cos_theta_v` to the nearest column node, where the
    /// rate jumps. The lookup is linear in `cosθv` between nodes, so its rate is constant
    /// there: the derivative of the function the renderer evaluates, taken in the cell the
    /// lookup picks. Zero where `cosθv` is clamped. For a renormalised table, `scale = 1/H` of
    /// the blend is differentiated through `H` ([`LtcEntry::horizon_fraction`]).
    pub fn lookup_rate(&self, cos_theta_v: f64, alpha: f64) -> (LtcEntry, f64) {
        let a = if alpha > self.alpha_min {
            alpha.min(1.0)
        } else {
            self.alpha_min
        };
        let node_distance = self
            .cosines
            .iter()
            .map(|&c| (c - cos_theta_v).abs())
            .fold(f64::INFINITY, f64::min);
        let zero = LtcEntry {
            m_inv: DMat3::ZERO,
            norm: 0.0,
            fresnel: 0.0,
            scale: 0.0,
            cosine: 0.0,
        };
        if !(cos_theta_v > self.cos_theta_min && cos_theta_v < 1.0) {
            return (zero, node_distance);
        }
        let c = cos_theta_v;
        let (i0, ta) = bracket(&self.alphas, a.sqrt(), a);
        // At a node the lookup is continuous but its rate has two sides: the cell's is taken.
        let (j0, _) = bracket_desc(&self.cosines, (1.0 - c).sqrt(), c);
        let den = self.cosines[j0] - self.cosines[j0 + 1];
        if den == 0.0 {
            return (zero, node_distance);
        }
        // tc = (v0 − c)/(v0 − v1): dtc/dc = −1/(v0 − v1).
        let dtc = -1.0 / den;
        let n = self.n;
        let r00 = &self.records[i0 * n + j0];
        let r01 = &self.records[i0 * n + j0 + 1];
        let r10 = &self.records[(i0 + 1) * n + j0];
        let r11 = &self.records[(i0 + 1) * n + j0 + 1];
        let mut r = [0.0; RECORD_VALUES];
        for k in 0..RECORD_VALUES {
            r[k] = dtc * ((1.0 - ta) * (r01[k] - r00[k]) + ta * (r11[k] - r10[k]));
        }
        let mut rate = LtcEntry::from_record(&r);
        rate.m_inv.y_axis = DVec3::ZERO;
        if self.renormalized {
            let e = self.lookup(c, alpha);
            rate.scale = -e.scale * e.scale * e.horizon_fraction_rate(&rate);
        }
        (rate, node_distance)
    }

    /// Are the stored scales the horizon renormalisation (and lookups renormalise)?
    pub fn is_renormalized(&self) -> bool {
        self.renormalized
    }

    /// The same table with `f` applied to every stored entry (e.g. the horizon
    /// renormalisation `scale = 1/H`, [`LtcEntry::horizon_fraction`]).
    pub(crate) fn map_entries(&self, f: impl Fn(LtcEntry) -> LtcEntry) -> LtcTable {
        let entries: Vec<LtcEntry> = (0..self.n * self.n)
            .map(|k| f(LtcEntry::from_record(&self.records[k])))
            .collect();
        LtcTable::from_entries(self.n, self.alpha_min, self.cos_theta_min, &entries)
    }

    /// [`LtcTable::map_entries`] with the row `i` and column `j` of each entry.
    pub(crate) fn map_entries_indexed(
        &self,
        f: impl Fn(usize, usize, LtcEntry) -> LtcEntry,
    ) -> LtcTable {
        let entries: Vec<LtcEntry> = (0..self.n * self.n)
            .map(|k| {
                f(
                    k / self.n,
                    k % self.n,
                    LtcEntry::from_record(&self.records[k]),
                )
            })
            .collect();
        LtcTable::from_entries(self.n, self.alpha_min, self.cos_theta_min, &entries)
    }

    /// [`LtcTable::map_entries`] setting `scale = 1/H` (candidate (a) of docs/ltc.md).
    pub(crate) fn horizon_renormalized(&self) -> LtcTable {
        self.map_entries(|e| LtcEntry {
            scale: 1.0 / e.horizon_fraction(),
            ..e
        })
    }

    /// Serialise (little-endian binary, docs/ltc.md).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_LEN + self.records.len() * RECORD_LEN + 8);
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(self.n as u32).to_le_bytes());
        out.extend_from_slice(&self.alpha_min.to_le_bytes());
        out.extend_from_slice(&self.cos_theta_min.to_le_bytes());
        for rec in &self.records {
            for x in rec {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        let sum = fnv1a64(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Parse and validate the binary format.
    pub fn from_bytes(bytes: &[u8]) -> crate::Result<Self> {
        if bytes.len() < HEADER_LEN + 8 {
            return Err(TableFormatError::Header("truncated").into());
        }
        if bytes[..8] != MAGIC {
            return Err(TableFormatError::Magic.into());
        }
        let version = u32_at(bytes, 8);
        if version != VERSION {
            return Err(TableFormatError::Version(version).into());
        }
        let n = u32_at(bytes, 12) as usize;
        if !(2..=4096).contains(&n) {
            return Err(TableFormatError::Header("size out of range").into());
        }
        let expected = HEADER_LEN + n * n * RECORD_LEN + 8;
        if bytes.len() != expected {
            return Err(TableFormatError::Length {
                got: bytes.len(),
                expected,
            }
            .into());
        }
        let body = &bytes[..expected - 8];
        if fnv1a64(body) != u64::from_le_bytes(bytes[expected - 8..].try_into().unwrap()) {
            return Err(TableFormatError::Checksum.into());
        }
        let alpha_min = f64_at(bytes, 16);
        let cos_theta_min = f64_at(bytes, 24);
        if !(alpha_min > 0.0 && alpha_min < 1.0 && cos_theta_min > 0.0 && cos_theta_min < 1.0) {
            return Err(TableFormatError::Header("alpha_min / cos_theta_min out of (0, 1)").into());
        }
        let mut records = Vec::with_capacity(n * n);
        for k in 0..n * n {
            let off = HEADER_LEN + k * RECORD_LEN;
            let mut r = [0.0; RECORD_VALUES];
            for (q, x) in r.iter_mut().enumerate() {
                *x = f64_at(bytes, off + 8 * q);
            }
            if !(r.iter().all(|x| x.is_finite()) && r[6] > 0.0 && (0.0..1.0).contains(&r[7])) {
                return Err(TableFormatError::Record(k).into());
            }
            records.push(r);
        }
        let (alphas, cosines) = nodes(n, alpha_min, cos_theta_min);
        Ok(LtcTable {
            n,
            alpha_min,
            cos_theta_min,
            alphas,
            cosines,
            renormalized: all_renormalized(&records),
            records,
        })
    }

    /// Write the table to `path` (binary, docs/ltc.md).
    pub fn save(&self, path: impl AsRef<Path>) -> io::Result<()> {
        std::fs::write(path, self.to_bytes())
    }

    /// Read a table written by [`LtcTable::save`]; format errors are `InvalidData`.
    pub fn load(path: impl AsRef<Path>) -> io::Result<Self> {
        let bytes = std::fs::read(path)?;
        Self::from_bytes(&bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
    }
}

/// [`bracket`] for decreasing node values.
#[inline]
fn bracket_desc(vals: &[f64], u: f64, value: f64) -> (usize, f64) {
    let n1 = vals.len() - 1;
    let k0 = ((u * n1 as f64) as usize).min(n1 - 1);
    let (v0, v1) = (vals[k0], vals[k0 + 1]);
    let den = v0 - v1;
    let t = if den != 0.0 {
        ((v0 - value) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (k0, t)
}
