//! The environment map: an equirectangular RGB radiance map with a rotation about +y and a
//! scale, its files (.hdr, .exr), an embedded procedural sky, and importance sampling for the
//! Monte Carlo reference.
//!
//! Convention (y up): pixel (column i, row j) of a W×H map is the direction with
//! θ = π(j + ½)/H from +y and φ = 2π(i + ½)/W, d = (sin θ sin φ, cos θ, −sin θ cos φ).
//! Row 0 is the top (+y); u = ¼ is +x, u = ½ is +z, u = 0 is −z.
//!
//! The map is piecewise constant: [`EnvironmentMap::radiance`] returns the pixel the direction
//! falls in (nearest pixel, no filtering). That is exactly the function the SH projection, the
//! pixel sums and [`EnvironmentSampler`] integrate, so they all agree on one radiance.

use std::f64::consts::PI;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use crate::error::InFile;
use glam::{DMat3, DVec3};

use super::sh::Sh9;

/// An equirectangular radiance map (see the module documentation for the convention).
///
/// The radiance in the world direction d is `scale · map(R_y(−rotate_deg) d)`: the content
/// is turned by `rotate_deg` about +y, right-handed (counter-clockwise seen from above), so
/// with `rotate_deg = 90` what the file shows at +x appears at −z, and what it shows at +z
/// appears at +x.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    width: usize,
    height: usize,
    /// Row-major, row 0 at the top (+y), linear RGB radiance.
    pixels: Vec<DVec3>,
    /// Rotation of the content about +y, in degrees (right-handed).
    pub rotate_deg: f64,
    /// Multiplies every pixel.
    pub scale: f64,
}

/// Rec. 709 luminance, the weight of a pixel for importance sampling.
pub(crate) use crate::raster::luminance;

impl EnvironmentMap {
    /// A map from `width * height` row-major pixels (row 0 at the top), no rotation, scale 1.
    /// Fails on a zero size, a pixel count that does not match, or a non-finite pixel.
    /// Negative pixels are allowed (a band-limited map rings below zero).
    pub fn new(width: usize, height: usize, pixels: Vec<DVec3>) -> crate::Result<Self> {
        if width == 0 || height == 0 {
            return Err(crate::Error::from(format!(
                "environment map has zero size ({width}x{height})"
            )));
        }
        if width.checked_mul(height) != Some(pixels.len()) {
            return Err(crate::Error::from(format!(
                "a {width}x{height} environment map needs {} pixels, got {}",
                width.saturating_mul(height),
                pixels.len()
            )));
        }
        if let Some(k) = pixels.iter().position(|p| !p.is_finite()) {
            return Err(crate::Error::from(format!(
                "environment map pixel ({}, {}) is not finite: {}",
                k % width,
                k / width,
                pixels[k]
            )));
        }
        Ok(Self {
            width,
            height,
            pixels,
            rotate_deg: 0.0,
            scale: 1.0,
        })
    }

    /// The same map with `rotate_deg` set.
    pub fn with_rotation(mut self, rotate_deg: f64) -> Self {
        self.rotate_deg = rotate_deg;
        self
    }

