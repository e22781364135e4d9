//! The files of a bench run: CSV and JSON tables, charts, the equal-time image strip, and the
//! Markdown tables printed by the CLI and quoted in `docs/benchmarks.md`.

use super::equal_time::{ErrorMetric, Estimate, LogLadder, error_vs_time_chart};
use super::plot::{Chart, Series, save_chart_png, save_chart_svg};
use super::runner::BenchImage;
use super::scaling::ScalingReport;
use super::table::{BenchReport, write_csv, write_json};
use crate::Result;
use crate::error::InFile;
use crate::render::image_io::write_png;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn estimate(e: &Option<Estimate>, digits: usize) -> String {
    match e {
        Some(e) if e.value.is_finite() => {
            format!(
                "{:.*e}{}",
                digits,
                e.value,
                if e.extrapolated { "*" } else { "" }
            )
        }
        _ => "–".into(),
    }
}

/// The equal-time table (000 Fig. 6) as Markdown: per method, its error at the analytic
/// method's time t* and the time it needs for the analytic method's error. `*` marks values
/// extrapolated beyond the ladder.
pub fn equal_time_markdown(report: &BenchReport) -> String {
    let mut s = String::new();
    let t_star = report
        .equal_time
        .first()
        .map_or(f64::NAN, |r| r.target_seconds);
    let target = report.equal_time.first();
    let _ = writeln!(
        s,
        "Scene `{}`, {}×{}, reference {} spp (rms stderr {:.2e}); analytic: t* = {:.3} s, \
         RMSE {:.3e}, corrected RMSE {:.3e}.\n",
        report.scene,
        report.width,
        report.height,
        report.reference.spp,
        report.reference.rms_stderr,
        t_star,
        target.map_or(f64::NAN, |r| r.rmse.target_error),
        target.map_or(f64::NAN, |r| r.rmse_corrected.target_error),
    );
    let _ = writeln!(
        s,
        "| method | MAE at t* | RMSE at t* | corrected RMSE at t* | time for analytic corrected RMSE | × t* | × t* to reach the reference noise |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    let target_corrected = target.map_or(f64::NAN, |r| r.rmse_corrected.target_error);
    for r in &report.equal_time {
        // Matching is done on the corrected RMSE: the raw RMSE of an exact method is the
        // reference's own noise, which no other method can get below.
        let m = &r.rmse_corrected;
        // An extrapolation more than 100× past the ladder's longest render reads a flattening
        // curve (a denoiser's bias, the LTC bias) as a slow decay: report it as not reached.
        let longest = report
            .rows
            .iter()
            .filter(|x| x.method == r.method && x.seconds.is_finite())
            .map(|x| x.seconds)
            .fold(0.0f64, f64::max);
        let credible = |e: &Estimate| !e.extrapolated || e.value <= 100.0 * longest;
        let (time, ratio) = match (&m.time_to_match, m.time_ratio) {
            (Some(e), Some(x)) if credible(e) => {
                let star = if e.extrapolated { "*" } else { "" };
                (format!("{:.3} s{star}", e.value), format!("{x:.1}{star}"))
            }
            (Some(_), _) => (
                format!("not reached in {longest:.2} s"),
                format!("> {:.0}", longest / r.target_seconds),
            ),
            _ => ("–".into(), "never".into()),
        };
        // Below a method's cheapest rung, extrapolating toward zero time is meaningless
        // (renders have a fixed cost): show the cheapest rung's error as a lower bound.
        let cheapest = report
            .rows
            .iter()
            .filter(|x| x.method == r.method && x.seconds.is_finite())
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds));
        let at = |e: &Option<Estimate>, of: fn(&super::table::BenchRow) -> f64| match cheapest {
            Some(c) if !r.deterministic && r.target_seconds < c.seconds => format!(
                "> {:.2e} (its {} spp takes {:.3} s)",
                of(c),
                c.spp.unwrap_or(0),
                c.seconds
            ),
            _ => estimate(e, 2),
        };
        // Where the analytic error is below what the reference can resolve, the time a method
        // needs to reach the reference's own noise (rms stderr) is a lower bound on the time it
        // needs for the analytic error.
        let below_noise = target_corrected < report.reference.rms_stderr;
        let floor = if r.deterministic || !below_noise {
            "–".to_string()
        } else {
            let ladder = LogLadder::new(
                report
                    .rows
                    .iter()
                    .filter(|x| x.method == r.method)
                    .map(|x| (x.seconds, x.rmse_corrected)),
            );
            match ladder.time_for(report.reference.rms_stderr) {
                Some(e) if credible(&e) => format!(
                    "{:.0}{}",
                    e.value / r.target_seconds,
                    if e.extrapolated { "*" } else { "" }
                ),
                Some(_) => format!("> {:.0}", longest / r.target_seconds),
                None => "–".into(),
            }
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            r.method,
            at(&r.mae.error_at_target_time, |x| x.mae),
            at(&r.rmse.error_at_target_time, |x| x.rmse),
            at(&r.rmse_corrected.error_at_target_time, |x| x.rmse_corrected),
            time,
            ratio,
            floor
        );
    }
    s.push_str(&noise_markdown(report));
    let sr = &report.speed_ratios;
    let f = |x: Option<f64>| x.map_or("–".into(), |v| format!("{v:.2}"));
    let _ = writeln!(
        s,
        "\nSpeed: analytic {} s, per-triangle {} s, unshadowed {} s; per-triangle / analytic = {}, \
         analytic / unshadowed = {}.",
        f(sr.analytic_seconds),
        f(sr.per_triangle_seconds),
        f(sr.unshadowed_seconds),
        f(sr.per_triangle_over_analytic),
        f(sr.analytic_over_unshadowed)
    );
    s
}

