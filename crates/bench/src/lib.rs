//! The measurement harness behind `strata compare` and `strata merge`: typed
//! results, statistics, the report and picture grid, and the protocol runner.

pub mod edits;
pub mod figures;
#[cfg(not(target_arch = "wasm32"))]
pub mod flip;
pub mod font;
pub mod grid;
pub mod merge;
pub mod methods;
pub mod plan;
pub mod portability;
pub mod report;
pub mod results;
pub mod resume;
pub mod run;
pub mod session;
pub mod stats;
pub mod tune;
pub mod video;

#[cfg(test)]
mod fixtures;
