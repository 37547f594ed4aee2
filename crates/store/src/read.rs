//! Reading a store in bounded memory: everything of the world but its map,
//! and the map's content hash streamed band by band (equal to
//! [`Level::content_hash`] of the same map loaded whole, so a reference
//! cached from a Vangers world serves its store and back).

use crate::error::StoreError;
use crate::format::{HEIGHTS, METAS};
use crate::store::{WorldStore, read_cell};
use sha2::{Digest, Sha256};
use strata_level::{Level, MidRule, World};

impl WorldStore {
    /// The world without its map: config, palette, water, views, edit, with
    /// a 2x1 stand-in level (read the map through a [`crate::ChunkCache`]).
    pub fn world_shell(&self) -> Result<World, StoreError> {
        let stand_in = Level::flat(2, 1, 0, 0).expect("2x1 is a valid map size");
        self.world_with_level(stand_in)
    }

    /// Bytes the map takes loaded whole (two planes).
    pub fn map_bytes(&self) -> u64 {
        2 * u64::from(self.width()) * u64::from(self.height())
    }

    /// [`Level::content_hash`] of the map, read one band of chunk rows at
    /// a time (each plane once: the hash takes every height, then every
    /// meta byte). Memory: one band of one plane (chunk rows x width).
    pub fn content_hash(&self, mid_rule: MidRule) -> Result<String, StoreError> {
        let mut hasher = Sha256::new();
        hasher.update(self.width().to_le_bytes());
        hasher.update(self.height().to_le_bytes());
        hasher.update([mid_rule as u8]);
        let (ch, cw) = self.chunk_shape();
        let (gy, gx) = self.grid();
        let w = self.width() as usize;
        let mut band = vec![0u8; ch as usize * w];
        for (array, name) in [(&self.heights, HEIGHTS), (&self.metas, METAS)] {
            for cy in 0..gy {
                for cx in 0..gx {
                    let bytes = read_cell(array, name, &[cy, cx])?;
                    if bytes.len() != (ch * cw) as usize {
                        return Err(StoreError::chunk(
                            name,
                            &[cy, cx],
                            format!("{} bytes decoded, expected {}", bytes.len(), ch * cw),
                        ));
                    }
                    let x0 = cx as usize * cw as usize;
                    for (r, row) in bytes.chunks_exact(cw as usize).enumerate() {
                        band[r * w + x0..r * w + x0 + cw as usize].copy_from_slice(row);
                    }
                }
                hasher.update(&band);
            }
        }
        Ok(hasher
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect())
    }
}
