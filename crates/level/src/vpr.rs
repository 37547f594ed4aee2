//! `.vpr`: the original generator's state. All we read is its tail: one
//! i32 LE water (flood) level per section of 2^`Section Size Power` rows
//! (Fostral: 128 sections of 128 rows, all 80).
//!
//! What we write: a 16-byte preamble, the ASCII magic `STRATVPR`, then u32 LE
//! section count and u32 LE rows per section, followed by the trailing
//! levels. We do not reproduce the original generator's state (its layout
//! is undocumented); readers that follow the format read only the tail.

use crate::error::LevelError;
use std::path::Path;

/// The magic our own `.vpr` files start with.
pub const STRATA_VPR_MAGIC: &[u8; 8] = b"STRATVPR";

/// Read the water levels of `sections` sections from the end of `.vpr` bytes.
pub fn parse_vpr(bytes: &[u8], sections: usize, path: &Path) -> Result<Vec<i32>, LevelError> {
    let tail = sections * 4;
    if bytes.len() < tail {
        return Err(LevelError::format(
            path,
            format!(
                "{} bytes, too short for the {sections} trailing water levels ({tail} bytes)",
                bytes.len()
            ),
        ));
    }
    Ok(bytes[bytes.len() - tail..]
        .chunks_exact(4)
        .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

/// The bytes of our own `.vpr`: preamble (see module docs) then the levels.
pub fn vpr_bytes(levels: &[i32], rows_per_section: u32) -> Vec<u8> {
    let mut out = Vec::with_capacity(16 + levels.len() * 4);
    out.extend_from_slice(STRATA_VPR_MAGIC);
    out.extend_from_slice(&(levels.len() as u32).to_le_bytes());
    out.extend_from_slice(&rows_per_section.to_le_bytes());
    for l in levels {
        out.extend_from_slice(&l.to_le_bytes());
    }
    out
}

pub fn read_vpr(path: &Path, sections: usize) -> Result<Vec<i32>, LevelError> {
    parse_vpr(&crate::error::read_file(path)?, sections, path)
}

pub fn write_vpr(path: &Path, levels: &[i32], rows_per_section: u32) -> Result<(), LevelError> {
    crate::error::write_file(path, &vpr_bytes(levels, rows_per_section))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fostral_vpr_water_is_80_everywhere() {
        let path = crate::error::fostral_file("output.vpr");
        let levels = read_vpr(&path, 16384 / 128).unwrap();
        assert_eq!(levels.len(), 128);
        assert!(levels.iter().all(|&l| l == 80), "{levels:?}");
    }

    #[test]
    fn our_vpr_round_trips_and_short_files_fail() {
        let levels: Vec<i32> = (0..16).map(|i| 70 + i).collect();
        let bytes = vpr_bytes(&levels, 128);
        assert_eq!(&bytes[..8], STRATA_VPR_MAGIC);
        assert_eq!(parse_vpr(&bytes, 16, Path::new("a.vpr")).unwrap(), levels);
        let err = parse_vpr(&bytes[..20], 16, Path::new("a.vpr"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("a.vpr: 20 bytes"), "{err}");
    }
}
