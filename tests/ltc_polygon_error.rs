//! The LTC tables' error on polygon integrals (docs/ltc.md, "Error on polygon integrals"),
//! the horizon renormalisation, and the conversion of the published table (Heitz et al. 2016,
//! via three.js).
//!
//! Oracle: stratified Monte Carlo on the VNDF sample square with collapsed-strata 99.9 %
//! half-widths (`polygon_error::oracle_integrals`), itself checked here against the
//! fitter's quadrature of the albedo.

use penumbra::ltc::fit::{lobe_moments, view_dir};
use penumbra::ltc::polygon_error::{
    TestPolygon, cell_error, ltc_form_factor, oracle_integrals, test_polygons,
};
use penumbra::ltc::published::published;
use penumbra::ltc::{LtcEntry, LtcTable};

/// Coarse subset of the map's configurations `(cosθv, α)`, between table nodes, weighted to
/// the grazing glossy range where the fits differ.
const CELLS: [(f64, f64); 6] = [
    (0.90, 0.20),
    (0.50, 0.10),
    (0.30, 0.30),
    (0.20, 0.15),
    (0.12, 0.30),
    (0.08, 0.05),
];

/// `(rms over CELLS of the per-polygon |LTC − oracle|/albedo, largest oracle half-width)`.
fn rms_error(table: &LtcTable, k: usize) -> (f64, f64, Vec<f64>) {
    let (mut sq, mut n, mut ci) = (0.0, 0.0, 0.0f64);
    let mut per_cell = Vec::new();
    for (q, &(c, a)) in CELLS.iter().enumerate() {
        let polys = test_polygons(c);
        let oracle = oracle_integrals(c, a, &polys, k, 1000 + q as u64);
        let e = cell_error(table, c, a, &polys, &oracle);
        sq += e.rms * e.rms * polys.len() as f64;
        n += polys.len() as f64;
        ci = ci.max(e.max_ci);
        per_cell.push(e.rms);
    }
    ((sq / n).sqrt(), ci, per_cell)
}

#[test]
fn ltc_oracle_albedo_matches_quadrature() {
    // The oracle's albedo (all samples above the horizon) against the graded midpoint rule
    // of the fitter (accurate to ~2e-6, docs/ltc.md).
    for &(c, a) in &CELLS {
        let polys = test_polygons(c);
        let o = oracle_integrals(c, a, &polys, 256, 7);
        let q = lobe_moments(view_dir(c), a, 1024).norm;
        assert!(
            (o.albedo.0 - q).abs() <= o.albedo.1 + 1e-5,
            "cosθv {c}, α {a}: oracle {} ± {}, quadrature {q}",
            o.albedo.0,
            o.albedo.1
        );
    }
}

#[test]
fn ltc_polygon_error_embedded_beats_published() {
    let k = 256;
    let (ours, ci, ours_cells) = rms_error(LtcTable::embedded(), k);
    let (theirs, ci2, their_cells) = rms_error(published(), k);
    eprintln!("polygon RMS error: embedded {ours:.4} {ours_cells:.4?}");
    eprintln!("                   published {theirs:.4} {their_cells:.4?} (max CI {ci:.1e})");
    // The oracle's noise is far below the difference measured.
    assert!(ci.max(ci2) < 0.1 * (theirs - ours));
    assert!(ours < 0.6 * theirs, "embedded {ours} vs published {theirs}");
    // And at every grazing glossy cell (θv ≥ 60°).
    for (q, &(c, _)) in CELLS.iter().enumerate() {
        if c <= 0.5 {
            assert!(
                ours_cells[q] < their_cells[q],
                "cell {:?}: {} vs {}",
                CELLS[q],
                ours_cells[q],
                their_cells[q]
            );
        }
    }
}

/// The two halves of the upper hemisphere as test pieces.
fn hemisphere() -> TestPolygon {
    test_polygons(0.5)
        .into_iter()
        .find(|p| p.name == "hemisphere")
        .unwrap()
}

#[test]
fn ltc_horizon_fraction_is_the_hemisphere_integral() {
    let h = hemisphere();
    for t in [LtcTable::embedded(), published()] {
        for &(i, j) in &[(5, 0), (20, 40), (34, 60), (50, 63), (63, 63), (10, 55)] {
            let e = t.entry(i, j);
            let ff: f64 = h.pieces.iter().map(|p| ltc_form_factor(&e, p)).sum();
            assert!(
                (ff - e.horizon_fraction()).abs() < 1e-12,
                "({i}, {j}): {ff} vs {}",
                e.horizon_fraction()
            );
        }
    }
    // The embedded table is renormalised: the LTC of the whole hemisphere is the albedo.
    let t = LtcTable::embedded();
    for i in (0..64).step_by(9) {
        for j in (0..64).step_by(7) {
            let e = t.entry(i, j);
            let ff: f64 = h.pieces.iter().map(|p| ltc_form_factor(&e, p)).sum();
            let r = e.specular_scale(1.0) * ff / e.norm;
            assert!((r - 1.0).abs() < 1e-12, "({i}, {j}): {r}");
        }
    }
}

