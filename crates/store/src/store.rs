//! [`WorldStore`]: a Strata world in any Zarr storage (a directory, memory,
//! an object store): open and check it, read chunks and summaries, write a
//! whole world, read it back as a [`World`].

use crate::error::StoreError;
use crate::format::{
    ChunkSummary, DECODING, FORMAT_NAME, FORMAT_VERSION, HEIGHTS, Layout, METAS, SUMMARY,
    SUMMARY_FIELDS, VPR, WorldAttrs, cut_chunk,
};
#[cfg(not(target_arch = "wasm32"))]
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;
use strata_level::views::format_views;
use strata_level::{Level, MidRule, World, vpr};
use zarrs::array::codec::{Crc32cCodec, GzipCodec};
use zarrs::array::{Array, ArrayBuilder, CodecOptions, data_type};
use zarrs::group::{Group, GroupBuilder};
use zarrs::storage::ReadableWritableListableStorageTraits;

/// The storage a store lives in (zarrs' dynamic storage handle).
pub type Storage = Arc<dyn ReadableWritableListableStorageTraits>;
/// One of the store's arrays.
pub type StoreArray = Array<dyn ReadableWritableListableStorageTraits>;

/// Makes the chunk at grid row `cy`, column `cx` (for [`WorldStore::create_with`]).
pub type ChunkFn<'a> = dyn Fn(u64, u64) -> Result<Chunk, StoreError> + Sync + 'a;

pub use crate::format::{ATTR, world_from_attrs};

/// Summary records per side of one summary-array chunk.
const SUMMARY_CHUNK: u64 = 64;

/// The two planes of one chunk, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chunk {
    /// Chunk rows.
    pub rows: u32,
    /// Chunk columns.
    pub cols: u32,
    /// `rows * cols` height bytes.
    pub heights: Vec<u8>,
    /// `rows * cols` meta bytes.
    pub metas: Vec<u8>,
}

impl Chunk {
    /// Bytes the chunk holds in memory (its two planes).
    pub fn bytes(&self) -> usize {
        self.heights.len() + self.metas.len()
    }
}

/// Options every chunk is written with: every chunk is stored, also one of
/// the fill value, so that a missing chunk object is an error, never zeros.
pub(crate) fn write_options() -> CodecOptions {
    CodecOptions::default().with_store_empty_chunks(true)
}

/// A Strata world in Zarr storage.
pub struct WorldStore {
    storage: Storage,
    what: String,
    attrs: WorldAttrs,
    pub(crate) heights: StoreArray,
    pub(crate) metas: StoreArray,
    pub(crate) summary: StoreArray,
    /// Complete level-of-detail levels 1.. (`lod.rs`).
    pub(crate) lods: Vec<crate::lod::LodArrays>,
}

impl std::fmt::Debug for WorldStore {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorldStore")
            .field("what", &self.what)
            .field("width", &self.attrs.width)
            .field("height", &self.attrs.height)
            .field("chunk", &self.attrs.chunk)
            .finish()
    }
}

/// The array's metadata as JSON (stable across zarrs versions).
fn metadata_json(array: &StoreArray) -> serde_json::Value {
    serde_json::to_value(array.metadata()).unwrap_or_default()
}

/// Check an array's type, shape and chunk shape against what the world needs.
fn check_array(
    array: &StoreArray,
    name: &str,
    dtype: &str,
    shape: &[u64],
    chunk: &[u64],
) -> Result<(), StoreError> {
    let json = metadata_json(array);
    let found = json
        .get("data_type")
        .and_then(|d| {
            d.as_str()
                .or_else(|| d.get("name").and_then(|n| n.as_str()))
        })
        .unwrap_or("?");
    if found != dtype {
        return Err(StoreError::array(
            name,
            format!("data type {found}, expected {dtype}"),
        ));
    }
    if array.shape() != shape {
        return Err(StoreError::array(
            name,
            format!("shape {:?}, expected {shape:?}", array.shape()),
        ));
    }
    let grid = json
        .pointer("/chunk_grid/configuration/chunk_shape")
        .and_then(|s| serde_json::from_value::<Vec<u64>>(s.clone()).ok());
    if grid.as_deref() != Some(chunk) {
        return Err(StoreError::array(
            name,
            format!("chunk shape {grid:?}, expected {chunk:?} (a regular grid)"),
        ));
    }
    Ok(())
}

