//! Equal-time comparison (000 Fig. 6 style): what error every other method reaches in the time
//! the analytic method takes, and how long it needs to reach the analytic method's error.
//!
//! A stochastic method is run at a ladder of budgets (samples per pixel); each rung gives a
//! point (time, error). Between rungs the error is interpolated piecewise linearly in
//! log(time)–log(error): Monte Carlo error falls as a power of the budget (∝ spp^−½) and time
//! grows about linearly with it, so such a ladder is a straight line in log–log and the
//! interpolation is exact for it. Rules for awkward ladders:
//!
//! * **Outside the ladder** the end segment (the two cheapest or the two dearest rungs) is
//!   extended with its slope, and the estimate is flagged `extrapolated`.
//! * **Error 0** (or negative, NaN) has no logarithm. Such a rung is left out of that metric's
//!   ladder and counted in `dropped_points`; `rmse_corrected` is 0 whenever the error is below
//!   what the reference's noise resolves, so this happens at the dear end of a ladder. A
//!   non-positive *target* error cannot be reached on a log scale either: its time-to-match is
//!   `None`. Rungs with a time that is not positive and finite are dropped likewise.
//! * **Equal times** (two rungs timed identically) are merged into one point at the mean
//!   log(error).
//! * **Non-monotone ladders** (noise, or timing jitter): the rungs are sorted by time and the
//!   error at a time comes from the one segment whose times bracket it, whatever the errors do.
//!   The time to reach an error is the *earliest* crossing: segments are scanned in order of
//!   time and the first whose two errors bracket the target is used. With no bracketing segment
//!   the end segment on the target's side is extended only if its error falls with time;
//!   otherwise the answer is `None`.
//! * **A single rung** gives no trend: the error at any time is that rung's error, flagged
//!   `extrapolated` unless the time is the rung's own, and the time to reach an error is
//!   `None`.
//! * **Deterministic methods** (every row with `spp == None`) have one point whatever the
//!   budget: their error is reported as it is (not extrapolated) and their time-to-match is
//!   their own time when their error is within `MATCH_TOLERANCE` of the target's (more time
//!   would not lower it), `None` otherwise.

use super::plot::{Chart, Series};
use super::table::{BenchRow, f64_or_nan};

/// Relative tolerance within which a deterministic method's error counts as equal to the
/// target's: two exact methods differ by rounding only, far below the reference's noise.
pub(crate) const MATCH_TOLERANCE: f64 = 1e-3;

/// One of the error columns of a [`BenchRow`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum ErrorMetric {
    Mae,
    Rmse,
    RmseCorrected,
}

impl ErrorMetric {
    pub(crate) fn of(self, row: &BenchRow) -> f64 {
        match self {
            ErrorMetric::Mae => row.mae,
            ErrorMetric::Rmse => row.rmse,
            ErrorMetric::RmseCorrected => row.rmse_corrected,
        }
    }

    /// The column name, as in the CSV.
    pub(crate) fn name(self) -> &'static str {
        match self {
            ErrorMetric::Mae => "mae",
            ErrorMetric::Rmse => "rmse",
            ErrorMetric::RmseCorrected => "rmse_corrected",
        }
    }
}

/// Where an [`Estimate`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    /// Interpolated on the segment whose ends bracket the query (or a rung itself).
    Bracketed,
    /// The end segment extended past the ladder.
    EndSegment,
    /// The method's only point.
    SinglePoint,
}

/// A value read off a ladder.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    #[serde(deserialize_with = "f64_or_nan")]
    pub value: f64,
    /// The query lies outside the ladder (or the ladder has one rung).
    pub extrapolated: bool,
    pub basis: Basis,
}

/// One rung of a ladder: time and error, and their logarithms.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rung {
    x: f64,
    y: f64,
    time: f64,
    error: f64,
}

/// The points of one method's ladder for one metric, sorted by time, in log–log.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct LogLadder {
    rungs: Vec<Rung>,
    /// Points left out: error or time not positive and finite.
    pub dropped: usize,
}

