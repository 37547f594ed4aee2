//! The store's layout: array names, the group attributes and the per-chunk
//! summary record.

use crate::error::StoreError;
use serde::{Deserialize, Serialize};
use std::path::Path;
use strata_level::World;
use strata_level::io::{WorldFiles, world_from_parts};
use strata_level::model::{Level, decode_column, pair_disagrees, pair_is_dual};

/// The format version this build writes and the newest it reads.
pub const FORMAT_VERSION: u32 = 1;
/// The attribute of the root group that holds [`WorldAttrs`].
pub const ATTR: &str = "strata";
/// The `lod` group's attribute that says how many levels are complete.
pub const LOD_ATTR: &str = "strata_lod";
/// The value of the `strata.format` attribute.
pub const FORMAT_NAME: &str = "strata-world";
/// The height plane (`uint8 [height, width]`).
pub const HEIGHTS: &str = "heights";
/// The meta plane (`uint8 [height, width]`).
pub const METAS: &str = "metas";
/// The per-chunk summaries (`uint32 [chunk rows, chunk columns, SUMMARY_FIELDS]`).
pub const SUMMARY: &str = "summary";
/// The `.vpr` bytes in the game's layout, when the world had one
/// (`uint8 [bytes]`; the generator state Strata does not model, kept so that
/// converting back writes the same file).
pub const VPR: &str = "vangers_vpr";

/// How a world is cut into chunks and compressed (chosen by measurement:
/// see the crate docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Layout {
    /// Chunk rows (a power of two; clamped to the map's height).
    pub chunk_height: u32,
    /// Chunk columns (a power of two, even: dual pairs never straddle a
    /// chunk; clamped to the map's width).
    pub chunk_width: u32,
    /// gzip level 0..=9 of each chunk.
    pub gzip_level: u32,
}

impl Default for Layout {
    /// The measured choice (crate docs): 256 x 256 chunks, gzip 6, no sharding.
    fn default() -> Self {
        Layout {
            chunk_height: 256,
            chunk_width: 256,
            gzip_level: 6,
        }
    }
}

impl Layout {
    /// The chunk (rows, columns) for a map: the layout's, clamped to the map.
    pub fn chunk_for(&self, width: u32, height: u32) -> (u32, u32) {
        (self.chunk_height.min(height), self.chunk_width.min(width))
    }
}

/// The text of the `strata.decoding` attribute: how to turn the two planes
/// into the two-interval sample without Strata (DESIGN §1).
pub const DECODING: &str = "Two uint8 planes, row-major [y, x]: heights and metas (a Vangers map's bytes). \
meta bits: 0x80 baked shadow (ignore), 0x40 DOUBLE_LEVEL, 0x38 terrain type (meta >> 3) & 7, \
0x04 object shadow (ignore), 0x03 two bits of the cave-gap code. Texels pair horizontally: \
even x = 2k, odd x = 2k+1. A pair is dual when both metas have 0x40. Dual pair: low = heights[even], \
high = heights[odd], code = ((metas[even] & 3) << 2) | (metas[odd] & 3), \
mid = min(low + ((code + 1) << 3), high) (the original game; vange-rs uses code << 3); \
floor terrain from the even texel, slab terrain from the odd; both texels of the pair decode to the \
same column, solid in [0, low] and [mid, high]. Single texel: low = mid = high = heights[x], solid in \
[0, low]. The map wraps in x and y. summary[cy, cx, :] = low_min, low_max, top_min, top_max, \
slab_bottom_min, slab_bottom_max (mid over dual texels; 255, 0 when none), dual_texels, \
pair_disagreements, of the chunk at chunk row cy, column cx.";

/// The group's `strata` attribute: everything of a world besides its planes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldAttrs {
    /// Always [`FORMAT_NAME`]: tells a Strata world from another Zarr group.
    pub format: String,
    /// The version the store was written in ([`FORMAT_VERSION`]).
    pub format_version: u32,
    /// Map width, texels (a power of two).
    pub width: u32,
    /// Map height, texels (a power of two).
    pub height: u32,
    /// Chunk shape `[rows, columns]` of the two planes.
    pub chunk: [u32; 2],
    /// The world's short name.
    pub name: String,
    /// `world.ini`, as text (map size, file names, colour ranges, …).
    pub world_ini: String,
    /// The palette as the `.pal` file's 768 bytes (6-bit RGB).
    pub palette: Vec<u8>,
    /// Water level per section (the `.vpr`'s), when the world has one.
    pub water: Option<Vec<i32>>,
    /// The world's views in `views.txt` form (empty: none).
    pub views: String,
    /// The edit fixture in `edit.txt` form.
    pub edit: Option<String>,
    /// How to decode the planes (see [`DECODING`]).
    pub decoding: String,
}

/// Fields per chunk in the summary array.
pub const SUMMARY_FIELDS: usize = 8;