fn open_array(storage: &Storage, name: &str) -> Result<StoreArray, StoreError> {
    Array::open(storage.clone(), &format!("/{name}"))
        .map_err(|e| StoreError::array(name, format!("cannot be opened: {e}")))
}

fn build_array(
    storage: &Storage,
    name: &str,
    shape: Vec<u64>,
    chunk: Vec<u64>,
    u32_type: bool,
    layout: &Layout,
    dims: &[&str],
) -> Result<StoreArray, StoreError> {
    let err =
        |e: &dyn std::fmt::Display| StoreError::array(name, format!("cannot be created: {e}"));
    let gzip = GzipCodec::new(layout.gzip_level).map_err(|e| err(&e))?;
    let mut builder = if u32_type {
        ArrayBuilder::new(shape, chunk.clone(), data_type::uint32(), 0u32)
    } else {
        ArrayBuilder::new(shape, chunk.clone(), data_type::uint8(), 0u8)
    };
    builder
        .bytes_to_bytes_codecs(vec![Arc::new(gzip), Arc::new(Crc32cCodec::new())])
        .dimension_names(Some(dims.to_vec()));
    let array = builder
        .build(storage.clone(), &format!("/{name}"))
        .map_err(|e| err(&e))?;
    array.store_metadata().map_err(|e| err(&e))?;
    Ok(array)
}

impl WorldStore {
    /// Open the world in `storage`; `what` names it in errors (a path).
    /// Checks the format, version, arrays' types and shapes; reads no chunk.
    pub fn open(storage: Storage, what: &str) -> Result<Self, StoreError> {
        let not_world = |msg: String| StoreError::NotAWorld {
            what: what.into(),
            msg,
        };
        let group = Group::open(storage.clone(), "/")
            .map_err(|e| not_world(format!("not a readable Zarr group: {e}")))?;
        let raw = group.attributes().get(ATTR).ok_or_else(|| {
            not_world(format!(
                "a Zarr group without a `{ATTR}` attribute: not a Strata world"
            ))
        })?;
        let attrs = crate::http::check_attrs(what, raw)?;
        let (w, h) = (attrs.width, attrs.height);
        let [ch, cw] = attrs.chunk;
        let heights = open_array(&storage, HEIGHTS)?;
        let metas = open_array(&storage, METAS)?;
        let summary = open_array(&storage, SUMMARY)?;
        let shape = [u64::from(h), u64::from(w)];
        for (array, name) in [(&heights, HEIGHTS), (&metas, METAS)] {
            let chunk = [u64::from(ch), u64::from(cw)];
            check_array(array, name, "uint8", &shape, &chunk)?;
        }
        let (gy, gx) = grid_of(&attrs);
        let sshape = [gy, gx, SUMMARY_FIELDS as u64];
        let schunk = [
            gy.min(SUMMARY_CHUNK),
            gx.min(SUMMARY_CHUNK),
            SUMMARY_FIELDS as u64,
        ];
        check_array(&summary, SUMMARY, "uint32", &sshape, &schunk)?;
        let lods = crate::lod::open_levels(&storage, (w, h, (ch, cw)))?;
        Ok(WorldStore {
            storage,
            what: what.into(),
            attrs,
            heights,
            metas,
            summary,
            lods,
        })
    }

    /// Write `world` into empty `storage` with `layout`, every chunk and its
    /// summary (in parallel), and open it.
    pub fn create(
        storage: Storage,
        world: &World,
        layout: &Layout,
        what: &str,
    ) -> Result<Self, StoreError> {
        let level = &world.level;
        let (ch, cw) = layout.chunk_for(level.width(), level.height());
        let cut = |cy: u64, cx: u64| {
            let (heights, metas) = cut_chunk(level, cy as u32 * ch, cx as u32 * cw, ch, cw);
            Ok(Chunk {
                rows: ch,
                cols: cw,
                heights,
                metas,
            })
        };
        Self::create_with(
            storage,
            world,
            level.width(),
            level.height(),
            layout,
            what,
            &cut,
        )
    }

