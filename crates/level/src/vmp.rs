//! `.vmp`: the uncompressed map. No header; per row `width` height bytes
//! then `width` meta bytes.

use crate::error::LevelError;
use crate::model::{Level, MidRule};
use rayon::prelude::*;
use std::path::Path;

/// Decode `.vmp` bytes of a `width` x `height` map.
pub fn decode_vmp(
    bytes: &[u8],
    width: u32,
    height: u32,
    mid_rule: MidRule,
    path: &Path,
) -> Result<Level, LevelError> {
    let w = width as usize;
    let expected = 2 * w * height as usize;
    if bytes.len() != expected {
        return Err(LevelError::format(
            path,
            format!(
                "{} bytes, but a {width}x{height} map needs {expected} (2 bytes per texel): \
                 truncated, or the map size in world.ini disagrees with the file",
                bytes.len()
            ),
        ));
    }
    let n = w * height as usize;
    let mut heights = vec![0u8; n];
    let mut metas = vec![0u8; n];
    heights
        .par_chunks_mut(w)
        .zip(metas.par_chunks_mut(w))
        .zip(bytes.par_chunks(2 * w))
        .for_each(|((h, m), row)| {
            h.copy_from_slice(&row[..w]);
            m.copy_from_slice(&row[w..]);
        });
    Level::from_planes(width, height, heights, metas, mid_rule)
        .map_err(|e| LevelError::format(path, e.to_string()))
}

/// The `.vmp` bytes of a level.
pub fn encode_vmp(level: &Level) -> Vec<u8> {
    let w = level.width() as usize;
    let mut out = vec![0u8; 2 * level.heights().len()];
    out.par_chunks_mut(2 * w)
        .zip(level.heights().par_chunks(w))
        .zip(level.metas().par_chunks(w))
        .for_each(|((row, h), m)| {
            row[..w].copy_from_slice(h);
            row[w..].copy_from_slice(m);
        });
    out
}

/// Read and decode a `.vmp` of a `width x height` map (sizes from `world.ini`).
pub fn read_vmp(
    path: &Path,
    width: u32,
    height: u32,
    mid_rule: MidRule,
) -> Result<Level, LevelError> {
    let bytes = crate::error::read_file(path)?;
    decode_vmp(&bytes, width, height, mid_rule, path)
}

/// Write `level` as a `.vmp` (uncompressed rows).
pub fn write_vmp(path: &Path, level: &Level) -> Result<(), LevelError> {
    crate::error::write_file(path, &encode_vmp(level))
}
