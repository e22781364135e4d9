//! Nelder–Mead downhill simplex minimiser (Nelder & Mead 1965), with the dimension-adaptive
//! coefficients of Gao & Han 2012 for `D > 2` and restarts from the best vertex (a
//! collapsed simplex is the classic failure mode of the method; a restart with the initial
//! step sizes costs `D + 1` evaluations and recovers from it).

/// Stopping rules.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Options {
    /// Hard limit on objective evaluations (over all restarts).
    pub max_evals: usize,
    /// Converged when `f_worst − f_best <= f_abs + f_rel · |f_best|` ...
    pub f_rel: f64,
    pub f_abs: f64,
    /// ... and every vertex is within `x_tol · step[k]` of the best one in coordinate `k`.
    pub x_tol: f64,
    /// Number of restarts after the first convergence; stops early when a restart improves
    /// the minimum by less than `f_rel` (relative).
    pub restarts: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_evals: 5000,
            f_rel: 1e-9,
            f_abs: 0.0,
            x_tol: 1e-7,
            restarts: 3,
        }
    }
}

/// Result of [`minimize`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Minimum<const D: usize> {
    pub x: [f64; D],
    pub f: f64,
    pub evals: usize,
}

/// Minimise `f` starting from the simplex `{x0, x0 + step_k e_k}`. Non-finite objective
/// values are treated as `+∞` (use them for infeasible points).
pub(crate) fn minimize<const D: usize>(
    mut f: impl FnMut(&[f64; D]) -> f64,
    x0: [f64; D],
    step: [f64; D],
    opts: &Options,
) -> Minimum<D> {
    assert!(D >= 1);
    let mut eval = |x: &[f64; D], evals: &mut usize| {
        *evals += 1;
        let y = f(x);
        if y.is_nan() { f64::INFINITY } else { y }
    };
    let n = D as f64;
    // Gao & Han 2012: reflection 1, expansion 1 + 2/n, contraction 3/4 − 1/(2n),
    // shrink 1 − 1/n. They reduce to the classic (1, 2, 1/2, 1/2) for n = 2; for n = 1 the
    // classic ones are used (the adaptive shrink would be 0).
    let (c_exp, c_con, c_shr) = if D <= 2 {
        (2.0, 0.5, 0.5)
    } else {
        (1.0 + 2.0 / n, 0.75 - 0.5 / n, 1.0 - 1.0 / n)
    };
    let mut evals = 0usize;
    let mut best_x = x0;
    let mut best_f = eval(&x0, &mut evals);
    let mut simplex: Vec<([f64; D], f64)> = Vec::with_capacity(D + 1);

    for round in 0..=opts.restarts {
        let start_f = best_f;
        simplex.clear();
        simplex.push((best_x, best_f));
        for k in 0..D {
            let mut x = best_x;
            x[k] += step[k];
            let y = eval(&x, &mut evals);
            simplex.push((x, y));
        }
        loop {
            simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
            let (f_best, f_worst) = (simplex[0].1, simplex[D].1);
            let f_conv = f_worst - f_best <= opts.f_abs + opts.f_rel * f_best.abs();
            let x_conv = simplex[1..].iter().all(|(x, _)| {
                (0..D).all(|k| (x[k] - simplex[0].0[k]).abs() <= opts.x_tol * step[k].abs())
            });
            if (f_conv && x_conv) || evals >= opts.max_evals {
                break;
            }
            let mut centroid = [0.0; D];
            for (x, _) in &simplex[..D] {
                for k in 0..D {
                    centroid[k] += x[k] / n;
                }
            }
            let worst = simplex[D];
            let along = |t: f64| -> [f64; D] {
                let mut x = [0.0; D];
                for k in 0..D {
                    x[k] = centroid[k] + t * (centroid[k] - worst.0[k]);
                }
                x
            };
            let xr = along(1.0);
            let fr = eval(&xr, &mut evals);
            if fr < f_best {
                let xe = along(c_exp);
                let fe = eval(&xe, &mut evals);
                simplex[D] = if fe < fr { (xe, fe) } else { (xr, fr) };
                continue;
            }
            if fr < simplex[D - 1].1 {
                simplex[D] = (xr, fr);
                continue;
            }
            // Contraction: outside if the reflected point beats the worst, else inside.
            let (xc, fc, accept) = if fr < worst.1 {
                let xc = along(c_con);
                let fc = eval(&xc, &mut evals);
                (xc, fc, fc <= fr)
            } else {
                let xc = along(-c_con);
                let fc = eval(&xc, &mut evals);
                (xc, fc, fc < worst.1)
            };
            if accept {
                simplex[D] = (xc, fc);
                continue;
            }
            // Shrink towards the best vertex.
            let x_best = simplex[0].0;
            for v in simplex[1..].iter_mut() {
                for (x, b) in v.0.iter_mut().zip(x_best.iter()) {
                    *x = b + c_shr * (*x - b);
                }
                v.1 = eval(&v.0, &mut evals);
            }
        }
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if simplex[0].1 <= best_f {
            best_x = simplex[0].0;
            best_f = simplex[0].1;
        }
        let improved = start_f - best_f > opts.f_rel * best_f.abs();
        if evals >= opts.max_evals || (round > 0 && !improved) {
            break;
        }
    }
    Minimum {
        x: best_x,
        f: best_f,
        evals,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosenbrock_2d() {
        let r = minimize(
            |x: &[f64; 2]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2),
            [-1.2, 1.0],
            [0.1, 0.1],
            &Options {
                f_abs: 1e-20,
                ..Options::default()
            },
        );
        assert!(
            (r.x[0] - 1.0).abs() < 1e-5 && (r.x[1] - 1.0).abs() < 1e-5,
            "{r:?}"
        );
    }

    #[test]
    fn quadratic_4d_and_1d_and_infeasible_region() {
        let c = [0.3, -2.0, 5.0, 1e-3];
        let r = minimize(
            |x: &[f64; 4]| {
                if x[0] < 0.0 {
                    return f64::INFINITY;
                }
                (0..4).map(|k| (k + 1) as f64 * (x[k] - c[k]).powi(2)).sum()
            },
            [1.0, 1.0, 1.0, 1.0],
            [0.5, 0.5, 0.5, 0.5],
            &Options {
                f_abs: 1e-24,
                ..Options::default()
            },
        );
        for (x, c) in r.x.iter().zip(c.iter()) {
            assert!((x - c).abs() < 1e-6, "{r:?}");
        }
        let r = minimize(
            |x: &[f64; 1]| (x[0] - 2.0).powi(2) + 1.0,
            [0.0],
            [0.1],
            &Options::default(),
        );
        assert!(
            (r.x[0] - 2.0).abs() < 1e-4 && (r.f - 1.0).abs() < 1e-8,
            "{r:?}"
        );
    }
}
