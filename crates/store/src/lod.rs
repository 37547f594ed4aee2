//! Level-of-detail arrays (issue 33): `lod/{k}/heights` and `lod/{k}/metas`,
//! k = 1, 2, .., each the map at 1/2^k per side in the same planes and
//! chunk shape ([`strata_level::lod`] says how a coarse pair is chosen), so
//! a renderer can draw far terrain from a few coarse chunks instead of
//! thousands of fine ones. Level k is made from level k-1, a chunk from the
//! four below it, so building them reads each chunk of the map once.
//!
//! The `lod` group's attribute `strata_lod` (`{"levels": K}`) is written
//! last: a store whose build stopped part-way reads as having none. A store
//! without the group opens as before. They are built on demand
//! ([`crate::DirStore::build_lods`]); the paged renderer's level of detail
//! that reads them is not on `main` yet. Edit batches rewrite the coarse
//! chunks over the edited ones in the same all-or-nothing batch (`fs.rs`).
//!
//! They are written with gzip level 1: a 65536² world adds a third of its
//! texels, and level 6 would add a third of the generation's compression
//! time for 1-2 % fewer bytes.

use crate::error::StoreError;
use crate::format::{HEIGHTS, METAS};
use crate::store::{Chunk, Storage, StoreArray, WorldStore, read_cell, write_cell};
use std::collections::HashMap;
use std::sync::Arc;
use zarrs::array::codec::{Crc32cCodec, GzipCodec};
use zarrs::array::{Array, ArrayBuilder, data_type};
use zarrs::group::{Group, GroupBuilder};

/// The group holding the levels.
pub const LOD_GROUP: &str = "lod";
pub use crate::format::LOD_ATTR;
pub use strata_level::lod::MAX_LOD;
/// gzip level of the coarse chunks (see the module docs).
const LOD_GZIP: u32 = 1;

/// The array name of `plane` (`heights` or `metas`) at level `k`.
pub fn lod_name(k: u32, plane: &str) -> String {
    format!("{LOD_GROUP}/{k}/{plane}")
}

/// The two arrays of one level.
pub(crate) type LodArrays = (StoreArray, StoreArray);

/// Levels a world of `width` x `height` texels in `chunk` (rows, columns)
/// chunks can have ([`strata_level::lod::possible_levels`]).
pub fn possible_levels(width: u32, height: u32, chunk: (u32, u32)) -> u32 {
    strata_level::lod::possible_levels(width, height, chunk.1, chunk.0)
}

fn level_shape(store: &WorldStore, k: u32) -> (Vec<u64>, Vec<u64>) {
    let (ch, cw) = store.chunk_shape();
    (
        vec![
            u64::from(store.height() >> k),
            u64::from(store.width() >> k),
        ],
        vec![u64::from(ch), u64::from(cw)],
    )
}

/// Open the complete levels of the store in `storage` (none without the
/// group or its attribute).
pub(crate) fn open_levels(
    storage: &Storage,
    store_shape: (u32, u32, (u32, u32)),
) -> Result<Vec<LodArrays>, StoreError> {
    let Ok(group) = Group::open(storage.clone(), &format!("/{LOD_GROUP}")) else {
        return Ok(Vec::new());
    };
    let Some(levels) = group
        .attributes()
        .get(LOD_ATTR)
        .and_then(|a| a.get("levels"))
        .and_then(|l| l.as_u64())
    else {
        return Ok(Vec::new());
    };
    let (w, h, chunk) = store_shape;
    let most = possible_levels(w, h, chunk);
    if levels > u64::from(most) {
        return Err(StoreError::array(
            LOD_GROUP,
            format!("says {levels} levels; a {w}x{h} world has at most {most}"),
        ));
    }
    let mut out = Vec::new();
    for k in 1..=levels as u32 {
        let open = |plane: &str| {
            let name = lod_name(k, plane);
            let array = Array::open(storage.clone(), &format!("/{name}"))
                .map_err(|e| StoreError::array(&name, format!("cannot be opened: {e}")))?;
            let shape = [u64::from(h >> k), u64::from(w >> k)];
            if array.shape() != shape {
                return Err(StoreError::array(
                    &name,
                    format!("shape {:?}, expected {shape:?}", array.shape()),
                ));
            }
            Ok::<_, StoreError>(array)
        };
        out.push((open(HEIGHTS)?, open(METAS)?));
    }
    Ok(out)
}

