//! What the viewport shows of a render: the AOV (an image or a per-pixel quantity) and how
//! it is mapped to display colours. Pure functions, tested without a window.

use crate::render::derivative::{MASKED_GREY, derivative_scale, diverging_colour};
use crate::render::image_io::srgb_oetf;
use crate::render::{Image, RenderOutput};
use egui::Color32;
use glam::DVec3;

/// The image or per-pixel quantity shown in the viewport.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Aov {
    /// The method's result.
    Final,
    /// Analytic unshadowed illumination (stochastic methods).
    U,
    /// Stochastic shadowed illumination S_N.
    SN,
    /// Stochastic unshadowed illumination U_N.
    UN,
    /// Weighted shadow W = S_N / U_N (luminance).
    W,
    /// The denoiser's noise estimate E (denoised methods).
    NoiseEstimate,
    /// Occluders left after culling (analytic methods).
    OccludersKept,
    /// Edges of the horizon-clipped light polygons (analytic methods).
    SilhouetteEdges,
    /// Time per pixel (analytic methods).
    Cost,
    /// The image's derivative along the gizmo's active axis of the selected object (the
    /// analytic method; diverging colours, masked pixels grey).
    Derivative,
}

impl Aov {
    pub const ALL: [Aov; 10] = [
        Aov::Final,
        Aov::U,
        Aov::SN,
        Aov::UN,
        Aov::W,
        Aov::NoiseEstimate,
        Aov::OccludersKept,
        Aov::SilhouetteEdges,
        Aov::Cost,
        Aov::Derivative,
    ];

    pub(crate) fn label(self) -> &'static str {
        match self {
            Aov::Final => "final",
            Aov::U => "U (analytic unshadowed)",
            Aov::SN => "S_N (stochastic shadowed)",
            Aov::UN => "U_N (stochastic unshadowed)",
            Aov::W => "W = S_N / U_N",
            Aov::NoiseEstimate => "noise estimate E",
            Aov::OccludersKept => "occluders after culling",
            Aov::SilhouetteEdges => "light polygon edges",
            Aov::Cost => "cost per pixel (time)",
            Aov::Derivative => "derivative (selected object, active axis)",
        }
    }

    /// Whether the AOV is a colour image (tone-mapped) or a scalar (false colour).
    pub(crate) fn is_radiance(self) -> bool {
        matches!(self, Aov::Final | Aov::U | Aov::SN | Aov::UN)
    }
}

/// How radiance becomes a display colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ToneMap {
    /// Exposure, clamp to [0, 1], sRGB (what `penumbra render` writes to PNG).
    Clamp,
    /// Exposure, Reinhard x / (1 + x) per channel, sRGB.
    Reinhard,
}

/// The values of an AOV, either colours or scalars, at the render's resolution.
pub(crate) enum AovValues {
    Radiance(Vec<DVec3>),
    Scalar(Vec<f64>),
    /// A derivative and its mask (`render::derivative`), in diverging colours.
    Signed {
        derivative: Image,
        mask: Image,
    },
}

/// Extracts `aov` from a render; `None` when the method did not compute it.
pub(crate) fn aov_values(out: &RenderOutput, aov: Aov) -> Option<AovValues> {
    let b = out.buffers.as_ref();
    let img = |i: &Image| AovValues::Radiance(i.pixels.clone());
    match aov {
        Aov::Final => Some(img(&out.image)),
        Aov::U => b.map(|b| img(&b.u)),
        Aov::SN => b.map(|b| img(&b.s_n)),
        Aov::UN => b.map(|b| img(&b.u_n)),
        // The W_N the denoiser's noise estimate reads (Eq. 23 on luminance, 1 where undefined
        // or invalid): the one definition, `denoise::weighted_shadow`.
        Aov::W => b.map(|b| {
            AovValues::Scalar(crate::denoise::ratio::weighted_shadow(
                &b.s_n, &b.u_n, &b.gbuffer,
            ))
        }),
        Aov::NoiseEstimate => out
            .denoise
            .as_ref()
            .map(|d| AovValues::Scalar(d.noise.clone())),
        Aov::OccludersKept => out
            .pixel_stats
            .as_ref()
            .map(|s| AovValues::Scalar(s.iter().map(|p| p.occluders_kept as f64).collect())),
        Aov::SilhouetteEdges => out
            .pixel_stats
            .as_ref()
            .map(|s| AovValues::Scalar(s.iter().map(|p| p.light_edges as f64).collect())),
        Aov::Cost => out
            .pixel_stats
            .as_ref()
            .map(|s| AovValues::Scalar(s.iter().map(|p| p.nanos as f64 * 1e-3).collect())),
        Aov::Derivative => out.derivative.as_ref().map(|d| AovValues::Signed {
            derivative: d.derivative.clone(),
            mask: d.mask.clone(),
        }),
    }
}

