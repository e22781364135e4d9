//! Figures as plain data and their back ends: a figure description ([`description`]), drawn
//! into pixmaps ([`raster`], labels in the vector font of [`font`]) or written as SVG
//! ([`svg`]); and charts built as such descriptions ([`plot`]). Below every layer that draws a
//! chart or a heat map (the benchmark, the LTC error map).

pub mod description;
pub mod font;
pub mod plot;
pub mod raster;
pub mod svg;

pub use description::{Figure, Item, Shape, Subpath};
