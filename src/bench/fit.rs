//! Least-squares straight lines, for scaling plots (000 Figs. 5 and 7: run time against the
//! number of vertices): y = a + b·x, and its log–log variant ln y = a + b·ln x, whose slope is
//! the exponent of a power law y = e^a·x^b.

/// A fitted line y = intercept + slope·x.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination 1 − SS_res/SS_tot; 1 when all y are equal (the line fits
    /// them exactly).
    pub r_squared: f64,
    /// Points used.
    pub n: usize,
}

impl LineFit {
    #[cfg(test)]
    pub(crate) fn predict(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }
}

/// Ordinary least squares over the points with finite coordinates. `None` with fewer than two
/// such points or when all their x are equal (no slope is defined).
///
/// Closed form on centred sums (which keeps large offsets from cancelling):
/// slope = Sxy/Sxx, intercept = ȳ − slope·x̄, R² = Sxy²/(Sxx·Syy).
pub(crate) fn fit_line(points: &[(f64, f64)]) -> Option<LineFit> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in &pts {
        let (dx, dy) = (x - mx, y - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    if sxx == 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let r_squared = if syy == 0.0 {
        1.0
    } else {
        (sxy * sxy / (sxx * syy)).min(1.0)
    };
    Some(LineFit {
        slope,
        intercept: my - slope * mx,
        r_squared,
        n,
    })
}

/// [`fit_line`] on (ln x, ln y): `slope` is the exponent b of y = C·x^b, `intercept` is ln C,
/// and R² is measured in log space. Points with a coordinate that is not positive and finite are
/// skipped (they have no logarithm); `n` counts the rest.
#[cfg(test)]
pub(crate) fn fit_log_log(points: &[(f64, f64)]) -> Option<LineFit> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    fit_line(&logs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
    }

    /// (0,1), (1,3), (2,4), (3,4): x̄ = 1.5, ȳ = 3, Sxx = 5, Sxy = 5, Syy = 6, so slope 1,
    /// intercept 1.5, R² = 25/30.
    #[test]
    fn hand_computed_line() {
        let f = fit_line(&[(0.0, 1.0), (1.0, 3.0), (2.0, 4.0), (3.0, 4.0)]).unwrap();
        assert_eq!(f.slope, 1.0);
        assert_eq!(f.intercept, 1.5);
        assert!(close(f.r_squared, 5.0 / 6.0, 1e-15));
        assert_eq!(f.n, 4);
        assert_eq!(f.predict(2.0), 3.5);
    }

    /// Noise-free lines come back exactly (to rounding) with R² = 1, far from the origin too.
    #[test]
    fn noise_free_synthetic_line() {
        for (a, b, x0) in [(0.3, 2.5, 0.0), (-7.0, -0.125, 1e6), (1e-6, 3e-9, 12345.0)] {
            let pts: Vec<(f64, f64)> = (0..50)
                .map(|i| x0 + i as f64 * 0.7)
                .map(|x| (x, a + b * x))
                .collect();
            let f = fit_line(&pts).unwrap();
            assert!(close(f.slope, b, 1e-9), "{} vs {b}", f.slope);
            assert!(close(f.intercept, a, 1e-9 * (b * x0).abs().max(1.0)));
            assert!(close(f.r_squared, 1.0, 1e-12));
        }
    }

    /// y = 3·x^1.5 gives exponent 1.5 and intercept ln 3; zeros and NaN are skipped.
    #[test]
    fn noise_free_power_law() {
        let mut pts: Vec<(f64, f64)> = [8.0, 12.0, 100.0, 1000.0, 4096.0, 1e5]
            .iter()
            .map(|&v: &f64| (v, 3.0 * v.powf(1.5)))
            .collect();
        pts.push((0.0, 1.0));
        pts.push((5.0, f64::NAN));
        let f = fit_log_log(&pts).unwrap();
        assert!(close(f.slope, 1.5, 1e-12));
        assert!(close(f.intercept, 3f64.ln(), 1e-12));
        assert!(close(f.r_squared, 1.0, 1e-12));
        assert_eq!(f.n, 6);
    }

    #[test]
    fn degenerate_inputs() {
        assert!(fit_line(&[]).is_none());
        assert!(fit_line(&[(1.0, 2.0)]).is_none());
        assert!(fit_line(&[(1.0, 2.0), (1.0, 3.0)]).is_none());
        assert!(fit_line(&[(1.0, 2.0), (f64::NAN, 3.0)]).is_none());
        let flat = fit_line(&[(1.0, 2.0), (2.0, 2.0), (3.0, 2.0)]).unwrap();
        assert_eq!(
            (flat.slope, flat.intercept, flat.r_squared),
            (0.0, 2.0, 1.0)
        );
    }
}