/// One radiance value to a display colour.
#[inline]
pub(crate) fn tonemap(c: DVec3, exposure: f64, op: ToneMap) -> Color32 {
    let scale = exposure.exp2();
    let f = |v: f64| {
        let x = if v.is_finite() {
            (v * scale).max(0.0)
        } else {
            0.0
        };
        let y = match op {
            ToneMap::Clamp => x.min(1.0),
            ToneMap::Reinhard => x / (1.0 + x),
        };
        (srgb_oetf(y) * 255.0).round().clamp(0.0, 255.0) as u8
    };
    Color32::from_rgb(f(c.x), f(c.y), f(c.z))
}

/// A perceptually ordered false-colour ramp (dark blue → teal → yellow), for t in [0, 1].
pub(crate) fn false_colour(t: f64) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    // Piecewise-linear through five stops close to viridis.
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [0.267, 0.005, 0.329]),
        (0.25, [0.229, 0.322, 0.546]),
        (0.5, [0.128, 0.567, 0.551]),
        (0.75, [0.369, 0.789, 0.383]),
        (1.0, [0.993, 0.906, 0.144]),
    ];
    let k = STOPS.iter().position(|s| s.0 >= t).unwrap_or(4).max(1);
    let (t0, a) = STOPS[k - 1];
    let (t1, b) = STOPS[k];
    let u = (t - t0) / (t1 - t0);
    let c = |i: usize| ((a[i] + (b[i] - a[i]) * u) * 255.0).round() as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

/// Display colours of an AOV, and for scalars the value range the ramp spans (for a
/// derivative ±its scale, the 99th percentile of its magnitude: `render::derivative`'s map).
pub(crate) fn display(
    values: &AovValues,
    exposure: f64,
    op: ToneMap,
) -> (Vec<Color32>, Option<(f64, f64)>) {
    match values {
        AovValues::Radiance(px) => (px.iter().map(|&c| tonemap(c, exposure, op)).collect(), None),
        AovValues::Scalar(v) => {
            let (lo, hi) = v
                .iter()
                .filter(|x| x.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                });
            let (lo, hi) = if lo <= hi {
                (lo.min(0.0), hi)
            } else {
                (0.0, 1.0)
            };
            let span = if hi > lo { hi - lo } else { 1.0 };
            (
                v.iter().map(|&x| false_colour((x - lo) / span)).collect(),
                Some((lo, hi)),
            )
        }
        AovValues::Signed { derivative, mask } => {
            let top = derivative_scale(derivative, mask);
            let colours = derivative
                .pixels
                .iter()
                .zip(&mask.pixels)
                .map(|(&d, m)| {
                    let [r, g, b] = if m.x != 0.0 {
                        MASKED_GREY
                    } else {
                        diverging_colour(crate::raster::luminance(d), top)
                    };
                    Color32::from_rgb(r, g, b)
                })
                .collect();
            (colours, Some((-top, top)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::luminance;

    #[test]
    fn tonemap_matches_the_png_writer() {
        for v in [0.0, 1e-4, 0.01, 0.2, 0.5, 0.99, 1.0, 3.0] {
            let c = tonemap(DVec3::splat(v), 0.0, ToneMap::Clamp);
            assert_eq!(
                c.r(),
                crate::render::image_io::to_srgb8(v as f32, 0.0),
                "{v}"
            );
        }
        let c = tonemap(
            DVec3::new(f64::NAN, -1.0, f64::INFINITY),
            0.0,
            ToneMap::Reinhard,
        );
        assert_eq!((c.r(), c.g(), c.b()), (0, 0, 0));
    }

    #[test]
    fn false_colour_is_monotone_in_luminance() {
        let mut last = -1.0;
        for k in 0..=20 {
            let c = false_colour(k as f64 / 20.0);
            let l = luminance(DVec3::new(c.r() as f64, c.g() as f64, c.b() as f64));
            assert!(l > last, "step {k}: {l} after {last}");
            last = l;
        }
    }
}
