//! Regenerates the committed table: `cargo test --test suite ltc_generate:: -- --ignored --nocapture`
//! (the same as `penumbra fit-ltc --out assets/ltc/ggx_ltc_64.bin`), and writes the per-cell
//! fit report assets/ltc/fit_report.tsv.

use penumbra::ltc::LTC_TABLE_SIZE;
use penumbra::ltc::fit::fit_table_cells;
use std::time::Instant;

#[test]
#[ignore = "fits the 64×64 table (minutes); run explicitly to regenerate assets/ltc/"]
fn generate_committed_table() {
    let t0 = Instant::now();
    let n = LTC_TABLE_SIZE;
    let (table, cells) = fit_table_cells(n, |done, total| {
        if done % 256 == 0 || done == total {
            eprintln!(
                "fit-ltc: {done}/{total} cells, {:.0} s",
                t0.elapsed().as_secs_f64()
            );
        }
    });
    let secs = t0.elapsed().as_secs_f64();
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/ltc");
    table.save(format!("{dir}/ggx_ltc_64.bin")).unwrap();
    let tsv = penumbra::ltc::fit::report_tsv(&table, &cells);
    std::fs::write(format!("{dir}/fit_report.tsv"), tsv).unwrap();
    eprintln!(
        "fit-ltc: {n}×{n} table in {secs:.1} s on {} threads",
        rayon::current_num_threads()
    );
}
