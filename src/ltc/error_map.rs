//! The error map of LTC tables over `(θv, α)` (`penumbra ltc-error`): per configuration of
//! [`super::polygon_error::map_grid`], the polygon-integral error of each table against one
//! shared Monte Carlo oracle; written as CSV and as a PNG heat map (docs/ltc.md, "Error on
//! polygon integrals").

use super::polygon_error::{
    CellError, OracleIntegrals, cell_error, entry_error, map_grid, oracle_integrals, test_polygons,
};
use super::table::{LtcEntry, LtcTable};
use crate::figure::font::{Align, TextStyle, draw_text};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

/// One configuration of the map: its grid position, the oracle and each table's error.
pub struct MapCell {
    pub i: usize,
    pub j: usize,
    pub cos_theta_v: f64,
    pub alpha: f64,
    pub oracle: OracleIntegrals,
    /// One per table, in the order given to [`compute_map`].
    pub errors: Vec<CellError>,
}

/// Summary of one table over the map.
#[derive(Clone, Debug, Default)]
pub struct MapSummary {
    /// RMS over all cells and polygons of `|LTC − oracle|/albedo`.
    pub rms_all: f64,
    /// The same restricted to the grazing, glossy cells (θv ≥ 60°, α ≤ 0.4).
    pub rms_grazing_glossy: f64,
    /// Median over the cells of the per-cell RMS.
    pub median_cell_rms: f64,
    /// Largest per-cell RMS, and its `(cosθv, α)`.
    pub max_cell_rms: (f64, f64, f64),
    /// Largest relative error over polygons holding ≥ 10 % of the lobe.
    pub max_rel_big: f64,
    /// Mean of the per-cell mean signed errors (negative: too dark).
    pub mean_signed: f64,
    /// Largest oracle half-width (99.9 %) in units of the albedo.
    pub max_ci: f64,
}

/// Where the map's LTCs come from: a table's lookup, or one entry per map cell (fitted at
/// the cell itself, `entries[i * m + j]`).
pub enum Source<'a> {
    Table(&'a LtcTable),
    Entries(Vec<LtcEntry>),
}

/// `m × m` configurations, `k × k` oracle samples each (cells in parallel).
pub fn compute_map(sources: &[Source], m: usize, k: usize) -> Vec<MapCell> {
    map_grid(m)
        .into_par_iter()
        .map(|(i, j, c, a)| {
            let polys = test_polygons(c);
            let oracle = oracle_integrals(c, a, &polys, k, (i * m + j) as u64);
            let errors = sources
                .iter()
                .map(|s| match s {
                    Source::Table(t) => cell_error(t, c, a, &polys, &oracle),
                    Source::Entries(e) => entry_error(&e[i * m + j], c, a, &polys, &oracle),
                })
                .collect();
            MapCell {
                i,
                j,
                cos_theta_v: c,
                alpha: a,
                oracle,
                errors,
            }
        })
        .collect()
}

/// Summary of table `t` (index into the tables of [`compute_map`]).
pub fn summarize(cells: &[MapCell], t: usize) -> MapSummary {
    let mut s = MapSummary::default();
    let (mut sq, mut n, mut sq_g, mut n_g) = (0.0, 0.0, 0.0, 0.0);
    let mut rms: Vec<f64> = Vec::with_capacity(cells.len());
    for c in cells {
        let e = &c.errors[t];
        let np = c.oracle.values.len() as f64;
        sq += e.rms * e.rms * np;
        n += np;
        if c.cos_theta_v <= 0.5 && c.alpha <= 0.4 {
            sq_g += e.rms * e.rms * np;
            n_g += np;
        }
        rms.push(e.rms);
        if e.rms > s.max_cell_rms.0 {
            s.max_cell_rms = (e.rms, c.cos_theta_v, c.alpha);
        }
        s.max_rel_big = s.max_rel_big.max(e.max_rel_big);
        s.mean_signed += e.mean_signed / cells.len() as f64;
        s.max_ci = s.max_ci.max(e.max_ci);
    }
    rms.sort_by(f64::total_cmp);
    s.rms_all = (sq / n.max(1.0)).sqrt();
    s.rms_grazing_glossy = (sq_g / n_g.max(1.0)).sqrt();
    s.median_cell_rms = rms.get(rms.len() / 2).copied().unwrap_or(0.0);
    s
}

/// CSV, one line per configuration and table.
pub fn to_csv(cells: &[MapCell], names: &[&str]) -> String {
    let mut out = String::from(
        "table,i,j,theta_v_deg,cos_theta_v,alpha,albedo,rms,max_abs,max_abs_polygon,mean_signed,max_rel_big,hemisphere,max_ci\n",
    );
    for c in cells {
        for (t, e) in c.errors.iter().enumerate() {
            writeln!(
                out,
                "{},{},{},{:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{},{:.6},{:.6},{:.6},{:.2e}",
                names[t],
                c.i,
                c.j,
                c.cos_theta_v.acos().to_degrees(),
                c.cos_theta_v,
                c.alpha,
                e.albedo,
                e.rms,
                e.max_abs,
                e.max_abs_polygon,
                e.mean_signed,
                e.max_rel_big,
                e.hemisphere,
                e.max_ci
            )
            .unwrap();
        }
    }
    out
}

