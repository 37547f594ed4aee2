//! The measurement harness behind `strata compare` and `strata merge`: typed
//! results, statistics, the report and picture grid, and the protocol runner.
//!
//! Stability: this crate is the harness of the `strata` tools (compare, merge, tune), not a library API. Its public items
//! serve the `strata` binary and the tests and may change between
//! revisions; the embedding API is `strata-render` with the GPU-free crates
//! (`strata-level`, `strata-camera`, `strata-mesh`, `strata-reference`,
//! `strata-collide`, `strata-physics`, `strata-export`), which are documented
//! item by item (`#![warn(missing_docs)]`).

pub mod edits;
pub mod figures;
#[cfg(not(target_arch = "wasm32"))]
pub mod flip;
pub mod font;
pub mod gameplay;
pub mod grid;
pub mod merge;
pub mod methods;
#[cfg(not(target_arch = "wasm32"))]
pub mod paged_run;
pub mod plan;
pub mod portability;
pub mod resume;
pub mod run;
pub mod session;
pub mod tune;
pub mod video;
pub mod warm;

// The results file, merge's checks, the statistics and `report.md` need no
// GPU: their home is `strata-results` (which `strata-fuzz` fuzzes without
// building wgpu); these keep the `strata_bench::…` paths.
pub use strata_results as results;
pub use strata_results::{report, stats};

#[cfg(test)]
use strata_results::fixtures;