impl WorldStore {
    /// Complete level-of-detail levels (0: none).
    pub fn lod_levels(&self) -> u32 {
        self.lods.len() as u32
    }

    /// Levels this world can have ([`possible_levels`]).
    pub fn possible_lod_levels(&self) -> u32 {
        possible_levels(self.width(), self.height(), self.chunk_shape())
    }

    /// The chunk at grid row `cy`, column `cx` of level `k` (0: the map),
    /// whose grid is the map's halved `k` times.
    pub fn read_lod_chunk(&self, k: u32, cy: u64, cx: u64) -> Result<Chunk, StoreError> {
        if k == 0 {
            return self.read_chunk(cy, cx);
        }
        let Some((heights, metas)) = self.lods.get(k as usize - 1) else {
            return Err(StoreError::Invalid(format!(
                "{}: level of detail {k} asked for; the store has {}",
                self.what(),
                self.lod_levels()
            )));
        };
        let (gy, gx) = self.grid();
        if cy >= gy >> k || cx >= gx >> k {
            return Err(StoreError::chunk(
                &lod_name(k, HEIGHTS),
                &[cy, cx],
                format!("outside the {}x{} chunk grid", gy >> k, gx >> k),
            ));
        }
        let (ch, cw) = self.chunk_shape();
        let n = ch as usize * cw as usize;
        let read = |array: &StoreArray, plane: &str| {
            let name = lod_name(k, plane);
            let bytes = read_cell(array, &name, &[cy, cx])?;
            if bytes.len() != n {
                return Err(StoreError::chunk(
                    &name,
                    &[cy, cx],
                    format!("{} bytes decoded, expected {n}", bytes.len()),
                ));
            }
            Ok(bytes)
        };
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights: read(heights, HEIGHTS)?,
            metas: read(metas, METAS)?,
        })
    }

    /// Level `k`'s chunk (`cy`, `cx`) from the four of level `k - 1` below
    /// it, each taken from `fresh` when there, else read.
    fn merge_below(
        &self,
        k: u32,
        cy: u64,
        cx: u64,
        fresh: &HashMap<(u64, u64), Arc<Chunk>>,
    ) -> Result<Chunk, StoreError> {
        let (ch, cw) = self.chunk_shape();
        let mut quad = Vec::with_capacity(4);
        for (dy, dx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let cell = (2 * cy + dy, 2 * cx + dx);
            quad.push(match fresh.get(&cell) {
                Some(c) => c.clone(),
                None => Arc::new(self.read_lod_chunk(k - 1, cell.0, cell.1)?),
            });
        }
        assert_eq!(ch, cw, "level-of-detail chunks are square");
        let (heights, metas) = strata_level::lod::merge_quad(
            [0, 1, 2, 3].map(|i| (quad[i].heights.as_slice(), quad[i].metas.as_slice())),
            cw as usize,
        );
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights,
            metas,
        })
    }

    /// Write every level this world can have (replacing any), level by
    /// level, each chunk from the four below it (in parallel), then the
    /// group attribute that makes them count. `progress(k, levels)` after
    /// each level.
    pub fn build_lods(&mut self, progress: &dyn Fn(u32, u32)) -> Result<u32, StoreError> {
        let levels = if self.chunk_shape().0 == self.chunk_shape().1 {
            self.possible_lod_levels()
        } else {
            0
        };
        self.lods.clear();
        if levels == 0 {
            return Ok(0);
        }
        let storage = self.storage().clone();
        let err = |e: &dyn std::fmt::Display| {
            StoreError::array(LOD_GROUP, format!("cannot be written: {e}"))
        };
        let mut group = GroupBuilder::new()
            .build(storage.clone(), &format!("/{LOD_GROUP}"))
            .map_err(|e| err(&e))?;
        group.store_metadata().map_err(|e| err(&e))?;
        let none = HashMap::new();
        for k in 1..=levels {
            let level_group = GroupBuilder::new()
                .build(storage.clone(), &format!("/{LOD_GROUP}/{k}"))
                .map_err(|e| err(&e))?;
            level_group.store_metadata().map_err(|e| err(&e))?;
            let (shape, chunk) = level_shape(self, k);
            let make = |plane: &str| -> Result<StoreArray, StoreError> {
                let name = lod_name(k, plane);
                let gzip = GzipCodec::new(LOD_GZIP).map_err(|e| StoreError::array(&name, e))?;
                let mut builder =
                    ArrayBuilder::new(shape.clone(), chunk.clone(), data_type::uint8(), 0u8);
                builder
                    .bytes_to_bytes_codecs(vec![Arc::new(gzip), Arc::new(Crc32cCodec::new())])
                    .dimension_names(Some(vec!["y", "x"]));
                let array = builder
                    .build(storage.clone(), &format!("/{name}"))
                    .map_err(|e| StoreError::array(&name, e))?;
                array
                    .store_metadata()
                    .map_err(|e| StoreError::array(&name, e))?;
                Ok(array)
            };
            let arrays = (make(HEIGHTS)?, make(METAS)?);
            let (gy, gx) = self.grid();
            let cells: Vec<(u64, u64)> = (0..gy >> k)
                .flat_map(|y| (0..gx >> k).map(move |x| (y, x)))
                .collect();
            crate::store::map_cells(&cells, &|&(cy, cx)| {
                let c = self.merge_below(k, cy, cx, &none)?;
                write_cell(&arrays.0, &lod_name(k, HEIGHTS), &[cy, cx], &c.heights)?;
                write_cell(&arrays.1, &lod_name(k, METAS), &[cy, cx], &c.metas)
            })?;
            self.lods.push(arrays);
            progress(k, levels);
        }
        group
            .attributes_mut()
            .insert(LOD_ATTR.into(), serde_json::json!({ "levels": levels }));
        group.store_metadata().map_err(|e| err(&e))?;
        Ok(levels)
    }

    /// The coarse chunks that change when the map's chunks `changed` are
    /// replaced: `(k, cy, cx, chunk)` for every level, the merge of the new
    /// chunks and the stored ones beside them.
    #[cfg_attr(not(feature = "fs"), allow(dead_code))]
    pub(crate) fn lod_updates(
        &self,
        changed: &[(u64, u64, Chunk)],
    ) -> Result<Vec<(u32, u64, u64, Chunk)>, StoreError> {
        let mut out = Vec::new();
        let mut fresh: HashMap<(u64, u64), Arc<Chunk>> = changed
            .iter()
            .map(|(y, x, c)| ((*y, *x), Arc::new(c.clone())))
            .collect();
        for k in 1..=self.lod_levels() {
            let mut cells: Vec<(u64, u64)> = fresh.keys().map(|&(y, x)| (y / 2, x / 2)).collect();
            cells.sort_unstable();
            cells.dedup();
            let mut next = HashMap::new();
            for (cy, cx) in cells {
                let c = self.merge_below(k, cy, cx, &fresh)?;
                next.insert((cy, cx), Arc::new(c.clone()));
                out.push((k, cy, cx, c));
            }
            fresh = next;
        }
        Ok(out)
    }

    /// The arrays of level `k` (1-based).
    #[cfg_attr(not(feature = "fs"), allow(dead_code))]
    pub(crate) fn lod_arrays(&self, k: u32) -> &LodArrays {
        &self.lods[k as usize - 1]
    }
}