/// Colour of an error on a log scale from 1e-3 (dark blue) to 1e-1 (yellow-white).
fn colour(err: f64) -> [u8; 3] {
    let t = ((err.max(1e-4).log10() + 3.0) / 2.0).clamp(0.0, 1.0) as f32;
    // A short perceptual-ish ramp: navy → purple → orange → pale yellow.
    let stops: [[f32; 3]; 4] = [
        [20.0, 24.0, 82.0],
        [140.0, 40.0, 130.0],
        [240.0, 120.0, 40.0],
        [252.0, 240.0, 160.0],
    ];
    let x = t * 3.0;
    let k = (x as usize).min(2);
    let f = x - k as f32;
    let mut c = [0u8; 3];
    for q in 0..3 {
        c[q] = (stops[k][q] + (stops[k + 1][q] - stops[k][q]) * f).round() as u8;
    }
    c
}

fn fill(pm: &mut Pixmap, x: f32, y: f32, w: f32, h: f32, c: [u8; 3]) {
    let mut paint = Paint::default();
    paint.set_color(Color::from_rgba8(c[0], c[1], c[2], 255));
    if let Some(r) = Rect::from_xywh(x, y, w, h) {
        pm.fill_rect(r, &paint, Transform::identity(), None);
    }
}

/// The heat map: one panel per table, cells coloured by their RMS polygon error (log scale),
/// labelled with it in percent of the albedo; α grows downward, θv to the right.
pub fn heat_map_png(cells: &[MapCell], names: &[&str], m: usize, path: &Path) -> crate::Result<()> {
    let cs = 34.0f32;
    let (left, top, gap) = (70.0f32, 46.0f32, 30.0f32);
    let panel = cs * m as f32;
    let bar = 60.0;
    let w = left + names.len() as f32 * (panel + gap) + bar;
    let h = top + panel + 70.0;
    let mut pm = Pixmap::new(w as u32, h as u32).ok_or_else(|| crate::Error::from("pixmap"))?;
    pm.fill(Color::WHITE);
    let black = [0u8, 0, 0];
    for (t, name) in names.iter().enumerate() {
        let x0 = left + t as f32 * (panel + gap);
        let s = summarize(cells, t);
        draw_text(
            &mut pm,
            &format!("{name}: RMS {:.2} %", 100.0 * s.rms_all),
            x0 + 0.5 * panel,
            top - 16.0,
            &TextStyle::new(13.0, black).align(Align::Center),
        );
        for c in cells {
            let e = c.errors[t].rms;
            let (x, y) = (x0 + c.j as f32 * cs, top + c.i as f32 * cs);
            let col = colour(e);
            fill(&mut pm, x, y, cs - 1.0, cs - 1.0, col);
            let lum = 0.3 * col[0] as f32 + 0.59 * col[1] as f32 + 0.11 * col[2] as f32;
            let ink = if lum > 140.0 {
                [0, 0, 0]
            } else {
                [255, 255, 255]
            };
            let pct = 100.0 * e;
            let label = if pct >= 9.95 {
                format!("{pct:.0}")
            } else {
                format!("{pct:.1}")
            };
            draw_text(
                &mut pm,
                &label,
                x + 0.5 * cs,
                y + 0.5 * cs + 4.0,
                &TextStyle::new(10.0, ink).align(Align::Center),
            );
        }
        // θv ticks under the panel (every 4th column).
        for c in cells.iter().filter(|c| c.i == 0 && c.j % 4 == 0) {
            draw_text(
                &mut pm,
                &format!("{:.0}", c.cos_theta_v.acos().to_degrees()),
                x0 + (c.j as f32 + 0.5) * cs,
                top + panel + 14.0,
                &TextStyle::new(10.0, black).align(Align::Center),
            );
        }
        draw_text(
            &mut pm,
            "view angle (deg)",
            x0 + 0.5 * panel,
            top + panel + 32.0,
            &TextStyle::new(11.0, black).align(Align::Center),
        );
    }
    // α ticks left of the first panel.
    for c in cells.iter().filter(|c| c.j == 0 && c.i % 2 == 0) {
        draw_text(
            &mut pm,
            &format!("{:.3}", c.alpha),
            left - 6.0,
            top + (c.i as f32 + 0.5) * cs + 4.0,
            &TextStyle::new(10.0, black).align(Align::Right),
        );
    }
    draw_text(
        &mut pm,
        "alpha",
        14.0,
        top + 0.5 * panel,
        &TextStyle::new(11.0, black)
            .align(Align::Center)
            .rotate(-90.0),
    );
    // Colour bar, 0.1 % to 10 %.
    let bx = w - bar + 10.0;
    let steps = 40;
    for q in 0..steps {
        let f = q as f64 / (steps - 1) as f64;
        let e = 10f64.powf(-3.0 + 2.0 * f);
        let y = top + panel * (1.0 - f as f32) - panel / steps as f32;
        fill(&mut pm, bx, y, 14.0, panel / steps as f32 + 0.5, colour(e));
    }
    for (f, label) in [(0.0f32, "0.1"), (0.5, "1"), (1.0, "10 %")] {
        draw_text(
            &mut pm,
            label,
            bx + 18.0,
            top + panel * (1.0 - f) + 4.0,
            &TextStyle::new(10.0, black),
        );
    }
    draw_text(
        &mut pm,
        "RMS of (LTC - exact) / albedo over 17 polygons, per (view angle, alpha)",
        left,
        h - 14.0,
        &TextStyle::new(11.0, black),
    );
    crate::figure::plot::save_pixmap_png(&pm, path)?;
    Ok(())
}