/// The method the noise table compares with: the LTC corrected by sampling inside the exact
/// visible polygon.
const NOISE_TARGET: &str = "analytic-exact";

/// How long each stochastic method takes to bring its corrected RMSE (its own error, the
/// reference's noise taken out) down to the reference's noise (its rms standard error), and
/// how many times longer than `analytic-exact` that is. A biased method never gets there.
/// Read from the ladder in log–log like the equal-time table; `*` marks an extrapolation.
pub(crate) fn noise_markdown(report: &BenchReport) -> String {
    let noise = report.reference.rms_stderr;
    let mut methods: Vec<&str> = Vec::new();
    for r in report.rows.iter().filter(|r| r.spp.is_some()) {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    if methods.is_empty() || noise.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return String::new();
    }
    let time_to_noise = |method: &str| -> (Option<Estimate>, f64) {
        let rows = || report.rows.iter().filter(move |x| x.method == method);
        let longest = rows()
            .map(|x| x.seconds)
            .filter(|t| t.is_finite())
            .fold(0.0f64, f64::max);
        // Already at the noise on some rung: the cheapest such rung.
        let reached = rows()
            .filter(|x| x.rmse_corrected <= noise && x.seconds.is_finite())
            .map(|x| x.seconds)
            .min_by(f64::total_cmp);
        let crossing = LogLadder::new(rows().map(|x| (x.seconds, x.rmse_corrected)))
            .time_for(noise)
            .filter(|e| !e.extrapolated || e.value <= 100.0 * longest);
        let e = match (crossing, reached) {
            (Some(c), _) if !c.extrapolated => Some(c),
            (_, Some(t)) => Some(Estimate {
                value: t,
                extrapolated: false,
                basis: super::equal_time::Basis::Bracketed,
            }),
            (c, None) => c,
        };
        (e, longest)
    };
    let (target, _) = time_to_noise(NOISE_TARGET);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\nTime to reach the reference's noise (corrected RMSE ≤ rms stderr {noise:.2e}):\n"
    );
    let _ = writeln!(s, "| method | time | × {NOISE_TARGET} |");
    let _ = writeln!(s, "|---|---|---|");
    for m in methods {
        let (e, longest) = time_to_noise(m);
        let (time, ratio) = match e {
            Some(e) => {
                let star = if e.extrapolated { "*" } else { "" };
                let ratio = target.map_or("–".into(), |t| {
                    format!("{:.1}{star}", e.value / t.value.max(1e-12))
                });
                (format!("{:.3} s{star}", e.value), ratio)
            }
            None => (format!("not reached in {longest:.2} s"), "–".into()),
        };
        let _ = writeln!(s, "| {m} | {time} | {ratio} |");
    }
    s
}

/// The time-against-RMSE chart of a report, with the reference's own noise level drawn as a
/// horizontal line (errors near it are dominated by the reference, not the method).
pub fn time_vs_rmse_chart(report: &BenchReport) -> Chart {
    let mut chart = error_vs_time_chart(
        &report.rows,
        ErrorMetric::Rmse,
        &format!("{}: run time against RMSE", report.scene),
    );
    let times: Vec<f64> = report
        .rows
        .iter()
        .map(|r| r.seconds)
        .filter(|t| t.is_finite() && *t > 0.0)
        .collect();
    let (lo, hi) = times
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    if lo < hi && report.reference.rms_stderr > 0.0 {
        chart.series.push(Series {
            name: "reference noise".into(),
            points: vec![
                (lo, report.reference.rms_stderr),
                (hi, report.reference.rms_stderr),
            ],
            connect: true,
        });
    }
    chart
}

