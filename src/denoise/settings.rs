//! Parameters of the denoiser, with the reasoning behind each default.

/// Parameters of [`noise_estimate`](fn@super::noise_estimate),
/// [`joint_bilateral`](fn@super::joint_bilateral) and the two pipelines.
///
/// Defaults (see `docs/denoiser.md` for the derivations):
///
/// | field | default | meaning |
/// |---|---|---|
/// | `line_half_length` | 6 | 4 lines of 2·6+1 = 13 taps (11 second differences) in Eq. 29 |
/// | `sigma_gain` | 0.65 | σ = gain·E; aims at a residual standard deviation of ≈ 0.02 in W |
/// | `sigma_max` | 8 px | largest Gaussian standard deviation (kernel radius 24 px) |
/// | `sigma_min` | 0.25 px | below this a pixel is copied unchanged (neighbour weight < e⁻⁸) |
/// | `plane_tolerance` | 1.5 footprints | std-dev of the plane-distance weight |
/// | `normal_tolerance` | 0.3 rad | std-dev (≈ angle) of the normal weight |
/// | `seed` | 0x9E37_79B9 | seed of the per-pixel line offsets of Eq. 29 |
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct DenoiseSettings {
    /// L: each line of the noise estimate runs over 2L+1 pixels containing the centre pixel.
    pub line_half_length: u32,
    /// σ = `sigma_gain` × E (pixels per unit of E).
    pub sigma_gain: f64,
    /// σ is clamped to at most this many pixels.
    pub sigma_max: f64,
    /// Pixels whose σ is below this (or not a number) are copied unchanged.
    pub sigma_min: f64,
    /// Plane-distance weight exp(−½ (d / (tol·footprint))²), d = |n_c·(p_t − p_c)|.
    pub plane_tolerance: f64,
    /// Normal weight exp(−(1 − n_c·n_t) / tol²) ≈ exp(−½ (θ / tol)²).
    pub normal_tolerance: f64,
    /// Seed of the deterministic per-pixel random line offsets.
    pub seed: u64,
}

impl Default for DenoiseSettings {
    fn default() -> Self {
        DenoiseSettings {
            line_half_length: 6,
            sigma_gain: 0.65,
            sigma_max: 8.0,
            sigma_min: 0.25,
            plane_tolerance: 1.5,
            normal_tolerance: 0.3,
            seed: 0x9E37_79B9,
        }
    }
}
