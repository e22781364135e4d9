//! Figures drawn into pixmaps: a vector font for labels ([`font`]) and log–log charts with
//! their PNG writer ([`plot`]). Below every layer that draws a chart or a heat map (the
//! benchmark, the LTC error map).

pub mod font;
pub mod plot;