/// Statistics of one chunk, kept in the summary array so that the coarse
/// pyramid and `info` never read a chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ChunkSummary {
    /// Lowest floor top (`low`).
    pub low_min: u8,
    /// Highest floor top.
    pub low_max: u8,
    /// Lowest solid top (`high` of dual texels, `low` of single ones).
    pub top_min: u8,
    /// Highest solid top: the chunk's entry in a max-height pyramid.
    pub top_max: u8,
    /// Lowest slab bottom (`mid`) of the chunk's dual texels; 255 when none.
    pub slab_bottom_min: u8,
    /// Highest slab bottom; 0 when none.
    pub slab_bottom_max: u8,
    /// Texels in dual pairs.
    pub dual_texels: u32,
    /// Pairs whose two texels disagree about the dual flag.
    pub pair_disagreements: u32,
}

impl ChunkSummary {
    /// The summary of a chunk of `cols x rows` texels, given its planes.
    pub fn of(
        heights: &[u8],
        metas: &[u8],
        cols: usize,
        level_rule: strata_level::MidRule,
    ) -> Self {
        let mut s = ChunkSummary {
            low_min: u8::MAX,
            low_max: 0,
            top_min: u8::MAX,
            top_max: 0,
            slab_bottom_min: u8::MAX,
            slab_bottom_max: 0,
            dual_texels: 0,
            pair_disagreements: 0,
        };
        for (hr, mr) in heights.chunks_exact(cols).zip(metas.chunks_exact(cols)) {
            for x in 0..cols {
                let c = decode_column(hr, mr, x, level_rule);
                s.low_min = s.low_min.min(c.low);
                s.low_max = s.low_max.max(c.low);
                s.top_min = s.top_min.min(c.top());
                s.top_max = s.top_max.max(c.top());
                if c.dual {
                    s.slab_bottom_min = s.slab_bottom_min.min(c.mid);
                    s.slab_bottom_max = s.slab_bottom_max.max(c.mid);
                }
            }
            for p in mr.chunks_exact(2) {
                if pair_is_dual(p[0], p[1]) {
                    s.dual_texels += 2;
                }
                s.pair_disagreements += u32::from(pair_disagrees(p[0], p[1]));
            }
        }
        s
    }

    /// The record as stored.
    pub fn to_fields(self) -> [u32; SUMMARY_FIELDS] {
        [
            self.low_min.into(),
            self.low_max.into(),
            self.top_min.into(),
            self.top_max.into(),
            self.slab_bottom_min.into(),
            self.slab_bottom_max.into(),
            self.dual_texels,
            self.pair_disagreements,
        ]
    }

    /// The record from its stored fields (`None` when a byte field is out of range).
    pub fn from_fields(f: &[u32]) -> Option<Self> {
        let b = |i: usize| u8::try_from(f[i]).ok();
        Some(ChunkSummary {
            low_min: b(0)?,
            low_max: b(1)?,
            top_min: b(2)?,
            top_max: b(3)?,
            slab_bottom_min: b(4)?,
            slab_bottom_max: b(5)?,
            dual_texels: f[6],
            pair_disagreements: f[7],
        })
    }
}

/// The planes of one chunk (row-major, `rows x cols`) cut from a level.
pub fn cut_chunk(level: &Level, y0: u32, x0: u32, rows: u32, cols: u32) -> (Vec<u8>, Vec<u8>) {
    let n = rows as usize * cols as usize;
    let (mut h, mut m) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for y in y0..y0 + rows {
        let (hr, mr) = level.row(y);
        h.extend_from_slice(&hr[x0 as usize..(x0 + cols) as usize]);
        m.extend_from_slice(&mr[x0 as usize..(x0 + cols) as usize]);
    }
    (h, m)
}

/// The world of a store's attributes with `level` as its map and `vpr`
/// (the `vangers_vpr` array's bytes, when read) as its `.vpr`; `what` names
/// the store in errors.
pub fn world_from_attrs(
    what: &str,
    a: &WorldAttrs,
    level: Level,
    vpr: Option<&[u8]>,
) -> Result<World, StoreError> {
    let path = Path::new(what);
    let config = strata_level::WorldConfig::parse_store_bytes(
        a.world_ini.as_bytes(),
        &path.join("zarr.json#strata.world_ini"),
    )?;
    if (config.width(), config.height()) != (a.width, a.height) {
        return Err(StoreError::NotAWorld {
            what: what.into(),
            msg: format!(
                "its world.ini says {}x{}, its arrays {}x{}",
                config.width(),
                config.height(),
                a.width,
                a.height
            ),
        });
    }
    let views = (!a.views.is_empty()).then_some(a.views.as_bytes());
    let mut world = world_from_parts(
        a.name.clone(),
        path,
        config,
        level,
        WorldFiles {
            palette: &a.palette,
            vpr,
            views,
            edit: a.edit.as_ref().map(|e| e.as_bytes()),
        },
    )?;
    if world.water.is_none() {
        world.water = a.water.clone();
    }
    Ok(world)
}
