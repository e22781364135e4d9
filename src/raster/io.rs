//! Image files: PFM (read and write), OpenEXR and PNG (write).
//!
//! In memory an image is `width * height` linear RGB pixels, row-major, row 0 at the top.
//! Every error message names the file.

use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::Path;

use crate::error::InFile;

fn io_err(path: &Path, kind: io::ErrorKind, msg: impl std::fmt::Display) -> io::Error {
    io::Error::new(kind, format!("{}: {msg}", path.display()))
}

fn with_path(path: &Path) -> impl FnOnce(io::Error) -> io::Error + '_ {
    move |e| io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

/// `width * height`, if it matches `len` and does not overflow.
fn check_len(width: u32, height: u32, len: usize) -> crate::Result<()> {
    match (width as usize).checked_mul(height as usize) {
        Some(n) if n == len => Ok(()),
        Some(n) => Err(crate::Error::from(format!(
            "{width}x{height} image needs {n} pixels, got {len}"
        ))),
        None => Err(crate::Error::from(format!(
            "{width}x{height} image is too large"
        ))),
    }
}

/// Writes a colour PFM ("PF", little endian: scale -1.0). The format stores rows bottom to
/// top; `rgb` has row 0 at the top.
pub fn write_pfm(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> io::Result<()> {
    check_len(width, height, rgb.len())
        .map_err(|m| io_err(path, io::ErrorKind::InvalidInput, m))?;
    let header = format!("PF\n{width} {height}\n-1.0\n");
    let mut buf = Vec::with_capacity(header.len() + rgb.len() * 12);
    buf.extend_from_slice(header.as_bytes());
    if width > 0 {
        for row in rgb.chunks_exact(width as usize).rev() {
            for px in row {
                for c in px {
                    buf.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
    }
    let file = File::create(path).map_err(with_path(path))?;
    let mut w = BufWriter::new(file);
    w.write_all(&buf).map_err(with_path(path))?;
    w.flush().map_err(with_path(path))
}

/// Reads a PFM: colour ("PF") or greyscale ("Pf", returned as grey RGB), either
/// endianness (negative scale = little endian). Returns `(width, height, pixels)` with row 0
/// at the top. The magnitude of the scale is ignored.
pub fn read_pfm(path: &Path) -> io::Result<(u32, u32, Vec<[f32; 3]>)> {
    let mut bytes = Vec::new();
    File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(with_path(path))?;
    let bad = |m: String| io_err(path, io::ErrorKind::InvalidData, format!("PFM: {m}"));

    // Header: four whitespace-separated tokens, then exactly one whitespace byte.
    let mut pos = 0;
    let mut token = || -> Result<&[u8], io::Error> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos || pos >= bytes.len() {
            return Err(bad("truncated header".into()));
        }
        Ok(&bytes[start..pos])
    };
    let channels = match token()? {
        b"PF" => 3,
        b"Pf" => 1,
        m => {
            return Err(bad(format!(
                "bad magic {:?} (expected PF or Pf)",
                String::from_utf8_lossy(m)
            )));
        }
    };
    let mut number = |what: &str| -> Result<String, io::Error> {
        let t = token()?;
        std::str::from_utf8(t)
            .map(str::to_owned)
            .map_err(|_| bad(format!("bad {what}")))
    };
    let width: u32 = number("width")?
        .parse()
        .map_err(|_| bad("bad width".into()))?;
    let height: u32 = number("height")?
        .parse()
        .map_err(|_| bad("bad height".into()))?;
    let scale: f32 = number("scale")?
        .parse()
        .map_err(|_| bad("bad scale".into()))?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(bad(format!("bad scale {scale}")));
    }
    let little = scale < 0.0;
    let data = &bytes[pos + 1..]; // the single whitespace byte after the scale
    let n = (width as usize)
        .checked_mul(height as usize)
        .ok_or_else(|| bad(format!("{width}x{height} is too large")))?;
    let need = n
        .checked_mul(channels * 4)
        .ok_or_else(|| bad(format!("{width}x{height} is too large")))?;
    if data.len() < need {
        return Err(bad(format!(
            "{width}x{height} needs {need} bytes of data, file has {}",
            data.len()
        )));
    }

    let mut values = data[..need].chunks_exact(4).map(|b| {
        let b = [b[0], b[1], b[2], b[3]];
        if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    });
    let mut rows: Vec<Vec<[f32; 3]>> = Vec::with_capacity(height as usize);
    for _ in 0..height {
        let row = (0..width)
            .map(|_| {
                if channels == 3 {
                    let r = values.next().unwrap_or(0.0);
                    let g = values.next().unwrap_or(0.0);
                    let b = values.next().unwrap_or(0.0);
                    [r, g, b]
                } else {
                    [values.next().unwrap_or(0.0); 3]
                }
            })
            .collect();
        rows.push(row);
    }
    // Stored bottom to top.
    let pixels = rows.into_iter().rev().flatten().collect();
    Ok((width, height, pixels))
}

/// Writes linear RGB as 32-bit float OpenEXR (ZIP, scan lines).
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> crate::Result<()> {
    use exr::prelude::{Encoding, Image, SpecificChannels, Vec2, WritableImage};
    if let Err(m) = check_len(width, height, rgb.len()) {
        return Err(crate::Error::from(format!("{}: {m}", path.display())));
    }
    if width == 0 || height == 0 {
        return Err(crate::Error::from(format!(
            "{}: OpenEXR cannot store an empty image",
            path.display()
        )));
    }
    let w = width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let [r, g, b] = rgb[y * w + x];
        (r, g, b)
    });
    Image::from_encoded_channels((w, height as usize), Encoding::SMALL_LOSSLESS, channels)
        .write()
        .to_file(path)
        .in_file(path.display(), "writing OpenEXR")
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), on [0, 1].
pub fn srgb_oetf(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Tone-maps one linear value to an 8-bit sRGB code: times `2^exposure`, clamped to [0, 1]
/// (NaN to 0), sRGB curve, rounded.
pub fn to_srgb8(v: f32, exposure: f64) -> u8 {
    let x = v as f64 * exposure.exp2();
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    (srgb_oetf(x) * 255.0).round() as u8
}

/// Writes an 8-bit sRGB PNG from linear radiance, tone-mapped by [`to_srgb8`].
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    exposure: f64,
) -> crate::Result<()> {
    let bytes = png_bytes(width, height, rgb, exposure).in_file(path.display(), "writing PNG")?;
    std::fs::write(path, bytes).in_file(path.display(), "writing PNG")
}

/// [`write_png`]'s file as bytes (a download in the browser).
pub(crate) fn png_bytes(
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    exposure: f64,
) -> crate::Result<Vec<u8>> {
    if let Err(m) = check_len(width, height, rgb.len()) {
        return Err(crate::Error::from(format!("{m}")));
    }
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|px| px.map(|c| to_srgb8(c, exposure)))
        .collect();
    encode_png(&bytes, width, height, image::ExtendedColorType::Rgb8)
}

/// 8-bit pixels (RGB or RGBA) as a PNG file's bytes.
pub(crate) fn encode_png(
    pixels: &[u8],
    width: u32,
    height: u32,
    color: image::ExtendedColorType,
) -> crate::Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(pixels, width, height, color)
        .map_err(|e| crate::Error::from(format!("encoding PNG: {e}")))?;
    Ok(out)
}

/// Reads a PFM file as a linear [`Image`](super::Image).
pub fn read_pfm_image(path: &Path) -> io::Result<super::Image> {
    let (width, height, px) = read_pfm(path)?;
    Ok(super::Image {
        width,
        height,
        pixels: px
            .iter()
            .map(|c| glam::DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
            .collect(),
    })
}
