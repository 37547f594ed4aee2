//! `.vpr`: the original world generator's state, ending with the water
//! (flood) level of each section of 2^`Section Size Power` rows.
//!
//! The game's layout (its `LoadVPR`, and vange-rs's `load_flood`), with
//! `geo` = `GeoNet Power`, W x H the map, `sections` = H >> `Section Size
//! Power`, `net` = (W H) >> (2 geo):
//!
//! ```text
//! flood_offset = 2*4 + (1+4+4)*4 + 2*net + 2*geo*4 + 2*sections*geo*4
//! file size    = flood_offset + 4*sections
//! ```
//!
//! Both readers refuse a file of any other size; the levels are `sections`
//! i32 LE at `flood_offset` (Fostral: 128 sections, all 80).
//!
//! What Strata models: only the water levels. The bytes before them are
//! the generator's state (its geo net and per-section tables), which no
//! reader of a finished world uses: a world Strata makes gets them
//! zero-filled; a world read from a game-layout file keeps them as read
//! (see [`crate::SourceFiles`]), so writing it back changes only the levels.
//!
//! Strata's older files (`STRATVPR`: the magic, u32 LE section count, u32 LE
//! rows per section, then the levels) are still read, so caches written
//! before the game's layout was adopted keep working.

use crate::config::WorldConfig;
use crate::error::LevelError;
use std::path::Path;

/// The magic Strata's older `.vpr` files start with.
pub const OLD_STRATA_MAGIC: &[u8; 8] = b"STRATVPR";
/// Bytes before the levels in an older Strata file.
const OLD_STRATA_HEADER: u64 = 16;

/// Where the water levels lie in a `.vpr`, from the map's size and the
/// two `world.ini` powers the game computes it from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VprLayout {
    /// Map width, texels.
    pub width: u32,
    /// Map height, texels.
    pub height: u32,
    /// `[Global Parameters] GeoNet Power`.
    pub geo_net_power: u32,
    /// `[Global Parameters] Section Size Power`.
    pub section_size_power: u32,
}

/// Which layout a `.vpr` was read in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VprFormat {
    /// The game's own layout (generator state, then the levels).
    Game,
    /// Strata's older `STRATVPR` layout.
    OldStrata,
}

impl VprLayout {
    /// The layout a world's config implies.
    pub fn of(config: &WorldConfig) -> Self {
        VprLayout {
            width: config.width(),
            height: config.height(),
            geo_net_power: config.geo_net_power(),
            section_size_power: config.section_size_power(),
        }
    }

    /// Water sections: H >> `Section Size Power`, as the game counts them.
    pub fn sections(&self) -> usize {
        self.height
            .checked_shr(self.section_size_power)
            .unwrap_or(0) as usize
    }

    /// Cells of the generator's geo net: (W H) >> (2 `GeoNet Power`).
    fn net_size(&self) -> u64 {
        (u64::from(self.width) * u64::from(self.height))
            .checked_shr(2 * self.geo_net_power)
            .unwrap_or(0)
    }

    /// Byte offset of the first water level.
    pub fn flood_offset(&self) -> u64 {
        let geo = u64::from(self.geo_net_power);
        let sections = self.sections() as u64;
        2 * 4 + (1 + 4 + 4) * 4 + 2 * self.net_size() + 2 * geo * 4 + 2 * sections * geo * 4
    }

    /// The size the game's readers require.
    pub fn file_size(&self) -> u64 {
        self.flood_offset() + 4 * self.sections() as u64
    }

    /// Size of an older Strata file of this map.
    fn old_strata_size(&self) -> u64 {
        OLD_STRATA_HEADER + 4 * self.sections() as u64
    }

    /// Check a `.vpr` file's length (before reading it, so a huge file is
    /// refused without being read): the game's size, or an older Strata file's.
    pub fn check_len(&self, len: u64, path: &Path) -> Result<(), LevelError> {
        if len == self.file_size() || len == self.old_strata_size() {
            return Ok(());
        }
        let what = if len < self.file_size() {
            "too short"
        } else {
            "too long"
        };
        Err(LevelError::format(
            path,
            format!(
                "{len} bytes, {what}: the water levels of a {}x{} map (GeoNet Power {}, Section \
                 Size Power {}) need a .vpr of {} bytes ({} levels at byte {}); does world.ini \
                 match the file?",
                self.width,
                self.height,
                self.geo_net_power,
                self.section_size_power,
                self.file_size(),
                self.sections(),
                self.flood_offset()
            ),
        ))
    }
}

