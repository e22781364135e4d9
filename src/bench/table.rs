//! The rows of a benchmark (one render of one method at one budget) and the report of a scene:
//! CSV and JSON files.

use super::equal_time::{EqualTimeRow, Target, equal_time};
use crate::render::compare::Comparison;
use crate::shading::Method;
use serde::{Deserialize, Deserializer};
use std::fs::File;
use std::io::{self, BufReader, BufWriter, Write};
use std::path::Path;

/// Reads an `f64` that may have been written as JSON `null` (serde_json writes NaN and ±∞ that
/// way): `null` reads back as NaN.
pub(crate) fn f64_or_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// One render of one method at one budget, compared with the reference.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BenchRow {
    pub scene: String,
    pub method: String,
    /// Samples per pixel; `None` for deterministic methods.
    pub spp: Option<u32>,
    /// Wall-clock time of the render.
    #[serde(deserialize_with = "f64_or_nan")]
    pub seconds: f64,
    #[serde(deserialize_with = "f64_or_nan")]
    pub mae: f64,
    #[serde(deserialize_with = "f64_or_nan")]
    pub rmse: f64,
    /// RMSE divided by the reference's mean value.
    #[serde(deserialize_with = "f64_or_nan")]
    pub relative_rmse: f64,
    /// RMSE with the reference's own noise removed: sqrt(max(0, MSE − mean(reference stderr²))).
    #[serde(deserialize_with = "f64_or_nan")]
    pub rmse_corrected: f64,
    /// Light pieces whose visible polygon was not inside the light's (`shading::invariant`;
    /// the analytic methods): a bug wherever it is not zero.
    #[serde(default)]
    pub violations: u64,
    /// Shading points where a path gave up for one exact there (degenerate configurations,
    /// bounds crossed).
    #[serde(default)]
    pub fallbacks: crate::render::FallbackTotals,
    /// The process's peak resident memory during the row's renders, in MB (Linux).
    #[serde(default)]
    pub peak_mb: Option<f64>,
}

impl BenchRow {
    /// A row from a comparison with the reference (`render::compare::compare`);
    /// `reference_rms_stderr` is [`ReferenceInfo::rms_stderr`].
    pub(crate) fn from_comparison(
        scene: &str,
        method: &str,
        spp: Option<u32>,
        seconds: f64,
        comparison: &Comparison,
        reference_rms_stderr: f64,
    ) -> Self {
        BenchRow {
            scene: scene.to_string(),
            method: method.to_string(),
            spp,
            seconds,
            mae: comparison.mae,
            rmse: comparison.rmse,
            relative_rmse: comparison.relative_rmse,
            rmse_corrected: corrected_rmse(comparison.rmse, reference_rms_stderr),
            violations: 0,
            fallbacks: Default::default(),
            peak_mb: None,
        }
    }
}

/// RMSE against a noisy reference with the reference's noise taken out.
///
/// If the reference is the truth plus independent noise of per-channel variance σᵢ², the
/// expected squared difference of an image from it is (image − truth)² + σᵢ², so
/// MSE − mean(σᵢ²) estimates the MSE against the truth. The difference can come out negative
/// when the image is closer to the truth than the reference's noise can resolve: it is clamped
/// to 0, i.e. "no error detectable". `rms_stderr` = sqrt(mean(σᵢ²)).
pub(crate) fn corrected_rmse(rmse: f64, rms_stderr: f64) -> f64 {
    (rmse * rmse - rms_stderr * rms_stderr).max(0.0).sqrt()
}

/// The converged render every row is compared with.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ReferenceInfo {
    /// Samples per pixel of the reference.
    pub spp: u32,
    #[serde(deserialize_with = "f64_or_nan")]
    pub seconds: f64,
    /// Mean of the per-channel standard error of the reference.
    #[serde(deserialize_with = "f64_or_nan")]
    pub mean_stderr: f64,
    /// sqrt(mean(stderr²)) over channels: what `corrected_rmse` takes out.
    #[serde(deserialize_with = "f64_or_nan")]
    pub rms_stderr: f64,
}

