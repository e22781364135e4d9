//! How precisely a file wrote its coordinates, and the tolerances that follow from it
//! (docs/scenes.md, "Precision of the input").
//!
//! Exporters round: Blender's OBJ exporter writes `%.6f` (six decimals, whatever the
//! magnitude), others `%.9g` (nine significant digits, trailing zeros stripped), some dump f32
//! values with all their digits. A quad that was planar in the exporter is then planar only up
//! to that rounding, and calling it "non-planar" would be noise. So the rounding of every
//! coordinate is inferred from the digits as stored, for the whole file:
//!
//! * **Fixed decimals** (`%.Nf`): `N` is the most decimals any coordinate has. The format is
//!   taken as fixed when at least half of the coordinates whose last digit is not 0 have those
//!   `N` decimals (with `%.Nf` all of them do, except values whose trailing zeros a writer
//!   stripped); a coordinate is then within `0.5·10^-N` of what was meant.
//! * **Significant digits** (`%.Sg`) otherwise: `S` is the most significant digits any
//!   coordinate has, and `v` is within `0.5·10^(⌊log10|v|⌋ − S + 1)` of what was meant.
//! * **f32 data**: when every coordinate is an f32 value (within a thousandth of an f32 ulp),
//!   the data was computed in f32 as well as stored in it (Blender holds meshes in f32; glTF
//!   stores f32). A vertex computed as a vector (a rotation, a scaling, a sine and a cosine)
//!   carries an error of the order of its *largest* coordinate's ulp in every coordinate, not
//!   of each coordinate's own ulp: half an ulp for the arithmetic and half for the storage.
//!   So each coordinate's rounding is at least one f32 ulp of the vertex's largest coordinate
//!   (`WrittenPrecision::vertex_rounding`), and half an ulp of its own value alone
//!   (`WrittenPrecision::coordinate_rounding`), however many digits were printed.
//!
//! A coordinate's rounding also never falls below the f64 rounding of its value (4 ulp). A
//! vertex is within the Euclidean norm of its three coordinates' roundings of its meant
//! position: its *rounding radius*. `planarity_tolerance` turns those radii into the
//! largest distance from its fitted plane at which a face that was planar as meant can still
//! be found.

use glam::DVec3;

/// The digits of one number as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WrittenNumber {
    pub value: f64,
    /// The decimal exponent of the last digit written: `1.25` → −2, `3e5` → 5, `120` → 0.
    pub last_digit: i32,
    /// Digits written from the first nonzero one on (trailing zeros count: they were written).
    pub significant: u32,
    /// Whether the last digit written is 0 (a writer that strips trailing zeros never leaves
    /// one, so such a number shows the format's full precision).
    pub ends_in_zero: bool,
}

