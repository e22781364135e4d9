//! `penumbra fit-ltc`, `ltc-error`, `ltc-import-three`: the LTC table's fit, error and import.

use anyhow::{Context, Result, bail};
use std::path::Path;

/// `--ltc-table`: `embedded`, `published` or a table file, optionally followed by `+renorm`
/// (horizon renormalisation). Tables other than the embedded ones live for the whole run.
pub fn ltc_table(spec: &str) -> Result<&'static penumbra::ltc::LtcTable> {
    penumbra::render::request::ltc_table(spec).map_err(anyhow::Error::msg)
}

/// `penumbra ltc-error`: the polygon-integral error map of `tables` (and of LTCs fitted at
/// the map's cells with the objectives `fits`), as CSV, PNG and a printed summary.
pub(crate) fn ltc_error(
    tables: &[String],
    fits: &[String],
    out: &Path,
    m: usize,
    k: usize,
) -> Result<()> {
    use penumbra::Choice;
    use penumbra::ltc::error_map::{Source, compute_map, heat_map_png, summarize, to_csv};
    use penumbra::ltc::fit::{FitOptions, Objective, fit_grid};
    std::fs::create_dir_all(out).with_context(|| format!("{}", out.display()))?;
    let start = web_time::Instant::now();
    let mut sources = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for t in tables {
        sources.push(Source::Table(ltc_table(t)?));
        names.push(t.clone());
    }
    for f in fits {
        let mut parts = f.split('+');
        let obj = parts.next().unwrap_or_default();
        let objective = Objective::named(obj).ok_or_else(|| {
            let names: Vec<&str> = Objective::names().collect();
            anyhow::anyhow!("objective '{obj}': expected one of {}", names.join(", "))
        })?;
        let mut fo = FitOptions {
            objective,
            renormalize: false,
            cosine_tail: false,
        };
        for flag in parts {
            match flag {
                "renorm" => fo.renormalize = true,
                "cosine" if matches!(objective, Objective::Polygons | Objective::Combined) => {
                    fo.cosine_tail = true
                }
                _ => bail!(
                    "--fit {f}: unknown option +{flag} (expected +renorm, or +cosine with polygons)"
                ),
            }
        }
        // The map's grid plus a normal-incidence column to start every row from.
        let grid = penumbra::ltc::polygon_error::map_grid(m);
        let alphas: Vec<f64> = (0..m).map(|i| grid[i * m].3).collect();
        let mut cosines = vec![1.0];
        cosines.extend((0..m).map(|j| grid[j].2));
        let cells = fit_grid(&alphas, &cosines, &fo, |_, _| {});
        let entries = (0..m * m)
            .map(|q| cells[(q / m) * (m + 1) + q % m + 1].entry)
            .collect();
        eprintln!(
            "fitted {f} at the map's cells: {:.1} s",
            start.elapsed().as_secs_f64()
        );
        sources.push(Source::Entries(entries));
        names.push(format!("fit {f}"));
    }
    let cells = compute_map(&sources, m, k);
    let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
    std::fs::write(out.join("ltc_error.csv"), to_csv(&cells, &name_refs))?;
    heat_map_png(&cells, &name_refs, m, &out.join("ltc_error.png"))?;
    say!(
        "{m}x{m} configurations, {} polygons each, {k}x{k} oracle samples, {:.1} s",
        cells[0].oracle.values.len(),
        start.elapsed().as_secs_f64()
    );
    say!(
        "table | RMS all | RMS (θv>=60°, α<=0.4) | median cell RMS | max cell RMS (cosθv, α) | max rel (>=10% lobe) | mean signed | max CI"
    );
    for (t, name) in names.iter().enumerate() {
        let s = summarize(&cells, t);
        say!(
            "{name} | {:.4} | {:.4} | {:.4} | {:.4} ({:.3}, {:.3}) | {:.3} | {:+.4} | {:.1e}",
            s.rms_all,
            s.rms_grazing_glossy,
            s.median_cell_rms,
            s.max_cell_rms.0,
            s.max_cell_rms.1,
            s.max_cell_rms.2,
            s.max_rel_big,
            s.mean_signed,
            s.max_ci
        );
    }
    say!("wrote {}", out.display());
    Ok(())
}

/// `penumbra ltc-import-three`: three.js's published table into our format.
pub fn import_three(js: &Path, out: &Path) -> Result<()> {
    let text = std::fs::read_to_string(js).with_context(|| format!("{}", js.display()))?;
    let table = penumbra::ltc::published::from_three_js(&text)
        .with_context(|| format!("{}", js.display()))?;
    table
        .save(out)
        .with_context(|| format!("{}", out.display()))?;
    say!("wrote {}", out.display());
    Ok(())
}

/// What `penumbra fit-ltc` is asked to fit.
pub(crate) struct FitRequest<'a> {
    pub(crate) out: &'a Path,
    pub(crate) size: usize,
    pub(crate) objective: Option<penumbra::ltc::fit::Objective>,
    pub(crate) no_renorm: bool,
    pub(crate) no_cosine_tail: bool,
    pub(crate) rows: Option<(usize, usize)>,
    pub(crate) base: Option<&'a str>,
    pub(crate) report: Option<&'a Path>,
}

/// `penumbra fit-ltc`: the whole table, or some rows of a base table fitted again.
pub fn fit_ltc(req: &FitRequest) -> Result<()> {
    let start = web_time::Instant::now();
    let mut fo = penumbra::ltc::fit::FitOptions::default();
    if let Some(o) = req.objective {
        fo.objective = o;
    }
    fo.renormalize = !req.no_renorm;
    // The tail is fitted only with the polygon objectives (fit_cell ignores it otherwise).
    fo.cosine_tail = !req.no_cosine_tail;
    let table = match (req.rows, req.base) {
        (Some((first, last)), Some(base)) => {
            penumbra::ltc::fit::refit_rows(ltc_table(base)?, first, last, &fo)
                .map_err(anyhow::Error::msg)?
        }
        _ => {
            let size = req.size;
            let (table, cells) =
                penumbra::ltc::fit::fit_table_cells_with(size, &fo, |done, total| {
                    if done % size == 0 {
                        eprintln!("  {done}/{total}");
                    }
                });
            if let Some(path) = req.report {
                std::fs::write(path, penumbra::ltc::fit::report_tsv(&table, &cells))
                    .with_context(|| format!("{}", path.display()))?;
            }
            table
        }
    };
    table
        .save(req.out)
        .with_context(|| format!("{}", req.out.display()))?;
    say!(
        "wrote {} in {:.1} s",
        req.out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