    /// The same map with `scale` set.
    pub fn with_scale(mut self, scale: f64) -> Self {
        self.scale = scale;
        self
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Row-major pixels, row 0 at the top; without rotation and scale.
    pub fn pixels(&self) -> &[DVec3] {
        &self.pixels
    }

    /// The stored value of pixel (column i, row j), without scale.
    pub fn pixel(&self, i: usize, j: usize) -> DVec3 {
        self.pixels[j * self.width + i]
    }

    /// The direction in the map's own frame at texture coordinates (u, v) ∈ [0, 1]²,
    /// v = 0 at the top: θ = π v from +y, φ = 2π u, d = (sin θ sin φ, cos θ, −sin θ cos φ).
    pub fn direction_at(u: f64, v: f64) -> DVec3 {
        let (sin_theta, cos_theta) = (PI * v).sin_cos();
        let (sin_phi, cos_phi) = (2.0 * PI * u).sin_cos();
        DVec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
    }

    /// The centre of pixel (i, j) in the map's own frame (rotation not applied; see
    /// [`Self::rotation`]).
    pub fn direction(&self, i: usize, j: usize) -> DVec3 {
        Self::direction_at(
            (i as f64 + 0.5) / self.width as f64,
            (j as f64 + 0.5) / self.height as f64,
        )
    }

    /// The pixel (i, j) containing the map-frame direction `d` (any length but zero). Pixel
    /// edges belong to the pixel after them; the poles and u = 1 are clamped into the map.
    pub fn pixel_of(&self, d: DVec3) -> (usize, usize) {
        let theta = d.x.hypot(d.z).atan2(d.y);
        let mut phi = d.x.atan2(-d.z);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let i = ((phi / (2.0 * PI) * self.width as f64) as usize).min(self.width - 1);
        let j = ((theta / PI * self.height as f64) as usize).min(self.height - 1);
        (i, j)
    }

    /// The exact solid angle of each pixel of row j: (2π/W)(cos θ_top − cos θ_bottom).
    pub fn solid_angle(&self, j: usize) -> f64 {
        let h = self.height as f64;
        let top = (PI * j as f64 / h).cos();
        let bottom = (PI * (j + 1) as f64 / h).cos();
        2.0 * PI / self.width as f64 * (top - bottom)
    }

    /// Map frame → world: R_y(rotate_deg), right-handed about +y.
    pub fn rotation(&self) -> DMat3 {
        DMat3::from_rotation_y(self.rotate_deg.to_radians())
    }

    /// The radiance arriving from the world direction `d`: `scale · map(R_y(−rotate_deg) d)`,
    /// nearest pixel (the map is piecewise constant, see the module documentation).
    pub fn radiance(&self, d: DVec3) -> DVec3 {
        let (i, j) = self.pixel_of(self.rotation().transpose() * d);
        self.scale * self.pixel(i, j)
    }

    /// Reads a Radiance RGBE (`.hdr`) or OpenEXR (`.exr`, the first RGB(A) layer) file.
    /// Every error names the file. Non-finite pixels are an error; negative pixels (which
    /// some EXR writers leave after filtering) are clamped to zero with a warning on stderr.
    pub fn load(path: impl AsRef<Path>) -> crate::Result<Self> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let decoded = match ext.as_deref() {
            Some("hdr") => read_hdr(path)?,
            Some("exr") => read_exr(path)?,
            _ => {
                return Err(crate::Error::from(format!(
                    "{}: unsupported environment map format (expected .hdr or .exr)",
                    path.display()
                )));
            }
        };
        Self::from_decoded(decoded, &path.display().to_string())
    }

    /// [`EnvironmentMap::load`] from a file's content (dropped on the browser's page): `name`
    /// tells the format by its extension and names the map in errors.
    pub fn from_bytes(bytes: &[u8], name: &str) -> crate::Result<Self> {
        let ext = Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let decoded = match ext.as_deref() {
            Some("hdr") => {
                decode_hdr(std::io::Cursor::new(bytes)).in_file(name, "reading Radiance HDR")?
            }
            Some("exr") => {
                decode_exr(std::io::Cursor::new(bytes)).in_file(name, "reading OpenEXR")?
            }
            _ => {
                return Err(crate::Error::from(format!(
                    "{name}: unsupported environment map format (expected .hdr or .exr)"
                )));
            }
        };
        Self::from_decoded(decoded, name)
    }

    /// The map of decoded pixels; negative components (some EXRs have them) are clamped to 0
    /// with a warning naming `label`.
    fn from_decoded(
        (width, height, mut pixels): (usize, usize, Vec<DVec3>),
        label: &str,
    ) -> crate::Result<Self> {
        let negative = pixels.iter().filter(|p| p.min_element() < 0.0).count();
        if negative > 0 && pixels.iter().all(|p| p.is_finite()) {
            eprintln!("warning: {label}: {negative} pixels with negative components, clamped to 0");
            for p in &mut pixels {
                *p = p.max(DVec3::ZERO);
            }
        }
        Self::new(width, height, pixels).in_file(label, "")
    }

    /// The embedded default: a procedural sky, so that nothing needs downloading. A blue
    /// zenith brightening to a pale horizon, a warm sun lobe (Gaussian, 3° wide, at 35°
    /// elevation towards u = 0.375, between +x and +z) and a dark ground below the horizon,
    /// blended over a few degrees so nothing is discontinuous. Deterministic; evaluated at the
    /// pixel centres. 256×128 is plenty.
    pub fn sky(width: usize, height: usize) -> Self {
        Self::from_fn(width.max(1), height.max(1), sky_radiance)
            .expect("the procedural sky is finite")
    }

    /// The band-limited map whose pixels are the SH reconstruction (Eq. 8) at the pixel
    /// centres; no rotation, scale 1. Can have negative pixels where the SH rings.
    pub fn from_sh(sh: &Sh9, width: usize, height: usize) -> Self {
        Self::from_fn(width, height, |d| sh.eval(d))
            .expect("SH reconstruction of finite coefficients")
    }