    /// Write a world chunk by chunk into empty `storage`: `chunk(cy, cx)`
    /// makes each chunk (called in parallel, each once), so a world larger
    /// than memory can be written. `world` gives everything but the planes
    /// (its level is not read; its config must give the map size).
    pub fn create_with(
        storage: Storage,
        world: &World,
        width: u32,
        height: u32,
        layout: &Layout,
        what: &str,
        chunk: &ChunkFn<'_>,
    ) -> Result<Self, StoreError> {
        let (w, h) = (width, height);
        let (ch, cw) = layout.chunk_for(w, h);
        if !ch.is_power_of_two()
            || !cw.is_power_of_two()
            || cw < 2
            || !w.is_power_of_two()
            || !h.is_power_of_two()
        {
            return Err(StoreError::Invalid(format!(
                "map {w}x{h}, chunk {cw}x{ch}: sides must be powers of two and the chunk width even"
            )));
        }
        let attrs = attrs_of(world, w, h, [ch, cw])?;
        let mut group = GroupBuilder::new()
            .build(storage.clone(), "/")
            .map_err(|e| StoreError::Invalid(format!("creating the root group: {e}")))?;
        group.attributes_mut().insert(
            ATTR.into(),
            serde_json::to_value(&attrs).expect("attributes serialise"),
        );
        let shape = vec![u64::from(h), u64::from(w)];
        let chunk_shape = vec![u64::from(ch), u64::from(cw)];
        let heights = build_array(
            &storage,
            HEIGHTS,
            shape.clone(),
            chunk_shape.clone(),
            false,
            layout,
            &["y", "x"],
        )?;
        let metas = build_array(
            &storage,
            METAS,
            shape,
            chunk_shape,
            false,
            layout,
            &["y", "x"],
        )?;
        let (gy, gx) = grid_of(&attrs);
        let summary = build_array(
            &storage,
            SUMMARY,
            vec![gy, gx, SUMMARY_FIELDS as u64],
            vec![
                gy.min(SUMMARY_CHUNK),
                gx.min(SUMMARY_CHUNK),
                SUMMARY_FIELDS as u64,
            ],
            true,
            layout,
            &["chunk_y", "chunk_x", "field"],
        )?;
        if let Some(water) = &world.water {
            let layout_vpr = vpr::VprLayout::of(&world.config);
            let bytes = vpr::vpr_bytes(
                water,
                &layout_vpr,
                world.source.vpr.as_deref(),
                Path::new("world.vpr"),
            )?;
            let n = bytes.len() as u64;
            let array = build_array(
                &storage,
                VPR,
                vec![n],
                vec![n.max(1)],
                false,
                layout,
                &["byte"],
            )?;
            array
                .store_chunk_opt(&[0], bytes, &write_options())
                .map_err(|e| StoreError::chunk(VPR, &[0], e))?;
        }
        let store = WorldStore {
            storage,
            what: what.into(),
            attrs,
            heights,
            metas,
            summary,
            lods: Vec::new(),
        };
        let cells: Vec<(u64, u64)> = (0..gy).flat_map(|y| (0..gx).map(move |x| (y, x))).collect();
        let summaries: Vec<ChunkSummary> = map_cells(&cells, &|&(cy, cx)| {
            let c = chunk(cy, cx)?;
            if (c.rows, c.cols) != (ch, cw) || c.bytes() != 2 * (ch * cw) as usize {
                return Err(StoreError::chunk(
                    HEIGHTS,
                    &[cy, cx],
                    "made with the wrong size",
                ));
            }
            store.write_chunk_into(&store.heights, &store.metas, cy, cx, &c)?;
            Ok(ChunkSummary::of(
                &c.heights,
                &c.metas,
                c.cols as usize,
                MidRule::Original,
            ))
        })?;
        store.write_summaries_into(&store.summary, &summaries, None)?;
        // The group last: a store with a root zarr.json is complete.
        group
            .store_metadata()
            .map_err(|e| StoreError::Invalid(format!("writing the root group: {e}")))?;
        Ok(store)
    }

