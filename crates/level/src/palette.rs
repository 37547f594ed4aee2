//! `.pal`: 256 RGB entries of 6-bit values (0..63), read as 8-bit (times 4).

use crate::error::LevelError;
use std::path::Path;

/// A palette in 8-bit RGB (the file's 6-bit values times 4).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Palette {
    /// RGB of each palette index; every channel a multiple of 4.
    pub colors: [[u8; 3]; 256],
}

/// Bytes in a `.pal` file.
pub const PAL_BYTES: usize = 256 * 3;

impl Palette {
    /// Decode `.pal` bytes; `path` only names the file in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, LevelError> {
        if bytes.len() != PAL_BYTES {
            return Err(LevelError::format(
                path,
                format!(
                    "palette is {} bytes, expected {PAL_BYTES} (256 x RGB)",
                    bytes.len()
                ),
            ));
        }
        if let Some(i) = bytes.iter().position(|&b| b > 63) {
            return Err(LevelError::format(
                path,
                format!(
                    "palette entry {} has value {} above the 6-bit maximum 63",
                    i / 3,
                    bytes[i]
                ),
            ));
        }
        let mut colors = [[0u8; 3]; 256];
        for (c, rgb) in colors.iter_mut().zip(bytes.chunks_exact(3)) {
            *c = [rgb[0] * 4, rgb[1] * 4, rgb[2] * 4];
        }
        Ok(Palette { colors })
    }

    /// The file bytes: each 8-bit channel divided by 4 (the low two bits,
    /// which a 6-bit palette cannot hold, are dropped).
    pub fn to_bytes(&self) -> Vec<u8> {
        self.colors.iter().flat_map(|c| c.map(|v| v >> 2)).collect()
    }

    /// Read and decode a `.pal` file.
    pub fn read(path: &Path) -> Result<Self, LevelError> {
        Self::from_bytes(&crate::error::read_file(path)?, path)
    }

    /// Write the palette as a `.pal` file.
    pub fn write(&self, path: &Path) -> Result<(), LevelError> {
        crate::error::write_file(path, &self.to_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fostral_palette_parses_and_round_trips() {
        let path = crate::error::fostral_file("harmony.pal");
        let bytes = std::fs::read(&path).unwrap();
        let pal = Palette::read(&path).unwrap();
        assert!(pal.colors.iter().flatten().all(|&v| v % 4 == 0 && v <= 252));
        // Not a blank palette: the terrain ranges hold many distinct colours.
        let distinct: std::collections::HashSet<_> = pal.colors.iter().collect();
        assert!(distinct.len() > 100, "{}", distinct.len());
        assert_eq!(pal.to_bytes(), bytes);
    }

    #[test]
    fn bad_palettes_are_errors() {
        let p = Path::new("p.pal");
        let err = Palette::from_bytes(&[0; 767], p).unwrap_err().to_string();
        assert!(err.contains("p.pal") && err.contains("767 bytes"), "{err}");
        let mut bytes = vec![0u8; PAL_BYTES];
        bytes[5] = 64;
        let err = Palette::from_bytes(&bytes, p).unwrap_err().to_string();
        assert!(err.contains("entry 1") && err.contains("64"), "{err}");
    }
}