    /// The map whose pixel (i, j) is `radiance` at its centre's direction (map frame).
    fn from_fn(
        width: usize,
        height: usize,
        radiance: impl Fn(DVec3) -> DVec3,
    ) -> crate::Result<Self> {
        let mut pixels = Vec::with_capacity(width * height);
        for j in 0..height {
            for i in 0..width {
                let d = Self::direction_at(
                    (i as f64 + 0.5) / width as f64,
                    (j as f64 + 0.5) / height as f64,
                );
                pixels.push(radiance(d));
            }
        }
        Self::new(width, height, pixels)
    }
}

/// The procedural sky's radiance in the map-frame direction `d` (unit).
fn sky_radiance(d: DVec3) -> DVec3 {
    let zenith = DVec3::new(0.20, 0.38, 0.85);
    let horizon = DVec3::new(1.05, 1.10, 1.20);
    let ground = DVec3::new(0.10, 0.085, 0.07);
    let sun_colour = DVec3::new(1.0, 0.85, 0.62);
    // A brighter ring at the horizon: the sky's optical depth grows towards it.
    let up = d.y.max(0.0);
    let sky = horizon.lerp(zenith, up.sqrt());
    let sun_dir = EnvironmentMap::direction_at(0.375, 0.5 - 35.0 / 180.0);
    let sigma = 3f64.to_radians();
    // exp((cos α − 1)/σ²) ≈ exp(−α²/2σ²) but needs no acos; peak 60× the zenith.
    let sun = sun_colour * (60.0 * ((d.dot(sun_dir) - 1.0) / (sigma * sigma)).exp());
    // Smoothstep over ±2° around the horizon between ground and sky.
    let t = ((d.y + 0.035) / 0.07).clamp(0.0, 1.0);
    let blend = t * t * (3.0 - 2.0 * t);
    ground.lerp(sky + sun, blend)
}

fn read_hdr(path: &Path) -> crate::Result<(usize, usize, Vec<DVec3>)> {
    let file = File::open(path).in_file(path.display(), "opening")?;
    decode_hdr(BufReader::new(file)).in_file(path.display(), "reading Radiance HDR")
}

fn decode_hdr(
    reader: impl std::io::BufRead + std::io::Seek,
) -> crate::Result<(usize, usize, Vec<DVec3>)> {
    let image = image::ImageReader::with_format(reader, image::ImageFormat::Hdr)
        .decode()?
        .into_rgb32f();
    let (w, h) = (image.width() as usize, image.height() as usize);
    let pixels = image
        .pixels()
        .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
    Ok((w, h, pixels))
}

/// The first RGBA layer of an OpenEXR file's content (the reading
/// `read_first_rgba_layer_from_file` makes of a file).
fn decode_exr(
    reader: impl std::io::Read + std::io::Seek + Send,
) -> crate::Result<(usize, usize, Vec<DVec3>)> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size: exr::prelude::Vec2<usize>, _: &exr::image::RgbaChannels| {
                (size.width(), vec![DVec3::ZERO; size.area()])
            },
            |(w, px): &mut (usize, Vec<DVec3>),
             pos: exr::prelude::Vec2<usize>,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = DVec3::new(r as f64, g as f64, b as f64);
            },
        )
        .first_valid_layer()
        .all_attributes();
    // The page has no threads to decompress with.
    #[cfg(target_arch = "wasm32")]
    let image = image.non_parallel();
    let image = image.from_buffered(reader)?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width(), size.height(), pixels))
}

fn read_exr(path: &Path) -> crate::Result<(usize, usize, Vec<DVec3>)> {
    // Reported before the decoder's own message, which does not always say "not found".
    if !path.exists() {
        return Err(crate::Error::from(format!(
            "{}: no such file",
            path.display()
        )));
    }
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![DVec3::ZERO; size.area()]),
        |(w, px): &mut (usize, Vec<DVec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = DVec3::new(r as f64, g as f64, b as f64);
        },
    )
    .in_file(path.display(), "reading OpenEXR")?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width(), size.height(), pixels))
}

/// Importance sampling of an [`EnvironmentMap`] for Monte Carlo references: a piecewise-constant
/// distribution over pixels, proportional to luminance × solid angle, mixed with a uniform
/// floor (`Self::UNIFORM_FLOOR` of the samples uniform on the sphere) so that the pdf is
/// positive everywhere, even where the map is black. Inside a pixel the direction is uniform
/// on the sphere (uniform in cos θ and φ), so the pdf is exactly the pixel's probability over
/// its solid angle.
#[derive(Clone, Debug)]
pub struct EnvironmentSampler {
    map: EnvironmentMap,
    to_world: DMat3,
    /// Probability of each pixel, row-major.
    pixel_prob: Vec<f64>,
    /// Cumulative row probabilities: `height + 1` entries from 0 to 1.
    row_cdf: Vec<f64>,
    /// Per row, the cumulative probabilities of its columns given the row: `width + 1`
    /// entries from 0 to 1 each.
    col_cdf: Vec<f64>,
}

