//! Figures as plain data and their back ends: a figure description (`description`), drawn
//! into pixmaps ([`raster`], labels in the vector font of [`font`]) or written as SVG
//! ([`svg`]) or PDF ([`pdf`]); and charts built as such descriptions ([`plot`]). Below every layer that draws a
//! chart or a heat map (the benchmark, the LTC error map).

use crate::error::InFile;

pub(crate) mod description;
pub mod font;
pub mod pdf;
pub mod plot;
pub mod raster;
pub mod svg;

pub use description::{Figure, Item, Rect, Rgb, Shape, Subpath};

/// The figure as the content of a `format` file (svg, pdf or png), as [`save`] writes it: a
/// download in the browser.
pub fn to_bytes(figure: &Figure, format: &str) -> crate::Result<Vec<u8>> {
    match format.to_ascii_lowercase().as_str() {
        "svg" => Ok(svg::to_svg(figure).into_bytes()),
        "pdf" => Ok(pdf::to_pdf(figure)),
        "png" => Ok(plot::pixmap_png_bytes(&raster::render(figure))?),
        _ => Err(crate::Error::from(format!(
            "a figure is written as .svg, .pdf or .png, not .{format}"
        ))),
    }
}

/// Writes `figure` to `path` as SVG, PDF or PNG, by the path's extension; an error names the
/// file.
pub fn save(figure: &Figure, path: &std::path::Path) -> crate::Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !["svg", "pdf", "png"].contains(&ext.to_ascii_lowercase().as_str()) {
        return Err(crate::Error::from(format!(
            "{}: a figure is written as .svg, .pdf or .png",
            path.display()
        )));
    }
    to_bytes(figure, ext)
        .and_then(|bytes| Ok(std::fs::write(path, bytes)?))
        .in_file(path.display(), "cannot write the figure")
}
