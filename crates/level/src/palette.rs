//! `.pal`: 256 RGB entries of 6-bit values.

/// A palette in 8-bit RGB (the file's 6-bit values times 4).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Palette {
    pub colors: [[u8; 3]; 256],
}