    /// The store's name in errors (its path).
    pub fn what(&self) -> &str {
        &self.what
    }
    /// The storage it lives in.
    pub fn storage(&self) -> &Storage {
        &self.storage
    }
    /// Everything of the world besides the planes.
    pub fn attrs(&self) -> &WorldAttrs {
        &self.attrs
    }
    /// Map width, texels.
    pub fn width(&self) -> u32 {
        self.attrs.width
    }
    /// Map height, texels.
    pub fn height(&self) -> u32 {
        self.attrs.height
    }
    /// Chunk (rows, columns).
    pub fn chunk_shape(&self) -> (u32, u32) {
        (self.attrs.chunk[0], self.attrs.chunk[1])
    }
    /// Chunks (rows, columns) of the grid.
    pub fn grid(&self) -> (u64, u64) {
        grid_of(&self.attrs)
    }

    /// The chunk at grid row `cy`, column `cx`, cut from an in-memory level.
    pub fn chunk_of_level(&self, level: &Level, cy: u64, cx: u64) -> Chunk {
        let (ch, cw) = self.chunk_shape();
        let (heights, metas) = cut_chunk(level, cy as u32 * ch, cx as u32 * cw, ch, cw);
        Chunk {
            rows: ch,
            cols: cw,
            heights,
            metas,
        }
    }

    fn check_cell(&self, cy: u64, cx: u64) -> Result<(), StoreError> {
        let (gy, gx) = self.grid();
        if cy >= gy || cx >= gx {
            return Err(StoreError::chunk(
                HEIGHTS,
                &[cy, cx],
                format!("outside the {gy}x{gx} chunk grid"),
            ));
        }
        Ok(())
    }

    /// Read and decode one array's chunk (its checksum checked).
    fn read_plane(
        &self,
        array: &StoreArray,
        name: &str,
        cy: u64,
        cx: u64,
    ) -> Result<Vec<u8>, StoreError> {
        let (ch, cw) = self.chunk_shape();
        let expected = ch as usize * cw as usize;
        let bytes = read_cell(array, name, &[cy, cx])?;
        if bytes.len() != expected {
            return Err(StoreError::chunk(
                name,
                &[cy, cx],
                format!("{} bytes decoded, expected {expected}", bytes.len()),
            ));
        }
        Ok(bytes)
    }

