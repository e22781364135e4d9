//! Image comparison: error metrics and, given the reference's per-pixel standard error,
//! agreement in units of its noise.

/// Error of an image against a reference (all channels).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Comparison {
    pub mae: f64,
    pub rmse: f64,
    /// RMSE divided by the reference's mean value.
    pub relative_rmse: f64,
    /// With a standard-error image: root mean square of (image − reference)/σ over channels
    /// with σ > 0 (≈ 1 when the difference is the reference's noise alone).
    pub rms_z: Option<f64>,
    /// Fraction of channels with |z| ≤ 3 (≈ 0.997 for Gaussian noise).
    pub within_3_sigma: Option<f64>,
    /// Mean of z: a bias shows as a mean far from 0 (its own noise is 1/√n).
    pub mean_z: Option<f64>,
    pub channels: usize,
}

pub fn compare(
    image: &[[f32; 3]],
    reference: &[[f32; 3]],
    stderr: Option<&[[f32; 3]]>,
) -> Comparison {
    let mut c = Comparison::default();
    let (mut abs, mut sq, mut refsum) = (0.0, 0.0, 0.0);
    let (mut zsq, mut zsum, mut within, mut nz) = (0.0, 0.0, 0usize, 0usize);
    for (i, (a, b)) in image.iter().zip(reference).enumerate() {
        for k in 0..3 {
            let d = a[k] as f64 - b[k] as f64;
            abs += d.abs();
            sq += d * d;
            refsum += b[k] as f64;
            c.channels += 1;
            if let Some(s) = stderr {
                let sigma = s[i][k] as f64;
                if sigma > 0.0 {
                    let z = d / sigma;
                    zsq += z * z;
                    zsum += z;
                    nz += 1;
                    if z.abs() <= 3.0 {
                        within += 1;
                    }
                }
            }
        }
    }
    let n = c.channels.max(1) as f64;
    c.mae = abs / n;
    c.rmse = (sq / n).sqrt();
    c.relative_rmse = c.rmse / (refsum / n).max(f64::MIN_POSITIVE);
    if stderr.is_some() && nz > 0 {
        c.rms_z = Some((zsq / nz as f64).sqrt());
        c.mean_z = Some(zsum / nz as f64);
        c.within_3_sigma = Some(within as f64 / nz as f64);
    }
    c
}