impl ReferenceInfo {
    /// From the reference's per-pixel standard-error image (all channels count).
    pub(crate) fn from_stderr(spp: u32, seconds: f64, stderr: &[[f32; 3]]) -> Self {
        let (mut sum, mut sq) = (0.0, 0.0);
        for c in stderr.iter().flatten() {
            sum += *c as f64;
            sq += *c as f64 * *c as f64;
        }
        let n = (3 * stderr.len()).max(1) as f64;
        ReferenceInfo {
            spp,
            seconds,
            mean_stderr: sum / n,
            rms_stderr: (sq / n).sqrt(),
        }
    }
}

/// The times of the three deterministic methods and how they compare (000 Sect. 4.4, Fig. 6).
/// A method with several rows counts with its fastest one (the usual way to time: the other
/// runs were slowed by something else). Ratios are `None` where a time is missing or not
/// positive.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeedRatios {
    pub analytic_seconds: Option<f64>,
    pub per_triangle_seconds: Option<f64>,
    pub unshadowed_seconds: Option<f64>,
    /// Per-triangle time / analytic time: what silhouettes save.
    pub per_triangle_over_analytic: Option<f64>,
    /// Analytic time / unshadowed time: what shadows cost over plain LTC shading.
    pub analytic_over_unshadowed: Option<f64>,
    /// Per-triangle time / unshadowed time.
    pub per_triangle_over_unshadowed: Option<f64>,
}

/// The fastest finite time of `method` among `rows`.
pub(crate) fn fastest_seconds(rows: &[BenchRow], method: &str) -> Option<f64> {
    rows.iter()
        .filter(|r| r.method == method && r.seconds.is_finite())
        .map(|r| r.seconds)
        .min_by(f64::total_cmp)
}

impl SpeedRatios {
    pub(crate) fn from_rows(rows: &[BenchRow]) -> Self {
        let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if a > 0.0 && b > 0.0 => Some(a / b),
            _ => None,
        };
        let a = fastest_seconds(rows, Method::Analytic.name());
        let p = fastest_seconds(rows, Method::PerTriangle.name());
        let u = fastest_seconds(rows, Method::Unshadowed.name());
        SpeedRatios {
            analytic_seconds: a,
            per_triangle_seconds: p,
            unshadowed_seconds: u,
            per_triangle_over_analytic: ratio(p, a),
            analytic_over_unshadowed: ratio(a, u),
            per_triangle_over_unshadowed: ratio(p, u),
        }
    }
}

/// Everything `penumbra bench` measured on one scene.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BenchReport {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: ReferenceInfo,
    pub rows: Vec<BenchRow>,
    /// Every other method against the analytic one at the analytic method's time
    /// (see [`equal_time`](mod@super::equal_time)); empty without an analytic row.
    pub equal_time: Vec<EqualTimeRow>,
    pub speed_ratios: SpeedRatios,
}

impl BenchReport {
    /// Builds the report: the equal-time table against the fastest `analytic` row, and the
    /// speed ratios.
    pub fn new(
        scene: &str,
        width: u32,
        height: u32,
        reference: ReferenceInfo,
        rows: Vec<BenchRow>,
    ) -> Self {
        let equal_time = match Target::fastest(&rows, Method::Analytic.name()) {
            Some(target) => equal_time(&rows, &target),
            None => Vec::new(),
        };
        let speed_ratios = SpeedRatios::from_rows(&rows);
        BenchReport {
            scene: scene.to_string(),
            width,
            height,
            reference,
            rows,
            equal_time,
            speed_ratios,
        }
    }
}

/// The CSV header, in the order of [`BenchRow`]'s fields.
pub(crate) const CSV_HEADER: &str = "scene,method,spp,seconds,mae,rmse,relative_rmse,rmse_corrected,\
                              violations,bounds_crossed,degenerate_fallbacks,peak_mb";

