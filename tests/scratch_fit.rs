use penumbra::ltc::fit::*;
use std::time::Instant;

#[test]
#[ignore]
fn moments_convergence() {
    for &(c, a) in &[(1.0, 0.5), (0.5, 0.3), (0.1, 1.0), (0.05, 0.05), (0.001, 0.5), (0.001, 1e-4), (0.3, 1e-4), (0.02, 0.8)] {
        let v = view_dir(c);
        let t = Instant::now();
        let m: Vec<_> = [128usize, 256, 512, 1024, 4096].iter().map(|&k| lobe_moments(v, a, k)).collect();
        let dt = t.elapsed();
        let r = &m[4];
        println!("c={c} a={a} norm={:.8} fres={:.8} | dn: {:.1e} {:.1e} {:.1e} {:.1e} | df {:.1e} {:.1e} {:.1e}  ({dt:?})", r.norm, r.fresnel,
            m[0].norm - r.norm, m[1].norm - r.norm, m[2].norm - r.norm, m[3].norm - r.norm,
            m[1].fresnel - r.fresnel, m[2].fresnel - r.fresnel, m[3].fresnel - r.fresnel);
    }
}

#[test]
#[ignore]
fn fit_some_cells() {
    for &a in &[1.0, 0.5, 0.1, 0.01, 1e-4] {
        let t = Instant::now();
        let f0 = fit_cell(1.0, a, [a.ln(), a.ln(), 0.0, 0.0]);
        println!("a={a} c=1 params={:?} rel_l3={:.4} evals={} {:?}", f0.params, (f0.l3_error/f0.lobe_l3).cbrt(), f0.evals, t.elapsed());
        let mut q = f0.params;
        for &c in &[0.9, 0.7, 0.5, 0.3, 0.1, 0.03, 0.001] {
            let t = Instant::now();
            let f = fit_cell(c, a, q);
            q = f.params;
            println!("   c={c} params={:.4?} rel_l3={:.4} evals={} {:?} minv={:.4?}", f.params, (f.l3_error/f.lobe_l3).cbrt(), f.evals, t.elapsed(), f.entry.m_inv.to_cols_array());
        }
    }
}