/// The y of the line through `a` and `b` at `x` (in whichever coordinates they are given).
fn interpolate(a: (f64, f64), b: (f64, f64), x: f64) -> f64 {
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

impl Rung {
    fn xy(&self) -> (f64, f64) {
        (self.x, self.y)
    }

    fn yx(&self) -> (f64, f64) {
        (self.y, self.x)
    }
}

impl LogLadder {
    /// From (time, error) points in any order.
    pub fn new(points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        let mut dropped = 0;
        let mut all: Vec<(f64, f64)> = Vec::new();
        for (t, e) in points {
            let ok = |v: f64| v > 0.0 && v.is_finite();
            if ok(t) && ok(e) {
                all.push((t, e));
            } else {
                dropped += 1;
            }
        }
        all.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Merge rungs with identical times at the mean log error.
        let mut rungs: Vec<Rung> = Vec::with_capacity(all.len());
        let mut i = 0;
        while i < all.len() {
            let j = i + all[i..].iter().take_while(|p| p.0 == all[i].0).count();
            let (time, error) = if j == i + 1 {
                all[i]
            } else {
                let y = all[i..j].iter().map(|p| p.1.ln()).sum::<f64>() / (j - i) as f64;
                (all[i].0, y.exp())
            };
            rungs.push(Rung {
                x: time.ln(),
                y: error.ln(),
                time,
                error,
            });
            i = j;
        }
        LogLadder { rungs, dropped }
    }

    /// Distinct points kept.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.rungs.len()
    }

    /// The error at time `t`. `None` for an empty ladder or a time that is not positive and
    /// finite. A rung's own time gives its error exactly.
    pub(crate) fn error_at(&self, t: f64) -> Option<Estimate> {
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let p = &self.rungs;
        if let Some(r) = p.iter().find(|r| r.time == t) {
            let basis = if p.len() == 1 {
                Basis::SinglePoint
            } else {
                Basis::Bracketed
            };
            return Some(Estimate {
                value: r.error,
                extrapolated: false,
                basis,
            });
        }
        let x = t.ln();
        let (y, basis) = match p.len() {
            0 => return None,
            1 => {
                return Some(Estimate {
                    value: p[0].error,
                    extrapolated: true,
                    basis: Basis::SinglePoint,
                });
            }
            _ if x < p[0].x => (interpolate(p[0].xy(), p[1].xy(), x), Basis::EndSegment),
            n if x > p[n - 1].x => (
                interpolate(p[n - 2].xy(), p[n - 1].xy(), x),
                Basis::EndSegment,
            ),
            _ => {
                // p[i].x <= x < p[i + 1].x
                let i = p.partition_point(|q| q.x <= x) - 1;
                (interpolate(p[i].xy(), p[i + 1].xy(), x), Basis::Bracketed)
            }
        };
        Some(estimate(y, basis))
    }

    /// The earliest time at which the ladder reaches error `e` (see the module notes). A
    /// rung's own error gives its time exactly.
    pub(crate) fn time_for(&self, e: f64) -> Option<Estimate> {
        if !(e > 0.0 && e.is_finite()) || self.rungs.len() < 2 {
            return None;
        }
        let p = &self.rungs;
        let y = e.ln();
        let exact = |r: &Rung| Estimate {
            value: r.time,
            extrapolated: false,
            basis: Basis::Bracketed,
        };
        for w in p.windows(2) {
            let (a, b) = (w[0], w[1]);
            if a.error == e {
                return Some(exact(&a));
            }
            if b.error == e {
                return Some(exact(&b));
            }
            if a.y.min(b.y) < y && y < a.y.max(b.y) {
                return Some(estimate(interpolate(a.yx(), b.yx(), y), Basis::Bracketed));
            }
        }
        let n = p.len();
        let (a, b) = if p.iter().all(|q| q.y > y) {
            (p[n - 2], p[n - 1])
        } else if p.iter().all(|q| q.y < y) {
            (p[0], p[1])
        } else {
            return None;
        };
        // Extend only an end segment whose error falls with time.
        (b.y < a.y).then(|| estimate(interpolate(a.yx(), b.yx(), y), Basis::EndSegment))
    }
}

/// An estimate from a log value.
fn estimate(log_value: f64, basis: Basis) -> Estimate {
    Estimate {
        value: log_value.exp(),
        extrapolated: basis != Basis::Bracketed,
        basis,
    }
}

/// The method everything is compared with: its time t* and its errors.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Target {
    pub method: String,
    pub seconds: f64,
    pub mae: f64,
    pub rmse: f64,
    pub rmse_corrected: f64,
}

impl Target {
    pub(crate) fn from_row(row: &BenchRow) -> Self {
        Target {
            method: row.method.clone(),
            seconds: row.seconds,
            mae: row.mae,
            rmse: row.rmse,
            rmse_corrected: row.rmse_corrected,
        }
    }

    /// The fastest row of `method` (finite times only).
    pub(crate) fn fastest(rows: &[BenchRow], method: &str) -> Option<Self> {
        rows.iter()
            .filter(|r| r.method == method && r.seconds.is_finite())
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
            .map(Target::from_row)
    }