#[test]
fn ltc_lookups_between_nodes_are_renormalised() {
    // A blend of 1/H values is not 1/H of the blended LTC: the lookup renormalises the
    // interpolated entry, so that the whole hemisphere integrates to the albedo everywhere,
    // including between nodes whose LTCs lie below the horizon by very different amounts
    // (grazing, smooth).
    let h = hemisphere();
    let t = LtcTable::embedded();
    assert!(t.is_renormalized() && !published().is_renormalized());
    for &(c, a) in &[
        (0.062, 0.001),
        (0.02, 0.0005),
        (0.3, 0.3),
        (0.11, 0.05),
        (0.9, 0.7),
        (0.004, 0.02),
    ] {
        let e = t.lookup(c, a);
        let ff: f64 = h.pieces.iter().map(|p| ltc_form_factor(&e, p)).sum();
        let r = e.specular_scale(1.0) * ff / e.norm;
        assert!((r - 1.0).abs() < 1e-9, "cosθv {c}, α {a}: {r}");
    }
}

#[test]
fn ltc_published_table_conversion() {
    let t = published();
    assert_eq!(t.size(), 64);
    // Normal incidence (column 0): rotationally symmetric lobes, m02 = m20 = 0.
    for i in 0..64 {
        let r = t.entry(i, 0).to_record();
        assert!(r[1] == 0.0 && r[2] == 0.0, "row {i}: {r:?}");
    }
    // α = 1 (row 63): ρ cosθl depends on cosθl only, so the fit is symmetric too, up to the
    // published fit's drift at grazing columns (|m20| = 7e-3 at column 54): checked for
    // θv ≤ 60° (column 44, cosθv = 0.51).
    for j in 0..=44 {
        let r = t.entry(63, j).to_record();
        assert!(r[1].abs() < 3e-3 && r[2].abs() < 3e-3, "column {j}: {r:?}");
    }
    // Not transposed: a smooth grazing lobe is strongly sheared.
    // (m02 = 0.097 against m00 = 0.0093 and m20 = −0.0047: transposed, |m02| would be the
    // smaller one.)
    let r = t.entry(10, 60).to_record();
    assert!(
        r[1].abs() > 5.0 * r[0].abs() && r[1].abs() > 5.0 * r[2].abs(),
        "{r:?}"
    );
    // Every stored M⁻¹ preserves orientation; the published table is not renormalised.
    for i in 0..64 {
        for j in 0..64 {
            let e = t.entry(i, j);
            assert!(e.m_inv.determinant() > 0.0 && e.scale == 1.0);
        }
    }
    // norm is the albedo: against our quadrature at a few nodes (the published fit used
    // its own sample counts; agreement to 1 %).
    for &(i, j) in &[(8, 0), (20, 16), (34, 32), (45, 48), (63, 0), (63, 40)] {
        let e = t.entry(i, j);
        let alb = lobe_moments(view_dir(t.cos_theta_at(j)), t.alpha_at(i), 512).norm;
        assert!(
            (e.norm - alb).abs() < 0.01,
            "({i}, {j}): norm {} vs albedo {alb}",
            e.norm
        );
    }
    // Lobe orientation: the LTC's axis `M z` leans to the reflection side (x < 0), and the
    // polygon integral at the reflection direction is right to 25 %.
    for &(c, a) in &[(0.6, 0.1), (0.3, 0.3)] {
        let e: LtcEntry = t.lookup(c, a);
        let axis = e.m_inv.inverse() * glam::DVec3::Z;
        assert!(
            axis.x < -0.2 * axis.z.abs(),
            "cosθv {c}, α {a}: axis {axis}"
        );
        let polys = test_polygons(c);
        let o = oracle_integrals(c, a, &polys, 128, 3);
        let q = polys
            .iter()
            .position(|p| p.name == "refl-quad-medium")
            .unwrap();
        let ltc = penumbra::ltc::polygon_error::ltc_integral(&e, &polys[q]);
        assert!(
            (ltc - o.values[q].0).abs() < 0.25 * o.values[q].0,
            "cosθv {c}, α {a}: {ltc} vs {:?}",
            o.values[q]
        );
    }
}

#[test]
fn ltc_table_older_versions_are_rejected() {
    // The format is versioned: versions 1 (6 values per entry) and 2 (7: no cosine tail) no
    // longer load, even with a valid checksum (the version, not the checksum, rejects them).
    fn fnv1a64(bytes: &[u8]) -> u64 {
        bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
    }
    let good = LtcTable::embedded().to_bytes();
    for version in [1u32, 2, 3] {
        let mut bytes = good.clone();
        bytes[8..12].copy_from_slice(&version.to_le_bytes());
        let body = bytes.len() - 8;
        let sum = fnv1a64(&bytes[..body]);
        bytes[body..].copy_from_slice(&sum.to_le_bytes());
        assert_eq!(
            LtcTable::from_bytes(&bytes).is_ok(),
            version == 3,
            "version {version}"
        );
    }
}
