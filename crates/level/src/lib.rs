//! Vangers world data: the file formats (`world.ini`, `.vmc`, `.vmp`, `.pal`,
//! `.vpr`), the decoded two-interval terrain model, edits, and a generator of
//! Vangers-like worlds. No GPU dependency.
//!
//! `FORMATS.md` (beside this crate's `Cargo.toml`) says what each file of a
//! world holds, what the game's and vange-rs's readers require of it, and
//! which parts Strata models.

pub mod config;
pub mod edit;
pub mod error;
pub mod generate;
pub mod huffman;
pub mod io;
pub mod model;
pub mod palette;
pub mod save;
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

use std::sync::Arc;

/// A complete world: the decoded map plus everything the directory carries.
#[derive(Clone, Debug)]
pub struct World {
    /// A short name for reports (the directory name, or `generated-<seed>`).
    pub name: String,
    pub level: Level,
    pub config: WorldConfig,
    pub palette: Palette,
    /// Water level of each section of 2^`Section Size Power` rows, when the
    /// world has a `.vpr` (see [`World::water_levels`] for a world without one).
    pub water: Option<Vec<i32>>,
    /// The world's default views (`views.txt`; Fostral's twelve for Fostral).
    pub views: Vec<ViewSpec>,
    /// The world's edit fixture (`edit.txt`; the paper's crater for Fostral).
    pub edit: Option<EditSite>,
    /// The bytes of the files the world was read from that the fields above
    /// do not hold whole; empty for a world made in memory.
    pub source: SourceFiles,
}

impl World {
    /// The water level of every section: the `.vpr`'s, else 0 everywhere
    /// (as vange-rs reads a world without one).
    pub fn water_levels(&self) -> Vec<i32> {
        match &self.water {
            Some(levels) => levels.clone(),
            None => vec![0; vpr::VprLayout::of(&self.config).sections()],
        }
    }
}

/// Bytes of a world's files as read, kept so that writing the world back
/// changes only what was edited (`io::write_world` uses them while they
/// still fit the world's map size).
#[derive(Clone, Default)]
pub struct SourceFiles {
    /// The `.vpr` when it was in the game's layout: its generator state,
    /// which Strata does not model, is written back unchanged.
    pub vpr: Option<Arc<[u8]>>,
    /// The `.vmc`: rows whose content did not change are written back with
    /// their own bytes and the file's Huffman trees where the format allows
    /// ([`vmc::encode_vmc_reusing`]).
    pub vmc: Option<Arc<[u8]>>,
}

impl std::fmt::Debug for SourceFiles {
    /// Sizes only: a map's bytes are tens of megabytes.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let len = |b: &Option<Arc<[u8]>>| b.as_ref().map(|b| b.len());
        f.debug_struct("SourceFiles")
            .field("vpr_bytes", &len(&self.vpr))
            .field("vmc_bytes", &len(&self.vmc))
            .finish()
    }
}