    pub(crate) fn error(&self, metric: ErrorMetric) -> f64 {
        match metric {
            ErrorMetric::Mae => self.mae,
            ErrorMetric::Rmse => self.rmse,
            ErrorMetric::RmseCorrected => self.rmse_corrected,
        }
    }
}

/// One metric of one method against the target.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MetricAtTarget {
    /// The target method's own error.
    #[serde(deserialize_with = "f64_or_nan")]
    pub target_error: f64,
    /// This method's error at the target's time t*.
    pub error_at_target_time: Option<Estimate>,
    /// The time this method needs to reach `target_error`.
    pub time_to_match: Option<Estimate>,
    /// `time_to_match / t*`: how many times longer than the target this method takes for the
    /// same error.
    pub time_ratio: Option<f64>,
    /// Rungs left out of the log–log ladder (error or time not positive and finite).
    pub dropped_points: usize,
}

/// One method against the target method at equal time.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EqualTimeRow {
    pub method: String,
    pub target_method: String,
    /// t*: the target method's time.
    pub target_seconds: f64,
    /// Every row of the method has `spp == None`.
    pub deterministic: bool,
    /// Rows of the method.
    pub points: usize,
    pub mae: MetricAtTarget,
    pub rmse: MetricAtTarget,
    pub rmse_corrected: MetricAtTarget,
}

impl EqualTimeRow {}

/// The distinct methods of `rows`, in order of first appearance.
pub(crate) fn methods(rows: &[BenchRow]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        if !names.contains(&r.method.as_str()) {
            names.push(&r.method);
        }
    }
    names
}

fn ratio(time: Option<Estimate>, t_star: f64) -> Option<f64> {
    time.filter(|_| t_star > 0.0 && t_star.is_finite())
        .map(|t| t.value / t_star)
}

/// One method's metric against the target.
fn metric_at_target(
    rows: &[&BenchRow],
    deterministic: bool,
    metric: ErrorMetric,
    target: &Target,
) -> MetricAtTarget {
    let target_error = target.error(metric);
    if deterministic {
        // The fastest run stands for the method (the others were slowed by something else).
        let Some(row) = rows
            .iter()
            .filter(|r| r.seconds.is_finite())
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        else {
            return MetricAtTarget {
                target_error,
                error_at_target_time: None,
                time_to_match: None,
                time_ratio: None,
                dropped_points: rows.len(),
            };
        };
        let err = metric.of(row);
        let single = |value| Estimate {
            value,
            extrapolated: false,
            basis: Basis::SinglePoint,
        };
        let time_to_match =
            (err <= target_error * (1.0 + MATCH_TOLERANCE) && err.is_finite() && row.seconds > 0.0)
                .then(|| single(row.seconds));
        return MetricAtTarget {
            target_error,
            error_at_target_time: err.is_finite().then(|| single(err)),
            time_to_match,
            time_ratio: ratio(time_to_match, target.seconds),
            dropped_points: 0,
        };
    }
    let ladder = LogLadder::new(rows.iter().map(|r| (r.seconds, metric.of(r))));
    let time_to_match = ladder.time_for(target_error);
    MetricAtTarget {
        target_error,
        error_at_target_time: ladder.error_at(target.seconds),
        time_to_match,
        time_ratio: ratio(time_to_match, target.seconds),
        dropped_points: ladder.dropped,
    }
}

/// Every method of `rows` other than the target's, at the target's time and error.
pub(crate) fn equal_time(rows: &[BenchRow], target: &Target) -> Vec<EqualTimeRow> {
    methods(rows)
        .into_iter()
        .filter(|m| *m != target.method)
        .map(|method| {
            let mine: Vec<&BenchRow> = rows.iter().filter(|r| r.method == method).collect();
            let deterministic = mine.iter().all(|r| r.spp.is_none());
            let at = |metric| metric_at_target(&mine, deterministic, metric, target);
            EqualTimeRow {
                method: method.to_string(),
                target_method: target.method.clone(),
                target_seconds: target.seconds,
                deterministic,
                points: mine.len(),
                mae: at(ErrorMetric::Mae),
                rmse: at(ErrorMetric::Rmse),
                rmse_corrected: at(ErrorMetric::RmseCorrected),
            }
        })
        .collect()
}

