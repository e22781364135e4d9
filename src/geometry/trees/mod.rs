//! Trees of precomputed silhouettes (001 Sect. 5): the BSP tree of a convex mesh's face planes,
//! the exact-silhouette tree of a non-convex one, the hoisted form (001 Sect. 8), their cells
//! and sections, and the triangulations proved per cell for sampling (001 Sect. 6.2).

pub mod bsp;
pub mod bsp_hoisted;
pub mod bsp_nonconvex;
pub mod bsp_sections;
pub mod cell_triangulation;
pub mod convex_cell;
pub mod silhouette_tree;