    /// Read the chunk at grid row `cy`, column `cx`.
    pub fn read_chunk(&self, cy: u64, cx: u64) -> Result<Chunk, StoreError> {
        self.check_cell(cy, cx)?;
        let (ch, cw) = self.chunk_shape();
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights: self.read_plane(&self.heights, HEIGHTS, cy, cx)?,
            metas: self.read_plane(&self.metas, METAS, cy, cx)?,
        })
    }

    /// Encode and write one chunk into the given arrays (the store's own, or
    /// a journal's with the same metadata).
    pub(crate) fn write_chunk_into(
        &self,
        heights: &StoreArray,
        metas: &StoreArray,
        cy: u64,
        cx: u64,
        chunk: &Chunk,
    ) -> Result<(), StoreError> {
        self.check_cell(cy, cx)?;
        for (array, name, plane) in [
            (heights, HEIGHTS, &chunk.heights),
            (metas, METAS, &chunk.metas),
        ] {
            write_cell(array, name, &[cy, cx], plane)?;
        }
        Ok(())
    }

    /// Every chunk's summary, grid row-major, from the summary array alone.
    pub fn summaries(&self) -> Result<Vec<ChunkSummary>, StoreError> {
        let (gy, gx) = self.grid();
        let mut out = Vec::with_capacity((gy * gx) as usize);
        let raw = self.read_summary_fields()?;
        for (i, f) in raw.chunks_exact(SUMMARY_FIELDS).enumerate() {
            let s = ChunkSummary::from_fields(f).ok_or_else(|| {
                StoreError::chunk(
                    SUMMARY,
                    &[
                        i as u64 / gx / SUMMARY_CHUNK,
                        (i as u64 % gx) / SUMMARY_CHUNK,
                        0,
                    ],
                    format!(
                        "record of chunk ({}, {}) out of range: {f:?}",
                        i as u64 / gx,
                        i as u64 % gx
                    ),
                )
            })?;
            out.push(s);
        }
        Ok(out)
    }

    /// The summary array's u32 fields, `[gy, gx, SUMMARY_FIELDS]` row-major.
    pub(crate) fn read_summary_fields(&self) -> Result<Vec<u32>, StoreError> {
        let (gy, gx) = self.grid();
        let (sy, sx) = (gy.min(SUMMARY_CHUNK), gx.min(SUMMARY_CHUNK));
        let f = SUMMARY_FIELDS as u64;
        let mut out = vec![0u32; (gy * gx * f) as usize];
        for by in 0..gy.div_ceil(sy) {
            for bx in 0..gx.div_ceil(sx) {
                let idx = [by, bx, 0];
                let data: Vec<u32> = match self.summary.retrieve_chunk_if_exists::<Vec<u32>>(&idx) {
                    Ok(Some(d)) => d,
                    Ok(None) => return Err(StoreError::chunk(SUMMARY, &idx, "missing")),
                    Err(e) => return Err(StoreError::chunk(SUMMARY, &idx, e)),
                };
                for y in 0..sy {
                    for x in 0..sx {
                        let (gyi, gxi) = (by * sy + y, bx * sx + x);
                        if gyi >= gy || gxi >= gx {
                            continue;
                        }
                        let src = ((y * sx + x) * f) as usize;
                        let dst = ((gyi * gx + gxi) * f) as usize;
                        out[dst..dst + f as usize].copy_from_slice(&data[src..src + f as usize]);
                    }
                }
            }
        }
        Ok(out)
    }

    /// Write summaries into `array` (the store's, or a journal's). With
    /// `only`, just the summary chunks holding those grid cells; `all` is
    /// then the whole grid's records.
    pub(crate) fn write_summaries_into(
        &self,
        array: &StoreArray,
        all: &[ChunkSummary],
        only: Option<&[(u64, u64)]>,
    ) -> Result<Vec<[u64; 3]>, StoreError> {
        let (gy, gx) = self.grid();
        let (sy, sx) = (gy.min(SUMMARY_CHUNK), gx.min(SUMMARY_CHUNK));
        let f = SUMMARY_FIELDS;
        let mut blocks: Vec<(u64, u64)> = match only {
            Some(cells) => cells.iter().map(|&(y, x)| (y / sy, x / sx)).collect(),
            None => (0..gy.div_ceil(sy))
                .flat_map(|y| (0..gx.div_ceil(sx)).map(move |x| (y, x)))
                .collect(),
        };
        blocks.sort_unstable();
        blocks.dedup();
        for &(by, bx) in &blocks {
            let mut data = vec![0u32; (sy * sx) as usize * f];
            for y in 0..sy {
                for x in 0..sx {
                    let (gyi, gxi) = (by * sy + y, bx * sx + x);
                    if gyi >= gy || gxi >= gx {
                        continue;
                    }
                    let rec = all[(gyi * gx + gxi) as usize].to_fields();
                    let dst = (y * sx + x) as usize * f;
                    data[dst..dst + f].copy_from_slice(&rec);
                }
            }
            array
                .store_chunk_opt(&[by, bx, 0], data, &write_options())
                .map_err(|e| StoreError::chunk(SUMMARY, &[by, bx, 0], e))?;
        }
        Ok(blocks.into_iter().map(|(y, x)| [y, x, 0]).collect())
    }

    /// The whole map as an in-memory level (chunks read in parallel).
    pub fn read_level(&self, mid_rule: MidRule) -> Result<Level, StoreError> {
        let (w, h) = (self.width() as usize, self.height() as usize);
        let (ch, cw) = self.chunk_shape();
        let (gy, gx) = self.grid();
        let mut heights = vec![0u8; w * h];
        let mut metas = vec![0u8; w * h];
        let band = ch as usize * w;
        let fill = |(cy, (hb, mb)): (usize, (&mut [u8], &mut [u8]))| -> Result<(), StoreError> {
            for cx in 0..gx {
                let c = self.read_chunk(cy as u64, cx)?;
                let x0 = cx as usize * cw as usize;
                for r in 0..ch as usize {
                    let src = r * cw as usize..(r + 1) * cw as usize;
                    let dst = r * w + x0..r * w + x0 + cw as usize;
                    hb[dst.clone()].copy_from_slice(&c.heights[src.clone()]);
                    mb[dst].copy_from_slice(&c.metas[src]);
                }
            }
            Ok(())
        };
        // zarrs' storage is not Send/Sync on wasm32: one thread there.
        #[cfg(not(target_arch = "wasm32"))]
        heights
            .par_chunks_mut(band)
            .zip(metas.par_chunks_mut(band))
            .enumerate()
            .try_for_each(fill)?;
        #[cfg(target_arch = "wasm32")]
        heights
            .chunks_mut(band)
            .zip(metas.chunks_mut(band))
            .enumerate()
            .try_for_each(fill)?;
        debug_assert_eq!(gy as usize * ch as usize, h);
        Level::from_planes(w as u32, h as u32, heights, metas, mid_rule)
            .map_err(|e| StoreError::Invalid(e.to_string()))
    }

    /// The whole world in memory: the level, config, palette, water, views, edit.
    pub fn read_world(&self, mid_rule: MidRule) -> Result<World, StoreError> {
        self.world_with_level(self.read_level(mid_rule)?)
    }

    /// The world's config, palette, water, views and edit around `level`
    /// (this store's map, or a stand-in where the map is read through a
    /// [`crate::ChunkCache`] instead).
    pub fn world_with_level(&self, level: Level) -> Result<World, StoreError> {
        let vpr = match Array::open(self.storage.clone(), &format!("/{VPR}")) {
            Ok(array) => Some(read_cell(&array, VPR, &[0])?),
            Err(_) => None,
        };
        world_from_attrs(&self.what, &self.attrs, level, vpr.as_deref())
    }
}