/// Reads the digits of a decimal number (`-12.50`, `1.5e-3`, `.5`, `7`); `None` for anything
/// else (`inf`, `nan`, hex).
pub(crate) fn written_number(token: &str) -> Option<WrittenNumber> {
    let value: f64 = token.parse().ok()?;
    if !value.is_finite() {
        return None;
    }
    let t = token.trim_start_matches(['+', '-']);
    let (mantissa, exponent) = match t.find(['e', 'E']) {
        Some(i) => (&t[..i], t[i + 1..].parse::<i32>().ok()?),
        None => (t, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    if !int.bytes().chain(frac.bytes()).all(|b| b.is_ascii_digit()) || int.len() + frac.len() == 0 {
        return None;
    }
    let digits: Vec<u8> = int.bytes().chain(frac.bytes()).collect();
    let first = digits.iter().position(|&d| d != b'0');
    let significant = first.map_or(0, |f| (digits.len() - f) as u32);
    Some(WrittenNumber {
        value,
        last_digit: exponent.saturating_sub(frac.len() as i32),
        significant,
        ends_in_zero: digits.last() == Some(&b'0'),
    })
}

/// The rounding of a file's coordinates, inferred from all of them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct WrittenPrecision {
    /// `Some(e)`: fixed decimals, every coordinate within `0.5·10^e`.
    pub fixed_last_digit: Option<i32>,
    /// The most significant digits of any coordinate (the significant-digits model).
    pub significant: u32,
    /// Every coordinate is an f32 value.
    pub f32_data: bool,
    /// No coordinate was seen: nothing is known and nothing is assumed beyond f64 rounding.
    pub empty: bool,
}

/// Gathers [`WrittenNumber`]s and infers the [`WrittenPrecision`] of the whole file.
#[derive(Clone, Debug, Default)]
pub(crate) struct PrecisionSurvey {
    count: u64,
    /// The smallest last-digit exponent seen, and how many numbers not ending in 0 have it.
    finest: Option<i32>,
    at_finest: u64,
    not_ending_in_zero: u64,
    significant: u32,
    all_f32: bool,
}

impl PrecisionSurvey {
    pub fn new() -> Self {
        PrecisionSurvey {
            all_f32: true,
            ..Default::default()
        }
    }

    pub(crate) fn add(&mut self, n: WrittenNumber) {
        self.count += 1;
        self.significant = self.significant.max(n.significant);
        let f = n.value as f32 as f64;
        self.all_f32 &= (n.value - f).abs() <= 1e-3 * f32_ulp(f);
        if n.significant == 0 {
            return; // a zero says nothing of the format
        }
        match self.finest {
            Some(e) if n.last_digit > e => {}
            Some(e) if n.last_digit == e => self.at_finest += !n.ends_in_zero as u64,
            _ => {
                self.finest = Some(n.last_digit);
                self.at_finest = !n.ends_in_zero as u64;
            }
        }
        self.not_ending_in_zero += !n.ends_in_zero as u64;
    }

    pub(crate) fn finish(&self) -> WrittenPrecision {
        if self.count == 0 {
            return WrittenPrecision {
                empty: true,
                ..Default::default()
            };
        }
        let fixed = self
            .finest
            .filter(|_| 2 * self.at_finest >= self.not_ending_in_zero);
        WrittenPrecision {
            fixed_last_digit: fixed,
            significant: self.significant,
            f32_data: self.all_f32,
            empty: false,
        }
    }
}

/// The spacing of f32 values at `v`.
fn f32_ulp(v: f64) -> f64 {
    let a = (v.abs() as f32).max(f32::MIN_POSITIVE);
    (f32::from_bits(a.to_bits() + 1) - a) as f64
}

impl WrittenPrecision {
    /// How far a coordinate written as `v` may be from the value meant.
    pub(crate) fn coordinate_rounding(&self, v: f64) -> f64 {
        let f64_rounding = 4.0 * f64::EPSILON * v.abs();
        if self.empty {
            return f64_rounding;
        }
        let decimal = match self.fixed_last_digit {
            Some(e) => 0.5 * 10f64.powi(e),
            None if v == 0.0 => 0.0,
            None => 0.5 * 10f64.powi(v.abs().log10().floor() as i32 - self.significant as i32 + 1),
        };
        let single = if self.f32_data { 0.5 * f32_ulp(v) } else { 0.0 };
        decimal.max(single).max(f64_rounding)
    }

    /// The rounding radius of a vertex written as `p`: how far it may be from the position
    /// meant. f32 data: one f32 ulp of the largest coordinate in each (see the module docs).
    pub(crate) fn vertex_rounding(&self, p: DVec3) -> f64 {
        let vector = if self.f32_data && !self.empty {
            f32_ulp(p.abs().max_element())
        } else {
            0.0
        };
        DVec3::new(
            self.coordinate_rounding(p.x).max(vector),
            self.coordinate_rounding(p.y).max(vector),
            self.coordinate_rounding(p.z).max(vector),
        )
        .length()
    }

    /// In words, for notes: "6 decimals", "9 significant digits", "f32 values".
    pub(crate) fn describe(&self) -> String {
        if self.empty {
            return "no coordinates".into();
        }
        let digits = match self.fixed_last_digit {
            Some(e) if e <= 0 => format!("{} decimals", -e),
            Some(e) => format!("multiples of 10^{e}"),
            None => format!("{} significant digits", self.significant),
        };
        if self.f32_data {
            format!("{digits}, f32 values")
        } else {
            digits
        }
    }
}

/// The largest distance of a vertex of `pts` from the face's fitted plane: through the
/// centroid, normal along Newell's area vector (0 for a face without area).
pub fn plane_deviation(pts: &[DVec3]) -> f64 {
    let m = pts.len().max(1);
    let c = pts.iter().copied().sum::<DVec3>() / m as f64;
    let Some(n) = (0..pts.len())
        .map(|k| (pts[k] - c).cross(pts[(k + 1) % pts.len()] - c))
        .sum::<DVec3>()
        .try_normalize()
    else {
        return 0.0;
    };
    pts.iter().map(|p| n.dot(*p - c).abs()).fold(0.0, f64::max)
}

/// How far from its fitted plane (through the centroid, normal along Newell's area vector) a
/// vertex of the face `pts` may lie when the face was planar as meant and each vertex is within
/// `rounding` of its meant position.
///
/// With meant vertices `q_i` on a plane of normal `m` and written ones `p_i = q_i + e_i`,
/// `|e_i| ≤ r`: the area vector `a = ½ Σ p_i × p_{i+1}` moves by
/// `δa = ½ Σ e_i × (p_{i+1} − p_{i−1})`, so `|δa| ≤ r·P` with `P = ½ Σ |p_{i+1} − p_{i−1}|`,
/// and the fitted normal `n` tilts from `m` by at most `r·P/A` (first order, `A = |a|`). The
/// distance of `p_i` from the fitted plane is
/// `|n·(p_i − c)| ≤ |(n − m)·(q_i − c_q)| + |n·(e_i − ē)| ≤ (r·P/A)·R + 2r`, with `R` the
/// largest distance of a vertex from the centroid. The tolerance is `r·(2 + P·R/A)`: 4r for
/// a square, more for thin faces, whose normal the rounding tilts more.
pub(crate) fn planarity_tolerance(pts: &[DVec3], rounding: f64) -> f64 {
    let m = pts.len();
    if m < 4 {
        return f64::INFINITY; // a triangle is planar
    }
    let c = pts.iter().copied().sum::<DVec3>() / m as f64;
    let area = (0..m)
        .map(|k| (pts[k] - c).cross(pts[(k + 1) % m] - c))
        .sum::<DVec3>()
        .length()
        * 0.5;
    let p = 0.5
        * (0..m)
            .map(|k| pts[(k + 1) % m].distance(pts[(k + m - 1) % m]))
            .sum::<f64>();
    let r_max = pts.iter().map(|q| q.distance(c)).fold(0.0, f64::max);
    if area <= 0.0 {
        return 0.0;
    }
    rounding * (2.0 + p * r_max / area) + 64.0 * f64::EPSILON * r_max
}

#[cfg(test)]
mod tests {
    use super::*;

    fn survey(tokens: &[&str]) -> WrittenPrecision {
        let mut s = PrecisionSurvey::new();
        for t in tokens {
            s.add(written_number(t).unwrap());
        }
        s.finish()
    }

    #[test]
    fn digits_are_read_as_written() {
        let n = written_number("-12.50").unwrap();
        assert_eq!((n.last_digit, n.significant, n.ends_in_zero), (-2, 4, true));
        let n = written_number("1.5e-3").unwrap();
        assert_eq!((n.last_digit, n.significant), (-4, 2));
        let n = written_number("0.000123").unwrap();
        assert_eq!((n.last_digit, n.significant), (-6, 3));
        let n = written_number("120").unwrap();
        assert_eq!((n.last_digit, n.significant), (0, 3));
        assert_eq!(written_number(".5").unwrap().last_digit, -1);
        for bad in ["inf", "nan", "0x1p3", "1.2.3", "", "e5"] {
            assert!(written_number(bad).is_none(), "{bad}");
        }
    }

    #[test]
    fn blender_six_decimals_are_fixed() {
        let p = survey(&["0.707107", "-0.707107", "1.000000", "0.195090", "-0.5"]);
        assert_eq!(p.fixed_last_digit, Some(-6));
        assert!((p.coordinate_rounding(12.3) - 5e-7).abs() < 1e-20);
        assert_eq!(p.describe(), "6 decimals");
    }

    #[test]
    fn nine_significant_digits_scale_with_magnitude() {
        let p = survey(&[
            "0.707106781",
            "12.3456789",
            "-1234.56789",
            "0.5",
            "3.14159265",
        ]);
        assert_eq!(p.fixed_last_digit, None);
        assert_eq!(p.significant, 9);
        assert!((p.coordinate_rounding(1234.56789) / 5e-6 - 1.0).abs() < 1e-9);
        assert!((p.coordinate_rounding(0.612345678) / 5e-10 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn f32_values_round_to_half_an_f32_ulp() {
        let tokens: Vec<String> = [0.1f32, 0.6180339, 3.3333333]
            .iter()
            .map(|&v| format!("{}", v as f64))
            .collect();
        let refs: Vec<&str> = tokens.iter().map(String::as_str).collect();
        let p = survey(&refs);
        assert!(p.f32_data, "{p:?}");
        assert!(p.coordinate_rounding(0.1) >= 0.5 * f32_ulp(0.1));
        assert!(!survey(&["0.1", "0.2"]).f32_data);
    }

    #[test]
    fn a_rounded_planar_quad_is_within_its_tolerance_and_a_bent_one_is_not() {
        // A tilted square, rounded to 6 decimals; the bound holds for every vertex.
        let round = |v: DVec3| (v * 1e6).round() / 1e6;
        let p = survey(&["0.000001"]);
        let mut worst = 0.0f64;
        for k in 0..200 {
            let a = k as f64 * 0.37;
            let (u, v) = (
                DVec3::new(a.cos(), a.sin(), 0.3 * a.sin()).normalize(),
                DVec3::new(-a.sin(), a.cos(), 0.7).normalize(),
            );
            let v = (v - u * u.dot(v)).normalize() * (0.2 + k as f64 * 0.01);
            // Off the 1e-6 grid: a centre on it would round opposite corners oppositely, and
            // the rounded parallelogram would stay planar.
            let c = DVec3::new(0.312_345_678_9, -1.723_456_789, 2.101_010_101);
            let q: Vec<DVec3> = [c - u - v, c + u - v, c + u + v, c - u + v]
                .into_iter()
                .map(round)
                .collect();
            let r = q.iter().map(|&x| p.vertex_rounding(x)).fold(0.0, f64::max);
            let tol = planarity_tolerance(&q, r);
            let off = plane_deviation(&q);
            assert!(off <= tol, "square {k}: {off:e} > {tol:e}");
            worst = worst.max(off / tol);
            // One corner lifted by 40 times the rounding (a quarter of that from the fitted
            // plane): beyond the tolerance.
            let n = u.cross(v).normalize();
            let mut bent = q.clone();
            bent[2] += n * 40.0 * r;
            assert!(
                plane_deviation(&bent) > planarity_tolerance(&bent, r),
                "bent square {k}"
            );
        }
        assert!(worst > 0.01, "the rounding is seen at all ({worst})");
    }
}
