//! A mesh's spherical polygon at a point: contour edges and the convex silhouette (001 Sect.
//! 4.2), the exact silhouette of a non-convex mesh (001 Sect. 4.3) with quantitative
//! invisibility, and the outline inside a light's window with the candidates a tile shares.

pub(crate) mod contour_pieces;
pub mod exact_silhouette;
pub mod quantitative_invisibility;
pub mod silhouette;
pub mod silhouette_walk;
pub mod tile_candidates;
pub mod windowed_silhouette;