/// The chunk grid (rows, columns) of a world's attributes.
fn grid_of(a: &WorldAttrs) -> (u64, u64) {
    (
        u64::from(a.height / a.chunk[0]),
        u64::from(a.width / a.chunk[1]),
    )
}

/// `f` over every grid cell: in parallel, except on wasm32, where zarrs'
/// storage is not Send/Sync.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) type CellFn<'a, T> = dyn Fn(&(u64, u64)) -> Result<T, StoreError> + Sync + 'a;

#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn map_cells<T: Send>(
    cells: &[(u64, u64)],
    f: &CellFn<'_, T>,
) -> Result<Vec<T>, StoreError> {
    cells.par_iter().map(f).collect()
}

#[cfg(target_arch = "wasm32")]
pub(crate) type CellFn<'a, T> = dyn Fn(&(u64, u64)) -> Result<T, StoreError> + 'a;

#[cfg(target_arch = "wasm32")]
pub(crate) fn map_cells<T>(cells: &[(u64, u64)], f: &CellFn<'_, T>) -> Result<Vec<T>, StoreError> {
    cells.iter().map(f).collect()
}

/// Read one chunk of an array: a missing object is an error, not zeros.
pub(crate) fn read_cell(
    array: &StoreArray,
    name: &str,
    cell: &[u64],
) -> Result<Vec<u8>, StoreError> {
    match array.retrieve_chunk_if_exists::<Vec<u8>>(cell) {
        Ok(Some(d)) => Ok(d),
        Ok(None) => Err(StoreError::chunk(name, cell, "missing (no chunk object)")),
        Err(e) => Err(StoreError::chunk(name, cell, e)),
    }
}

/// Encode and write one chunk of an array.
pub(crate) fn write_cell(
    array: &StoreArray,
    name: &str,
    cell: &[u64],
    data: &[u8],
) -> Result<(), StoreError> {
    array
        .store_chunk_opt(cell, data.to_vec(), &write_options())
        .map_err(|e| StoreError::chunk(name, cell, e))
}

/// The `strata` attribute of a world.
fn attrs_of(
    world: &World,
    width: u32,
    height: u32,
    chunk: [u32; 2],
) -> Result<WorldAttrs, StoreError> {
    let ini = world.config.to_ini_bytes();
    let world_ini = String::from_utf8(ini).map_err(|_| {
        StoreError::Invalid("world.ini is not UTF-8 text; a store keeps it as text".into())
    })?;
    Ok(WorldAttrs {
        format: FORMAT_NAME.into(),
        format_version: FORMAT_VERSION,
        width,
        height,
        chunk,
        name: world.name.clone(),
        world_ini,
        palette: world.palette.to_bytes(),
        water: world.water.clone(),
        views: if world.views.is_empty() {
            String::new()
        } else {
            format_views(&world.views)
        },
        edit: world.edit.as_ref().map(|e| e.format()),
        decoding: DECODING.into(),
    })
}
