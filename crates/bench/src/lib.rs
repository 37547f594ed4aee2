//! The measurement harness behind `strata compare` and `strata merge`: typed
//! results, statistics, the report and picture grid, and the protocol runner.

pub mod font;
pub mod grid;
pub mod merge;
pub mod plan;
pub mod report;
pub mod results;
pub mod stats;

#[cfg(test)]
mod fixtures;
