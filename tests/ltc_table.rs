//! The committed table: file round trip, node lookups, invariants of every entry, and that
//! `fit_table` reproduces it.

use penumbra::ltc::{ALPHA_MIN, COS_THETA_MIN, LTC_TABLE_SIZE, MAGIC};
use penumbra::ltc::{LtcEntry, LtcTable};

fn bits(e: &LtcEntry) -> Vec<u64> {
    e.m_inv
        .to_cols_array()
        .iter()
        .chain([e.norm, e.fresnel].iter())
        .map(|x| x.to_bits())
        .collect()
}

#[test]
fn ltc_embedded_table_round_trips_bit_exactly() {
    let t = LtcTable::embedded();
    assert!(std::ptr::eq(t, LtcTable::embedded()), "parsed once");
    assert_eq!(t.size(), LTC_TABLE_SIZE);
    assert_eq!(
        (t.alpha_min(), t.cos_theta_min()),
        (ALPHA_MIN, COS_THETA_MIN)
    );
    let asset = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/ltc/ggx_ltc_64.bin"
    ))
    .unwrap();
    assert_eq!(
        t.to_bytes(),
        asset,
        "serialisation reproduces the committed file"
    );

    let path =
        std::env::temp_dir().join(format!("penumbra_ltc_roundtrip_{}.bin", std::process::id()));
    t.save(&path).unwrap();
    let u = LtcTable::load(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(u.to_bytes(), asset);
    for i in 0..t.size() {
        for j in 0..t.size() {
            assert_eq!(bits(&t.entry(i, j)), bits(&u.entry(i, j)));
        }
    }
}

#[test]
fn ltc_corrupted_files_are_rejected() {
    let good = LtcTable::embedded().to_bytes();
    let mut bad = good.clone();
    bad[1000] ^= 1;
    assert!(LtcTable::from_bytes(&bad).is_err(), "checksum");
    assert!(
        LtcTable::from_bytes(&good[..good.len() - 1]).is_err(),
        "length"
    );
    let mut bad = good.clone();
    bad[0] = b'X';
    assert!(LtcTable::from_bytes(&bad).is_err(), "magic");
    assert_eq!(&good[..8], &MAGIC);
    assert_eq!(good.len(), 32 + 64 * 64 * 64 + 8);
}

#[test]
fn ltc_lookup_at_nodes_returns_stored_entries() {
    let t = LtcTable::embedded();
    for i in 0..t.size() {
        for j in 0..t.size() {
            let got = t.lookup(t.cos_theta_at(j), t.alpha_at(i));
            assert_eq!(bits(&got), bits(&t.entry(i, j)), "node ({i}, {j})");
        }
    }
    // Clamping: below the minima, above 1, NaN.
    let e = t.entry(0, t.size() - 1);
    assert_eq!(bits(&t.lookup(0.0, 0.0)), bits(&e));
    assert_eq!(bits(&t.lookup(-1.0, f64::NAN)), bits(&e));
    assert_eq!(bits(&t.lookup(1.5, 7.0)), bits(&t.entry(t.size() - 1, 0)));
}

#[test]
fn ltc_lookup_interpolates_between_nodes() {
    let t = LtcTable::embedded();
    let (i, j) = (20, 30);
    let (a0, a1) = (t.alpha_at(i), t.alpha_at(i + 1));
    let (c0, c1) = (t.cos_theta_at(j), t.cos_theta_at(j + 1));
    let e = t.lookup(0.5 * (c0 + c1), 0.25 * a0 + 0.75 * a1);
    let r = e.to_record();
    let rec = |i: usize, j: usize| t.entry(i, j).to_record();
    for (k, got) in r.iter().enumerate() {
        if k == 6 && t.is_renormalized() {
            // The scale of a renormalised table is 1/H of the interpolated entry itself.
            assert!(
                (got * e.horizon_fraction() - 1.0).abs() <= 1e-14,
                "scale {got}"
            );
            continue;
        }
        let want = 0.25 * 0.5 * (rec(i, j)[k] + rec(i, j + 1)[k])
            + 0.75 * 0.5 * (rec(i + 1, j)[k] + rec(i + 1, j + 1)[k]);
        assert!(
            (got - want).abs() <= 1e-14 * want.abs().max(1.0),
            "{k}: {got} vs {want}"
        );
    }
}

#[test]
fn ltc_every_entry_is_valid() {
    let t = LtcTable::embedded();
    for i in 0..t.size() {
        for j in 0..t.size() {
            let e = t.entry(i, j);
            assert_eq!(e.m_inv.y_axis.y, 1.0);
            assert!(
                e.m_inv.determinant() > 0.0,
                "orientation preserving at ({i}, {j})"
            );
            assert!(
                e.norm > 0.0 && e.norm <= 1.0,
                "norm ({i}, {j}) = {}",
                e.norm
            );
            assert!(
                e.fresnel >= 0.0 && e.fresnel <= e.norm,
                "fresnel ({i}, {j})"
            );
            // transform of the reflection direction is a unit vector above the horizon.
            let c = t.cos_theta_at(j);
            let r = glam::DVec3::new(-(1.0 - c * c).sqrt(), 0.0, c);
            let w = e.transform(r);
            assert!((w.length() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn ltc_fit_table_reproduces_committed_corners() {
    // fit_table(2) has the same four corner nodes as the 64×64 table. The moments are the
    // same deterministic computation (bit-identical); the matrices are Nelder–Mead minima
    // reached from different warm starts, equal to the optimiser's tolerance.
    let small = penumbra::ltc::fit::fit_table(2, |_, _| {});
    let big = LtcTable::embedded();
    let n = big.size() - 1;
    for (i, j, bi, bj) in [(0, 0, 0, 0), (0, 1, 0, n), (1, 0, n, 0), (1, 1, n, n)] {
        let (a, b) = (small.entry(i, j), big.entry(bi, bj));
        assert_eq!(a.norm.to_bits(), b.norm.to_bits());
        assert_eq!(a.fresnel.to_bits(), b.fresnel.to_bits());
        let ra = a.to_record();
        let rb = b.to_record();
        let scale = ra[..4].iter().map(|x| x.abs()).fold(0.0, f64::max);
        for k in 0..4 {
            assert!(
                (ra[k] - rb[k]).abs() <= 2e-3 * scale,
                "corner ({bi}, {bj}) m[{k}]: {} vs {}",
                ra[k],
                rb[k]
            );
        }
    }
}