fn read_levels(bytes: &[u8]) -> Vec<i32> {
    bytes
        .chunks_exact(4)
        .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The water levels of `.vpr` bytes, and the layout they were in. `path`
/// names the file in errors.
pub fn parse_vpr(
    bytes: &[u8],
    layout: &VprLayout,
    path: &Path,
) -> Result<(Vec<i32>, VprFormat), LevelError> {
    let len = bytes.len() as u64;
    layout.check_len(len, path)?;
    let sections = layout.sections();
    if len == layout.file_size() {
        let start = layout.flood_offset() as usize;
        return Ok((read_levels(&bytes[start..]), VprFormat::Game));
    }
    // The older Strata layout's size: its header must agree with the map.
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let rows = 1u64 << layout.section_size_power;
    if &bytes[..8] != OLD_STRATA_MAGIC
        || word(8) as usize != sections
        || u64::from(word(12)) != rows
    {
        return Err(LevelError::format(
            path,
            format!(
                "{len} bytes, neither the game's layout ({} bytes for a {}x{} map) nor an older \
                 Strata file of {sections} sections of {rows} rows",
                layout.file_size(),
                layout.width,
                layout.height
            ),
        ));
    }
    Ok((
        read_levels(&bytes[OLD_STRATA_HEADER as usize..]),
        VprFormat::OldStrata,
    ))
}

/// The bytes of a `.vpr` in the game's layout: `source` (a game-layout file
/// of the same map, as read) up to its levels, else zeros, then `levels`.
pub fn vpr_bytes(
    levels: &[i32],
    layout: &VprLayout,
    source: Option<&[u8]>,
    path: &Path,
) -> Result<Vec<u8>, LevelError> {
    if levels.len() != layout.sections() {
        return Err(LevelError::format(
            path,
            format!(
                "{} water levels, but a map of {} rows in sections of 2^{} rows has {}",
                levels.len(),
                layout.height,
                layout.section_size_power,
                layout.sections()
            ),
        ));
    }
    let state = layout.flood_offset() as usize;
    let mut out = match source {
        Some(bytes) if bytes.len() as u64 == layout.file_size() => bytes[..state].to_vec(),
        _ => vec![0u8; state],
    };
    out.reserve_exact(4 * levels.len());
    for l in levels {
        out.extend_from_slice(&l.to_le_bytes());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fostral_layout() -> VprLayout {
        VprLayout {
            width: 2048,
            height: 16384,
            geo_net_power: 5,
            section_size_power: 7,
        }
    }

    #[test]
    fn fostral_vpr_water_is_80_everywhere_and_writes_back_byte_identically() {
        let path = crate::error::fostral_file("output.vpr");
        let bytes = std::fs::read(&path).unwrap();
        let layout = fostral_layout();
        assert_eq!(bytes.len() as u64, layout.file_size());
        let (levels, format) = parse_vpr(&bytes, &layout, &path).unwrap();
        assert_eq!(format, VprFormat::Game);
        assert_eq!(levels.len(), 128);
        assert!(levels.iter().all(|&l| l == 80), "{levels:?}");
        let back = vpr_bytes(&levels, &layout, Some(&bytes), &path).unwrap();
        assert!(back == bytes, "Fostral's .vpr changed on write-back");
        // A changed level changes only its own four bytes.
        let mut raised = levels.clone();
        raised[3] = 90;
        let changed = vpr_bytes(&raised, &layout, Some(&bytes), &path).unwrap();
        let differ: Vec<usize> = (0..bytes.len())
            .filter(|&i| bytes[i] != changed[i])
            .collect();
        assert_eq!(differ, vec![layout.flood_offset() as usize + 12]);
    }

    #[test]
    fn size_formula_matches_the_writer_at_two_map_sizes() {
        // The formula written out by hand, against the issue's figure and the writer.
        for (w, h, geo, sec, expected) in [
            (2048u32, 16384u32, 5u32, 7u32, 71_252u64),
            (
                1024,
                2048,
                5,
                7,
                8 + 36 + 2 * 2048 + 40 + 2 * 16 * 5 * 4 + 16 * 4,
            ),
        ] {
            let layout = VprLayout {
                width: w,
                height: h,
                geo_net_power: geo,
                section_size_power: sec,
            };
            assert_eq!(layout.file_size(), expected, "{w}x{h}");
            let levels = vec![80; (h >> sec) as usize];
            let bytes = vpr_bytes(&levels, &layout, None, Path::new("o.vpr")).unwrap();
            assert_eq!(bytes.len() as u64, expected, "{w}x{h}");
            // Zero-filled state, levels where the game reads them.
            let offset = layout.flood_offset() as usize;
            assert!(bytes[..offset].iter().all(|&b| b == 0));
            let (back, format) = parse_vpr(&bytes, &layout, Path::new("o.vpr")).unwrap();
            assert_eq!((back, format), (levels, VprFormat::Game));
        }
    }

    #[test]
    fn older_strata_files_still_read() {
        let layout = VprLayout {
            width: 256,
            height: 512,
            geo_net_power: 5,
            section_size_power: 7,
        };
        let mut bytes = OLD_STRATA_MAGIC.to_vec();
        bytes.extend_from_slice(&4u32.to_le_bytes());
        bytes.extend_from_slice(&128u32.to_le_bytes());
        for l in [70i32, 71, 72, 73] {
            bytes.extend_from_slice(&l.to_le_bytes());
        }
        let (levels, format) = parse_vpr(&bytes, &layout, Path::new("a.vpr")).unwrap();
        assert_eq!(
            (levels, format),
            (vec![70, 71, 72, 73], VprFormat::OldStrata)
        );
        // Same size without the magic: neither layout.
        bytes[0] = b'X';
        let err = parse_vpr(&bytes, &layout, Path::new("a.vpr"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("a.vpr: 32 bytes, neither"), "{err}");
    }

    #[test]
    fn wrong_sizes_name_the_file_and_both_sizes() {
        let layout = fostral_layout();
        let p = Path::new("w/output.vpr");
        let short = parse_vpr(&[0u8; 20], &layout, p).unwrap_err().to_string();
        assert!(
            short.starts_with("w/output.vpr: 20 bytes, too short") && short.contains("71252 bytes"),
            "{short}"
        );
        let long = parse_vpr(&vec![0u8; 71_256], &layout, p)
            .unwrap_err()
            .to_string();
        assert!(
            long.contains("71256 bytes, too long") && long.contains("71252 bytes"),
            "{long}"
        );
        let err = vpr_bytes(&[1, 2], &layout, None, p)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("2 water levels") && err.contains("has 128"),
            "{err}"
        );
    }
}