/// Quotes a CSV field if it needs it (RFC 4180: commas, quotes, line breaks).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes the rows as CSV: the header [`CSV_HEADER`], then one line per row. Numbers are plain
/// decimals in Rust's shortest round-trip form (so they read back bit for bit; NaN as `NaN`,
/// infinities as `inf`); `spp` is empty for deterministic methods.
pub(crate) fn write_csv(rows: &[BenchRow], path: &Path) -> io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "{CSV_HEADER}")?;
    for r in rows {
        let spp = r.spp.map(|s| s.to_string()).unwrap_or_default();
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_field(&r.scene),
            csv_field(&r.method),
            spp,
            r.seconds,
            r.mae,
            r.rmse,
            r.relative_rmse,
            r.rmse_corrected,
            r.violations,
            r.fallbacks.bounds_crossed,
            r.fallbacks.degenerate,
            r.peak_mb.map(|m| m.to_string()).unwrap_or_default()
        )?;
    }
    w.flush()
}

/// Splits one CSV record into fields (RFC 4180 quoting). Returns `None` on an unterminated
/// quote, which means the record continues on the next line.
#[cfg(test)]
fn split_csv(line: &str) -> Option<Vec<String>> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        let field = fields.last_mut().expect("never empty");
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') => quoted = true,
            (false, ',') => fields.push(String::new()),
            (false, c) => field.push(c),
        }
    }
    (!quoted).then_some(fields)
}

#[cfg(test)]
fn bad(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, msg)
}

/// Reads a file written by [`write_csv`].
#[cfg(test)]
pub(crate) fn read_csv(path: &Path) -> io::Result<Vec<BenchRow>> {
    use std::io::BufRead;
    let mut lines = BufReader::new(File::open(path)?).lines();
    let header = lines.next().transpose()?.unwrap_or_default();
    if header.trim_end() != CSV_HEADER {
        return Err(bad(format!("{}: not a bench CSV", path.display())));
    }
    let mut rows = Vec::new();
    let mut record = String::new();
    for (i, line) in lines.enumerate() {
        let line = line?;
        if record.is_empty() && line.trim().is_empty() {
            continue;
        }
        if !record.is_empty() {
            record.push('\n');
        }
        record.push_str(line.trim_end_matches('\r'));
        let Some(f) = split_csv(&record) else {
            continue;
        };
        record.clear();
        let at = |what: &str| bad(format!("{}: line {}: {what}", path.display(), i + 2));
        if f.len() != 12 {
            return Err(at("expected 12 fields"));
        }
        let num = |k: usize| f[k].trim().parse::<f64>().map_err(|e| at(&e.to_string()));
        let count = |k: usize| f[k].trim().parse::<u64>().map_err(|e| at(&e.to_string()));
        let spp = match f[2].trim() {
            "" => None,
            s => Some(s.parse::<u32>().map_err(|e| at(&e.to_string()))?),
        };
        rows.push(BenchRow {
            scene: f[0].clone(),
            method: f[1].clone(),
            spp,
            seconds: num(3)?,
            mae: num(4)?,
            rmse: num(5)?,
            relative_rmse: num(6)?,
            rmse_corrected: num(7)?,
            violations: count(8)?,
            fallbacks: crate::render::FallbackTotals {
                bounds_crossed: count(9)?,
                degenerate: count(10)?,
            },
            peak_mb: match f[11].trim() {
                "" => None,
                _ => Some(num(11)?),
            },
        });
    }
    if !record.is_empty() {
        return Err(bad(format!("{}: unterminated quote", path.display())));
    }
    Ok(rows)
}

/// Writes the report as pretty-printed JSON. Non-finite numbers become `null` (JSON has no
/// NaN) and read back as NaN.
pub(crate) fn write_json(report: &BenchReport, path: &Path) -> io::Result<()> {
    let mut w = BufWriter::new(File::create(path)?);
    serde_json::to_writer_pretty(&mut w, report)?;
    writeln!(w)?;
    w.flush()
}

