//! The integration tests, as one test binary: each module below is one file of `tests/`.
//!
//! One binary instead of one per file: every test binary links the whole dependency stack
//! (egui, wgpu), and thirty of them filled a CI machine's disk. A test that changes
//! process-wide state stays a binary of its own: `set_difference_alloc`, which replaces the
//! global allocator (see `Cargo.toml`). Each file is a crate of its own and reaches the library
//! through its public paths, the stages' included (docs/architecture.md, "The public surface").
//! Run one module with `cargo test --test suite <module>::`.

mod ltc_common;
mod set_difference_common;
mod silhouette_common;

mod accel_bvh;
mod accel_triangle;
mod blender_exports;
mod boundary_agreement;
mod bsp;
mod bsp_hoisted;
mod bsp_nonconvex;
mod cell_triangulation;
mod cli;
mod derivative;
mod edge_hierarchy;
mod environment_math;
mod environment_probe;
mod environment_render;
mod exact_silhouette;
mod exporter_precision;
#[cfg(feature = "gui")]
mod figure_egui;
mod figure_svg;
mod figure_views;
mod gltf_loading;
mod image_io;
mod instances;
mod layering;
mod loader_fuzz;
mod ltc_correction;
mod ltc_edge_integral;
mod ltc_fit_accuracy;
mod ltc_generate;
mod ltc_ggx;
mod ltc_polygon_error;
mod ltc_table;
mod near_convex;
mod one_code_path;
mod quantitative_invisibility;
mod recorder;
mod scene_edit;
mod scene_loading;
mod scene_obj;
mod set_difference;
mod set_difference_chains;
mod set_difference_regressions;
mod shading_oracles;
mod sky_windows;
mod stochastic;
mod stress_exporter;
mod thesis_polyhedra;
mod tile_candidates;
mod tree_cache;
mod tree_cache_bound;
mod tree_library;
mod windowed_silhouette;
#[cfg(feature = "gui")]
mod workbench;
#[cfg(feature = "gui")]
mod workbench_layout;
