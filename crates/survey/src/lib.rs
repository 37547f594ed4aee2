//! The fit survey (issue 17): fit a set of worlds — by default a generated
//! grid that varies the dual fraction and the floor roughness one at a time
//! (the generator's knobs), or any world directories — at several mesh
//! qualities, and write the paper's ten-world table, the correlations of
//! log reduction against each predictor, the insertion causes against
//! quality, and plots. No GPU.
//!
//! Module map: [`plan`] (which worlds and qualities), [`run`](mod@run) (load, measure,
//! fit; one failed world keeps the others' rows), [`correlate`] (Pearson),
//! [`report`] (`survey.md`, `survey.json`), [`plots`] (SVG figures).
//!
//! Stability: this crate is the `strata survey` tool, not a library API. Its public items
//! serve the `strata` binary and the tests and may change between
//! revisions; the embedding API is `strata-render` with the GPU-free crates
//! (`strata-level`, `strata-camera`, `strata-mesh`, `strata-reference`,
//! `strata-collide`, `strata-physics`, `strata-export`), which are documented
//! item by item (`#![warn(missing_docs)]`).

pub mod correlate;
pub mod plan;
pub mod plots;
pub mod report;
pub mod run;

pub use plan::{Plan, WorldSpec};
pub use run::{FitRow, Survey, WorldRow, run};
