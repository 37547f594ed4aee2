//! `world.ini`: the world's configuration. (Parsing and writing: see issue 2.)

/// The parts of `world.ini` the renderer and the file formats need.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorldConfig {
    /// Width = 2^`Map Power X`.
    pub map_power_x: u32,
    /// Height = 2^`Map Power Y`.
    pub map_power_y: u32,
    /// `[Storage] Compressed Format Using=1`: the map is `.vmc`, else `.vmp`.
    pub compressed: bool,
    /// `[Storage] File Name`, without extension.
    pub file_name: String,
    /// `[Storage] Palette File`.
    pub palette_file: String,
    /// First palette index of each terrain type's colour range.
    pub begin_colors: [u8; 8],
    /// Last palette index of each terrain type's colour range.
    pub end_colors: [u8; 8],
}

impl WorldConfig {
    pub fn width(&self) -> u32 {
        1 << self.map_power_x
    }
    pub fn height(&self) -> u32 {
        1 << self.map_power_y
    }
}