/// Writes `chart` as `dir/STEM.png` and `dir/STEM.svg`, 900×600 (one description, two back
/// ends: `figure::plot::chart_figure`), and lists both in `files`.
fn save_chart(chart: &Chart, dir: &Path, stem: &str, files: &mut Vec<PathBuf>) -> Result<()> {
    let png = dir.join(format!("{stem}.png"));
    save_chart_png(chart, 900, 600, &png)?;
    files.push(png);
    let svg = dir.join(format!("{stem}.svg"));
    save_chart_svg(chart, 900, 600, &svg)?;
    files.push(svg);
    Ok(())
}

/// Writes `bench.csv`, `bench.json`, `equal_time.md`, `time_vs_rmse.png` and `.svg`, and one
/// PNG per method of the equal-time strip into `dir`.
pub fn write_bench_files(
    report: &BenchReport,
    strip: &[BenchImage],
    dir: &Path,
    exposure: f64,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).in_file(dir.display(), "cannot create")?;
    let mut files = Vec::new();
    let csv = dir.join("bench.csv");
    write_csv(&report.rows, &csv).in_file(csv.display(), "")?;
    files.push(csv);
    let json = dir.join("bench.json");
    write_json(report, &json).in_file(json.display(), "")?;
    files.push(json);
    let md = dir.join("equal_time.md");
    std::fs::write(&md, equal_time_markdown(report)).in_file(md.display(), "")?;
    files.push(md);
    save_chart(&time_vs_rmse_chart(report), dir, "time_vs_rmse", &mut files)?;
    for img in strip {
        let name = match img.spp {
            Some(n) => format!("strip_{}_{n}spp.png", img.label),
            None => format!("strip_{}.png", img.label),
        };
        let p = dir.join(name);
        write_png(
            &p,
            img.image.width,
            img.image.height,
            &img.image.to_rgb32(),
            exposure,
        )?;
        files.push(p);
    }
    Ok(files)
}

/// The scaling fits as Markdown.
pub fn scaling_markdown(report: &ScalingReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}×{}, best of the repeats.\n",
        report.width, report.height
    );
    let _ = writeln!(
        s,
        "| series | method | x | slope (µs per vertex) | intercept (s) | R² |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for f in &report.fits {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {:.3} | {:.4} |",
            f.series,
            f.method,
            f.x,
            f.slope * 1e6,
            f.intercept,
            f.r2
        );
    }
    if let Some(r) = report.naive_over_silhouette_slope {
        let _ = writeln!(
            s,
            "\nFig. 7: the naive per-face slope is {r:.2}× the silhouette slope (000 reports more than 2×)."
        );
    }
    let _ = writeln!(
        s,
        "\n| series | method | step | light vertices | occluder vertices | seconds |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for p in &report.points {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.3} |",
            p.series, p.method, p.step, p.light_vertices, p.occluder_vertices, p.seconds
        );
    }
    s
}

/// Writes `scaling.json`, `scaling.md`, `fig5_scaling.png` and `fig7_scaling.png` into `dir`.
pub fn write_scaling_files(report: &ScalingReport, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).in_file(dir.display(), "cannot create")?;
    let mut files = Vec::new();
    let json = dir.join("scaling.json");
    std::fs::write(&json, serde_json::to_string_pretty(report)?).in_file(json.display(), "")?;
    files.push(json);
    let md = dir.join("scaling.md");
    std::fs::write(&md, scaling_markdown(report)).in_file(md.display(), "")?;
    files.push(md);
    let series = |name: &str, method: &str, light: bool| Series {
        name: format!(
            "{method}: {} vertices",
            if light { "light" } else { "occluder" }
        ),
        points: report
            .points
            .iter()
            .filter(|p| p.series == name && p.method == method)
            .map(|p| {
                let x = if light {
                    p.light_vertices
                } else {
                    p.occluder_vertices
                };
                (x as f64, p.seconds)
            })
            .collect(),
        connect: true,
    };
    let fig5 = Chart {
        title: "000 Fig. 5: run time against vertices (duplicated lights / occluders)".into(),
        x_label: "vertices".into(),
        y_label: "time (s)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            series("fig5_lights", "analytic", true),
            series("fig5_occluders", "analytic", false),
        ],
    };
    save_chart(&fig5, dir, "fig5_scaling", &mut files)?;
    let fig7 = Chart {
        title: "000 Fig. 7: subdivided icosahedral light, silhouette vs naive per face".into(),
        x_label: "light vertices".into(),
        y_label: "time (s)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            series("fig7", "analytic", true),
            series("fig7", "per-triangle", true),
        ],
    };
    save_chart(&fig7, dir, "fig7_scaling", &mut files)?;
    Ok(files)
}