/// Reads a file written by `write_json`.
pub fn read_json(path: &Path) -> io::Result<BenchReport> {
    Ok(serde_json::from_reader(BufReader::new(File::open(path)?))?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("penumbra-bench-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn row(method: &str, spp: Option<u32>, seconds: f64, err: f64) -> BenchRow {
        BenchRow {
            scene: "fig4".into(),
            method: method.into(),
            spp,
            seconds,
            mae: 0.8 * err,
            rmse: err,
            relative_rmse: err / 0.3,
            rmse_corrected: corrected_rmse(err, 1e-3),
            ..BenchRow::default()
        }
    }

    fn sample_rows() -> Vec<BenchRow> {
        let mut rows = vec![
            row("analytic", None, 0.5, 2e-3),
            row("per-triangle", None, 2.0, 2e-3),
            row("unshadowed", None, 0.125, 0.05),
        ];
        for (k, spp) in [1u32, 4, 16, 64].into_iter().enumerate() {
            rows.push(row(
                "ray-traced",
                Some(spp),
                0.1 * spp as f64,
                0.04 / (1 << k) as f64,
            ));
        }
        // Awkward values that must survive the round trip.
        rows.push(BenchRow {
            scene: "a \"quoted\", scene".into(),
            method: "odd,name".into(),
            spp: Some(7),
            seconds: 1.0 / 3.0,
            mae: 1e-300,
            rmse: 0.1 + 0.2,
            relative_rmse: 123456789.125,
            rmse_corrected: 0.0,
            violations: 3,
            fallbacks: crate::render::FallbackTotals {
                degenerate: 12,
                bounds_crossed: 1,
            },
            peak_mb: Some(123.456789),
        });
        rows
    }

    /// Hand-computed: rmse 5, σ 3 → 4; below the noise → 0.
    #[test]
    fn corrected_rmse_removes_reference_variance() {
        assert_eq!(corrected_rmse(5.0, 3.0), 4.0);
        assert_eq!(corrected_rmse(2.0, 3.0), 0.0);
        assert_eq!(corrected_rmse(2.0, 0.0), 2.0);
        let info = ReferenceInfo::from_stderr(64, 1.0, &[[1.0, 1.0, 1.0], [3.0, 3.0, 3.0]]);
        assert_eq!(info.mean_stderr, 2.0);
        assert_eq!(info.rms_stderr, 5f64.sqrt());
    }

    /// Writing and reading back gives the same rows bit for bit, quoting included.
    #[test]
    fn csv_round_trip() {
        let rows = sample_rows();
        let path = scratch("rows.csv");
        write_csv(&rows, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().next(), Some(CSV_HEADER));
        assert_eq!(text.lines().count(), rows.len() + 1);
        assert!(text.contains("\nfig4,analytic,,0.5,"));
        assert!(text.contains("\n\"a \"\"quoted\"\", scene\",\"odd,name\",7,"));
        assert_eq!(read_csv(&path).unwrap(), rows);
    }

    /// The whole report survives JSON; NaN comes back as NaN.
    #[test]
    fn json_round_trip() {
        let mut rows = sample_rows();
        let reference = ReferenceInfo {
            spp: 4096,
            seconds: 300.0,
            mean_stderr: 8e-4,
            rms_stderr: 1e-3,
        };
        let report = BenchReport::new("fig4", 320, 240, reference.clone(), rows.clone());
        assert!(!report.equal_time.is_empty());
        assert_eq!(report.speed_ratios.per_triangle_over_analytic, Some(4.0));
        assert_eq!(report.speed_ratios.analytic_over_unshadowed, Some(4.0));
        assert_eq!(report.speed_ratios.per_triangle_over_unshadowed, Some(16.0));
        let path = scratch("report.json");
        write_json(&report, &path).unwrap();
        assert_eq!(read_json(&path).unwrap(), report);

        rows[0].mae = f64::NAN;
        let report = BenchReport::new("fig4", 320, 240, reference, rows);
        write_json(&report, &path).unwrap();
        let back = read_json(&path).unwrap();
        assert!(back.rows[0].mae.is_nan());
        assert_eq!(back.rows[1..], report.rows[1..]);
    }

    #[test]
    fn speed_ratios_take_the_fastest_and_skip_missing() {
        let rows = vec![
            row("analytic", None, 0.6, 1e-3),
            row("analytic", None, 0.5, 1e-3),
            row("per-triangle", None, 1.5, 1e-3),
        ];
        let s = SpeedRatios::from_rows(&rows);
        assert_eq!(s.analytic_seconds, Some(0.5));
        assert_eq!(s.per_triangle_over_analytic, Some(3.0));
        assert_eq!(s.unshadowed_seconds, None);
        assert_eq!(s.analytic_over_unshadowed, None);
    }
}
