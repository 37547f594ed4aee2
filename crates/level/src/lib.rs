//! Vangers world data: the file formats (`world.ini`, `.vmc`, `.vmp`, `.pal`,
//! `.vpr`), the decoded two-interval terrain model, edits, and a generator of
//! Vangers-like worlds. No GPU dependency.

pub mod config;
pub mod edit;
pub mod error;
pub mod generate;
pub mod huffman;
pub mod io;
pub mod model;
pub mod palette;
pub mod stats;
pub mod views;
pub mod vmc;
pub mod vmp;
pub mod vpr;

pub use config::WorldConfig;
pub use edit::DirtyRect;
pub use error::LevelError;
pub use model::{Column, Level, MidRule};
pub use palette::Palette;
pub use views::{EditSite, ViewSpec};

/// A complete world: the decoded map plus everything the directory carries.
#[derive(Clone, Debug)]
pub struct World {
    /// A short name for reports (the directory name, or `generated-<seed>`).
    pub name: String,
    pub level: Level,
    pub config: WorldConfig,
    pub palette: Palette,
    /// Water level of each 128-row section, when a `.vpr` is present.
    pub water: Option<Vec<i32>>,
    /// The world's default views (`views.txt`; Fostral's twelve for Fostral).
    pub views: Vec<ViewSpec>,
    /// The world's edit fixture (`edit.txt`; the paper's crater for Fostral).
    pub edit: Option<EditSite>,
}