/// The chart of 000 Fig. 6: `metric` against time on log–log axes, one series per method
/// (ladders joined in order of time, deterministic methods as single markers).
pub(crate) fn error_vs_time_chart(rows: &[BenchRow], metric: ErrorMetric, title: &str) -> Chart {
    let series = methods(rows)
        .into_iter()
        .map(|method| {
            let mut points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == method)
                .map(|r| (r.seconds, metric.of(r)))
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series {
                name: method.to_string(),
                connect: points.len() > 1,
                points,
            }
        })
        .collect();
    Chart {
        title: title.to_string(),
        x_label: "time (s)".to_string(),
        y_label: metric.name().to_string(),
        x_log: true,
        y_log: true,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
    }

    fn row(method: &str, spp: Option<u32>, seconds: f64, err: f64) -> BenchRow {
        BenchRow {
            scene: "s".into(),
            method: method.into(),
            spp,
            seconds,
            mae: err,
            rmse: err,
            relative_rmse: err,
            rmse_corrected: err,
            ..BenchRow::default()
        }
    }

    /// Hand-computed: between (1 s, 0.4) and (4 s, 0.1), the slope in log–log is −1, so at
    /// 2 s the error is 0.2; 0.1 is reached at 4 s, 0.05 at 8 s by extension (flagged), and
    /// 0.8 at 0.5 s backwards (flagged).
    #[test]
    fn interpolation_by_hand() {
        let l = LogLadder::new([(4.0, 0.1), (1.0, 0.4)]);
        let e = l.error_at(2.0).unwrap();
        assert!(close(e.value, 0.2) && !e.extrapolated && e.basis == Basis::Bracketed);
        assert_eq!(l.error_at(4.0).unwrap().value, 0.1);
        let e = l.error_at(16.0).unwrap();
        assert!(close(e.value, 0.025) && e.extrapolated && e.basis == Basis::EndSegment);
        let e = l.error_at(0.25).unwrap();
        assert!(close(e.value, 1.6) && e.extrapolated);

        let t = l.time_for(0.2).unwrap();
        assert!(close(t.value, 2.0) && !t.extrapolated);
        assert_eq!(l.time_for(0.1).unwrap().value, 4.0);
        let t = l.time_for(0.05).unwrap();
        assert!(close(t.value, 8.0) && t.extrapolated && t.basis == Basis::EndSegment);
        let t = l.time_for(0.8).unwrap();
        assert!(close(t.value, 0.5) && t.extrapolated);

        // Slope −1/2 by hand: (1, 1) → (100, 0.1); at 10 s the error is 10^−½.
        let l = LogLadder::new([(1.0, 1.0), (100.0, 0.1)]);
        assert!(close(l.error_at(10.0).unwrap().value, 0.1f64.sqrt()));
    }

    /// error = c/√spp, time = k·spp: both lines in log–log, so interpolation and extrapolation
    /// give the closed forms c·√(k/t) and k·(c/e)² to rounding, everywhere.
    #[test]
    fn synthetic_ladder_matches_closed_form() {
        let (c, k) = (0.37, 2.5e-3);
        let ladder: Vec<(f64, f64)> = [1u32, 2, 4, 8, 16, 64, 256, 1024]
            .iter()
            .map(|&s| (k * s as f64, c / (s as f64).sqrt()))
            .collect();
        let l = LogLadder::new(ladder.iter().copied());
        for t in [1e-4, 2.5e-3, 3e-3, 0.01, 0.1234, 1.0, 2.56, 10.0, 100.0] {
            let e = l.error_at(t).unwrap();
            assert!(close(e.value, c * (k / t).sqrt()), "t = {t}: {}", e.value);
            assert_eq!(e.extrapolated, !(2.5e-3..=2.56).contains(&t), "t = {t}");
        }
        for e in [1.0, 0.37, 0.1, 0.0123, 1e-3] {
            let t = l.time_for(e).unwrap();
            assert!(close(t.value, k * (c / e).powi(2)), "e = {e}: {}", t.value);
        }
    }

    /// A noisy ladder: the error at a time uses the bracketing segment; the time for an error
    /// is the earliest crossing; a rising end segment is not extended.
    #[test]
    fn non_monotone_ladder() {
        // Errors 0.4, 0.1, 0.2, 0.05 at times 1, 2, 4, 8 (shuffled on input).
        let l = LogLadder::new([(4.0, 0.2), (1.0, 0.4), (8.0, 0.05), (2.0, 0.1)]);
        // 2..4 rises from 0.1 to 0.2: at √8 s (the log midpoint) the error is √0.02.
        assert!(close(
            l.error_at(8f64.sqrt()).unwrap().value,
            0.02f64.sqrt()
        ));
        // 0.15 is crossed first on 1..2 (falling: ln 0.15 between ln 0.4 and ln 0.1).
        let t = l.time_for(0.15).unwrap().value;
        let expect = ((0.15f64 / 0.4).ln() / 0.25f64.ln() * 2f64.ln()).exp();
        assert!(close(t, expect) && t < 2.0, "{t} vs {expect}");
        // Rising last segment: no extension below the ladder.
        let rising = LogLadder::new([(1.0, 0.4), (2.0, 0.1), (4.0, 0.2)]);
        assert!(rising.time_for(0.05).is_none());
        assert!(rising.error_at(8.0).unwrap().value > 0.2);
    }

    /// Zeros, NaN, single rungs and equal times never panic and follow the documented rules.
    #[test]
    fn degenerate_ladders() {
        let l = LogLadder::new([
            (1.0, 0.4),
            (2.0, 0.0),
            (4.0, f64::NAN),
            (0.0, 1.0),
            (4.0, 0.1),
        ]);
        assert_eq!((l.len(), l.dropped), (2, 3));
        assert!(close(l.error_at(2.0).unwrap().value, 0.2));
        assert!(l.time_for(0.0).is_none() && l.time_for(f64::NAN).is_none());
        assert!(l.error_at(0.0).is_none() && l.error_at(f64::INFINITY).is_none());

        let one = LogLadder::new([(2.0, 0.3)]);
        let e = one.error_at(5.0).unwrap();
        assert_eq!(
            (e.value, e.extrapolated, e.basis),
            (0.3, true, Basis::SinglePoint)
        );
        assert!(!one.error_at(2.0).unwrap().extrapolated);
        assert!(one.time_for(0.3).is_none());
        assert!(LogLadder::new([]).error_at(1.0).is_none());

        // Equal times merge at the geometric mean of the errors.
        let l = LogLadder::new([(1.0, 0.1), (1.0, 0.4), (2.0, 0.1)]);
        assert_eq!(l.len(), 2);
        assert!(close(l.error_at(1.0).unwrap().value, 0.2));
    }

    /// The whole table: a stochastic ladder, a deterministic method equal to the target and one
    /// worse than it, all checked by hand.
    #[test]
    fn equal_time_table() {
        let mut rows = vec![row("analytic", None, 2.0, 0.01)];
        for (spp, t, e) in [(1, 1.0, 0.4), (4, 4.0, 0.2), (16, 16.0, 0.1)] {
            rows.push(row("mc", Some(spp), t, e));
        }
        rows.push(row("per-triangle", None, 6.0, 0.01 * (1.0 + 1e-9)));
        rows.push(row("unshadowed", None, 1.0, 0.3));
        let target = Target::fastest(&rows, "analytic").unwrap();
        let table = equal_time(&rows, &target);
        let names: Vec<&str> = table.iter().map(|r| r.method.as_str()).collect();
        assert_eq!(names, ["mc", "per-triangle", "unshadowed"]);

        // mc: slope −½; at 2 s the error is 0.4/√2; 0.01 needs (0.4/0.01)² = 1600 s, past
        // the ladder's 16 s: extrapolated, ratio 800.
        let mc = &table[0].rmse;
        assert!(!table[0].deterministic && table[0].points == 3);
        let e = mc.error_at_target_time.unwrap();
        assert!(close(e.value, 0.4 / 2f64.sqrt()) && !e.extrapolated);
        let t = mc.time_to_match.unwrap();
        assert!(close(t.value, 1600.0) && t.extrapolated);
        assert!(close(mc.time_ratio.unwrap(), 800.0));

        let pt = &table[1].rmse;
        assert!(table[1].deterministic);
        assert_eq!(pt.error_at_target_time.unwrap().basis, Basis::SinglePoint);
        assert_eq!(pt.time_to_match.unwrap().value, 6.0);
        assert_eq!(pt.time_ratio, Some(3.0));

        let un = &table[2].mae;
        assert_eq!(un.error_at_target_time.unwrap().value, 0.3);
        assert!(un.time_to_match.is_none() && un.time_ratio.is_none());
    }

    #[test]
    fn chart_has_one_series_per_method() {
        let rows = vec![
            row("analytic", None, 2.0, 0.01),
            row("mc", Some(4), 4.0, 0.2),
            row("mc", Some(1), 1.0, 0.4),
        ];
        let c = error_vs_time_chart(&rows, ErrorMetric::Rmse, "fig4");
        assert_eq!(c.series.len(), 2);
        assert!(!c.series[0].connect && c.series[1].connect);
        assert_eq!(c.series[1].points, [(1.0, 0.4), (4.0, 0.2)]);
    }
}
