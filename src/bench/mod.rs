//! The report of `penumbra bench`: run time against error for every method at a ladder of
//! budgets. The driver renders and times; this module holds what it produces and what is read
//! off it, all pure data. See `docs/benchmarks.md`.
//!
//! * [`table`]: one row per render (`BenchRow`), the report of a scene (`BenchReport`),
//!   CSV and JSON files, the noise-corrected RMSE.
//! * [`equal_time`](mod@equal_time): the error each method reaches in the analytic method's time, and the time
//!   it needs for the analytic method's error (000 Fig. 6), by log–log interpolation.
//! * [`fit`]: least-squares lines and power laws for scaling plots (000 Figs. 5 and 7).
//! * [`runner`]: the driver: reference, ladder, timing, comparison.
//! * [`scaling`]: run time against vertex counts (000 Figs. 5 and 7).
//! * [`polyhedra`]: 001 Tables 7.2 and 7.4 on the nine polyhedra of Table 7.1.
//! * [`realworld`]: `--suite realworld`, the scenes users load ([`realworld_scenes`]).
//! * `environment`: `--env SCENE`, the environment light in the form of
//!   002's Tables 1 and 2.
//! * [`speed`]: `--suite speed`, the speed guard: ratios measured in one run against a
//!   committed baseline.
//! * [`memory`]: the peak resident memory of a row.
//! * [`plot`]: PNG charts drawn with tiny-skia, labelled with the stroke font of `font`.

pub mod environment_tables;
pub mod equal_time;
pub mod fit;
pub mod memory;
pub mod output;
pub(crate) use crate::figure::plot;
pub mod polyhedra;
pub mod realworld;
pub mod realworld_scenes;
pub mod runner;
pub mod scaling;
pub mod speed;
pub mod table;