impl EnvironmentSampler {
    /// The share of uniform-sphere sampling in the mixture.
    pub(crate) const UNIFORM_FLOOR: f64 = 0.1;

    /// Builds the tables for `map` (which is copied, with its rotation and scale).
    pub fn new(map: &EnvironmentMap) -> Self {
        let (w, h) = (map.width, map.height);
        let weight = |i: usize, j: usize| luminance(map.pixel(i, j)).max(0.0) * map.solid_angle(j);
        let total: f64 = (0..h)
            .flat_map(|j| (0..w).map(move |i| (i, j)))
            .map(|(i, j)| weight(i, j))
            .sum();
        let floor = if total > 0.0 {
            Self::UNIFORM_FLOOR
        } else {
            1.0
        };
        let mut pixel_prob = Vec::with_capacity(w * h);
        for j in 0..h {
            for i in 0..w {
                let fitted = if total > 0.0 {
                    weight(i, j) / total
                } else {
                    0.0
                };
                let uniform = map.solid_angle(j) / (4.0 * PI);
                pixel_prob.push((1.0 - floor) * fitted + floor * uniform);
            }
        }
        // Σ ΔΩ = 4π only up to rounding: normalise so the pdf integrates to 1 exactly.
        let sum: f64 = pixel_prob.iter().sum();
        pixel_prob.iter_mut().for_each(|p| *p /= sum);

        let mut row_cdf = Vec::with_capacity(h + 1);
        let mut col_cdf = Vec::with_capacity(h * (w + 1));
        row_cdf.push(0.0);
        for row in pixel_prob.chunks_exact(w) {
            let row_sum: f64 = row.iter().sum();
            row_cdf.push(row_cdf.last().unwrap() + row_sum);
            let mut acc = 0.0;
            col_cdf.push(0.0);
            for p in row {
                acc += p / row_sum;
                col_cdf.push(acc);
            }
            *col_cdf.last_mut().unwrap() = 1.0;
        }
        *row_cdf.last_mut().unwrap() = 1.0;
        Self {
            map: map.clone(),
            to_world: map.rotation(),
            pixel_prob,
            row_cdf,
            col_cdf,
        }
    }

    /// The probability of pixel (i, j) (the pdf integrated over the pixel).
    pub(crate) fn pixel_probability(&self, i: usize, j: usize) -> f64 {
        self.pixel_prob[j * self.map.width + i]
    }

    /// A world direction from two uniform numbers in [0, 1), with the radiance arriving from
    /// it (scale applied) and its pdf with respect to solid angle.
    pub fn sample(&self, u1: f64, u2: f64) -> (DVec3, DVec3, f64) {
        let (w, h) = (self.map.width, self.map.height);
        let (j, v1) = pick(&self.row_cdf, u1);
        let (i, v2) = pick(&self.col_cdf[j * (w + 1)..(j + 1) * (w + 1)], u2);
        // Uniform on the sphere inside the pixel: cos θ and φ uniform over its bounds.
        let cos_top = (PI * j as f64 / h as f64).cos();
        let cos_bottom = (PI * (j + 1) as f64 / h as f64).cos();
        let cos_theta = cos_top + v1 * (cos_bottom - cos_top);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (2.0 * PI * (i as f64 + v2) / w as f64).sin_cos();
        let d = DVec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi);
        let pdf = self.pixel_probability(i, j) / self.map.solid_angle(j);
        (
            self.to_world * d,
            self.map.scale * self.map.pixel(i, j),
            pdf,
        )
    }

    /// The pdf (per solid angle) of [`Self::sample`] returning the world direction `d`.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let (i, j) = self.map.pixel_of(self.to_world.transpose() * d);
        self.pixel_probability(i, j) / self.map.solid_angle(j)
    }
}

/// The bin of `u` in a cumulative table (first entry 0, last 1) and `u` rescaled to [0, 1)
/// inside it. Bins of zero probability are never returned.
fn pick(cdf: &[f64], u: f64) -> (usize, f64) {
    let bins = cdf.len() - 1;
    let k = cdf.partition_point(|&c| c <= u).clamp(1, bins) - 1;
    let width = cdf[k + 1] - cdf[k];
    let v = if width > 0.0 {
        ((u - cdf[k]) / width).clamp(0.0, 1.0 - f64::EPSILON)
    } else {
        0.5
    };
    (k, v)
}
