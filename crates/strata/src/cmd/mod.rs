//! One module per subcommand: its arguments and its `run`.

pub mod adapters;
pub mod collide;
pub mod compare;
pub mod convert;
pub mod exact_counts;
pub mod export;
pub mod fit;
pub mod fly;
pub mod generate;
pub mod info;
pub mod merge;
pub mod metrics;
pub mod physics_bench;
pub mod reference;
pub mod render;
pub mod serve;
pub mod soak;
pub mod store_info;
pub mod survey;
pub mod tune;
pub mod video;
pub mod view;
