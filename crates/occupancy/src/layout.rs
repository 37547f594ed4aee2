//! Where every occupancy bit lives. The CPU build, the GPU build shaders and
//! the GPU traversal all index the one `u32` buffer through these rules:
//!
//! - level 0 has one bit per voxel of `(x, y, z)` texels; altitudes 0..256
//!   give `256 / z` voxels vertically;
//! - level `L + 1` has one bit per 2x2x2 block of level `L` (their OR), with
//!   each dimension `ceil(d / 2)`, until every dimension is at most 8;
//! - a level is a grid of 8x8x8 tiles (16 words each), ordered z fastest,
//!   then x, then y: `tile = (ty * tiles_x + tx) * tiles_z + tz`, so a tile
//!   column (all z of one `(tx, ty)`) is one contiguous run of words;
//! - inside a tile, the bit of local `(x, y, z)` is the 9-bit Morton code
//!   `x0 y0 z0 x1 y1 z1 x2 y2 z2` (x in the lowest bit): word `m >> 5`, bit `m & 31`.
//!
//! With Morton order a 2x2x2 block is one aligned byte, and the 64 bytes of a
//! tile map onto one 4x4x4 octant of its parent tile: reduction is "byte != 0".

use strata_level::DirtyRect;

/// Bits per tile side.
pub const TILE: u32 = 8;
/// `u32` words per 8x8x8 tile.
pub const TILE_WORDS: u32 = 16;
/// Altitudes span 0..256.
pub const ALTITUDES: u32 = 256;
/// `u32` words per level in [`Layout::level_table`].
pub const LEVEL_TABLE_STRIDE: usize = 8;

/// Spread the low 3 bits of `v` to bits 0, 3, 6.
#[inline]
fn spread3(v: u32) -> u32 {
    (v & 1) | ((v & 2) << 2) | ((v & 4) << 4)
}

/// Gather bits 0, 3, 6 of `m` into the low 3 bits.
#[inline]
fn gather3(m: u32) -> u32 {
    (m & 1) | ((m >> 2) & 2) | ((m >> 4) & 4)
}

/// Morton code of a local position inside a tile (each coordinate 0..8).
#[inline]
pub fn morton_encode(x: u32, y: u32, z: u32) -> u32 {
    spread3(x) | (spread3(y) << 1) | (spread3(z) << 2)
}

/// Inverse of [`morton_encode`] for codes 0..512.
#[inline]
pub fn morton_decode(m: u32) -> (u32, u32, u32) {
    (gather3(m), gather3(m >> 1), gather3(m >> 2))
}

/// Size of a level-0 voxel in texels (x, y) and altitude units (z).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VoxelSize {
    /// Texels across; a power of two, at least 2 (a dual pair stays in one voxel).
    pub x: u32,
    /// Texels down; a power of two.
    pub y: u32,
    /// Altitude units; a power of two, at most 256.
    pub z: u32,
}

impl VoxelSize {
    /// The paper's publication grid.
    pub const COARSE: VoxelSize = VoxelSize { x: 4, y: 8, z: 2 };
    /// The paper's shipping grid (about 146 MiB on Fostral).
    pub const FINE: VoxelSize = VoxelSize { x: 2, y: 4, z: 1 };
}

impl Default for VoxelSize {
    fn default() -> Self {
        Self::COARSE
    }
}

impl std::fmt::Display for VoxelSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{}", self.x, self.y, self.z)
    }
}

impl std::str::FromStr for VoxelSize {
    type Err = LayoutError;
    /// Parses `X,Y,Z`, e.g. `4,8,2`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let parts: Vec<_> = s.split(',').map(|p| p.trim().parse::<u32>()).collect();
        match parts.as_slice() {
            [Ok(x), Ok(y), Ok(z)] => Ok(VoxelSize {
                x: *x,
                y: *y,
                z: *z,
            }),
            _ => Err(LayoutError::Parse(s.to_string())),
        }
    }
}

/// Why a voxel size, map or dirty rectangle cannot be laid out.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum LayoutError {
    /// [`VoxelSize`]'s `from_str` got text other than `X,Y,Z` (the text).
    #[error("voxel size `{0}` is not three comma-separated integers like `4,8,2`")]
    Parse(String),
    /// The voxel size is not powers of two, has x below 2, or is larger than
    /// the map (or 256 altitudes).
    #[error(
        "voxel size {size} must be powers of two, x at least 2 (a dual pair must not straddle voxels), \
         at most the map ({width}x{height}) and z at most 256"
    )]
    BadSize {
        /// The voxel size asked for.
        size: VoxelSize,
        /// Map width, texels.
        width: u32,
        /// Map height, texels.
        height: u32,
    },
    /// The map's sides are not powers of two, or (from [`crate::Pyramid::update`])
    /// the level is not the size the pyramid was built for.
    #[error("map {width}x{height} is not a power of two in each direction")]
    BadMap {
        /// Map width, texels.
        width: u32,
        /// Map height, texels.
        height: u32,
    },
    /// The pyramid would need 2^32 words or more.
    #[error("occupancy pyramid of {bytes} bytes is too large to index with 32-bit words")]
    TooLarge {
        /// Bytes it would take.
        bytes: u64,
    },
    /// A dirty rectangle is empty or reaches past the map's edge.
    #[error("dirty rectangle {rect:?} is empty or outside the {width}x{height} map")]
    BadRect {
        /// The rectangle given.
        rect: DirtyRect,
        /// Map width, texels.
        width: u32,
        /// Map height, texels.
        height: u32,
    },
}

/// One level of the pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    /// Cells in x, y, z.
    pub dims: [u32; 3],
    /// Tiles in x, y, z (`ceil(dims / 8)`).
    pub tiles: [u32; 3],
    /// First word of the level in the buffer.
    pub offset: u32,
    /// Cell size at this level: texels in x, y and altitude units in z.
    pub cell: [u32; 3],
}

impl LevelInfo {
    /// Words of the whole level.
    pub fn words(&self) -> u32 {
        self.tiles[0] * self.tiles[1] * self.tiles[2] * TILE_WORDS
    }
    /// Words of one tile column (all z tiles of one `(tx, ty)`).
    pub fn column_words(&self) -> u32 {
        self.tiles[2] * TILE_WORDS
    }
    /// Word and bit of cell `(x, y, z)` (inside `dims`).
    #[inline]
    pub fn locate(&self, x: u32, y: u32, z: u32) -> (u32, u32) {
        let tile = ((y >> 3) * self.tiles[0] + (x >> 3)) * self.tiles[2] + (z >> 3);
        let m = morton_encode(x & 7, y & 7, z & 7);
        (self.offset + tile * TILE_WORDS + (m >> 5), m & 31)
    }
}

/// An inclusive rectangle of tile columns of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRange {
    /// First tile column in x.
    pub x0: u32,
    /// First tile column in y.
    pub y0: u32,
    /// Last tile column in x (inclusive).
    pub x1: u32,
    /// Last tile column in y (inclusive).
    pub y1: u32,
}

impl TileRange {
    /// The parent-level tile columns covering these ones.
    pub fn parent(&self) -> TileRange {
        TileRange {
            x0: self.x0 >> 1,
            y0: self.y0 >> 1,
            x1: self.x1 >> 1,
            y1: self.y1 >> 1,
        }
    }
    /// Number of tile columns in the range.
    pub fn columns(&self) -> u32 {
        (self.x1 - self.x0 + 1) * (self.y1 - self.y0 + 1)
    }
}

/// The whole pyramid's shape for one map size and voxel size.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Level 0's voxel size.
    pub voxel: VoxelSize,
    /// Map width, texels (a power of two).
    pub map_width: u32,
    /// Map height, texels (a power of two).
    pub map_height: u32,
    /// Level 0 (finest) first; the last has every dimension at most 8.
    pub levels: Vec<LevelInfo>,
    /// Words of the whole buffer.
    pub total_words: u32,
}

impl Layout {
    /// The levels for a map and voxel size. Errors: [`LayoutError::BadMap`],
    /// [`LayoutError::BadSize`], [`LayoutError::TooLarge`].
    pub fn new(map_width: u32, map_height: u32, voxel: VoxelSize) -> Result<Layout, LayoutError> {
        if !map_width.is_power_of_two() || !map_height.is_power_of_two() {
            return Err(LayoutError::BadMap {
                width: map_width,
                height: map_height,
            });
        }
        let pow2 = |v: u32| v.is_power_of_two();
        if !(pow2(voxel.x) && pow2(voxel.y) && pow2(voxel.z))
            || voxel.x < 2
            || voxel.x > map_width
            || voxel.y > map_height
            || voxel.z > ALTITUDES
        {
            return Err(LayoutError::BadSize {
                size: voxel,
                width: map_width,
                height: map_height,
            });
        }
        let mut dims = [
            map_width / voxel.x,
            map_height / voxel.y,
            ALTITUDES / voxel.z,
        ];
        let mut cell = [voxel.x, voxel.y, voxel.z];
        let mut levels = Vec::new();
        let mut offset: u64 = 0;
        loop {
            let tiles = dims.map(|d| d.div_ceil(TILE));
            let info = LevelInfo {
                dims,
                tiles,
                offset: offset as u32,
                cell,
            };
            offset += u64::from(tiles[0])
                * u64::from(tiles[1])
                * u64::from(tiles[2])
                * u64::from(TILE_WORDS);
            if offset > u64::from(u32::MAX) {
                return Err(LayoutError::TooLarge { bytes: offset * 4 });
            }
            levels.push(info);
            if dims.iter().all(|&d| d <= TILE) {
                break;
            }
            dims = dims.map(|d| d.div_ceil(2));
            cell = cell.map(|c| c * 2);
        }
        Ok(Layout {
            voxel,
            map_width,
            map_height,
            levels,
            total_words: offset as u32,
        })
    }

    /// Bytes of the whole buffer.
    pub fn bytes(&self) -> u64 {
        u64::from(self.total_words) * 4
    }

    /// Index of the coarsest level in `levels`.
    pub fn coarsest(&self) -> usize {
        self.levels.len() - 1
    }

    /// The level table as the GPU reads it: per level `dims.xyz, offset,
    /// tiles.xyz, 0` ([`LEVEL_TABLE_STRIDE`] words).
    pub fn level_table(&self) -> Vec<u32> {
        let mut t = Vec::with_capacity(self.levels.len() * LEVEL_TABLE_STRIDE);
        for l in &self.levels {
            t.extend_from_slice(&[
                l.dims[0], l.dims[1], l.dims[2], l.offset, l.tiles[0], l.tiles[1], l.tiles[2], 0,
            ]);
        }
        t
    }

    /// Level-0 tile columns whose voxels a change inside `rect` can affect.
    /// The rectangle is widened to whole dual pairs first: an edit of one
    /// texel of a pair changes the decoded column of both.
    pub fn dirty_tiles(&self, rect: &DirtyRect) -> Result<TileRange, LayoutError> {
        let bad = || LayoutError::BadRect {
            rect: *rect,
            width: self.map_width,
            height: self.map_height,
        };
        let x_end = rect.x.checked_add(rect.width).ok_or_else(bad)?;
        let y_end = rect.y.checked_add(rect.height).ok_or_else(bad)?;
        if rect.width == 0 || rect.height == 0 || x_end > self.map_width || y_end > self.map_height
        {
            return Err(bad());
        }
        let x0 = rect.x & !1;
        let x1 = (x_end - 1) | 1;
        let tx = self.voxel.x * TILE;
        let ty = self.voxel.y * TILE;
        Ok(TileRange {
            x0: x0 / tx,
            y0: rect.y / ty,
            x1: x1 / tx,
            y1: (y_end - 1) / ty,
        })
    }

    /// Every tile column of a level.
    pub fn all_tiles(&self, level: usize) -> TileRange {
        let l = &self.levels[level];
        TileRange {
            x0: 0,
            y0: 0,
            x1: l.tiles[0] - 1,
            y1: l.tiles[1] - 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MIB: f64 = 1024.0 * 1024.0;

    #[test]
    fn morton_round_trip() {
        let mut seen = [false; 512];
        for x in 0..8 {
            for y in 0..8 {
                for z in 0..8 {
                    let m = morton_encode(x, y, z);
                    assert!(m < 512 && !seen[m as usize]);
                    seen[m as usize] = true;
                    assert_eq!(morton_decode(m), (x, y, z));
                }
            }
        }
        // A 2x2x2 block is one aligned byte.
        assert_eq!(morton_encode(1, 1, 1), 7);
        assert_eq!(morton_encode(2, 0, 0), 8);
    }

    #[test]
    fn fostral_sizes() {
        let coarse = Layout::new(2048, 16384, VoxelSize::COARSE).unwrap();
        let mib = coarse.bytes() as f64 / MIB;
        assert!((mib - 18.29).abs() < 0.05, "coarse {mib} MiB");
        assert_eq!(coarse.levels[0].dims, [512, 2048, 128]);
        assert!(coarse.levels.last().unwrap().dims.iter().all(|&d| d <= 8));
        let fine = Layout::new(2048, 16384, VoxelSize::FINE).unwrap();
        let mib = fine.bytes() as f64 / MIB;
        assert!((mib - 146.3).abs() < 0.5, "fine {mib} MiB");
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert!(Layout::new(64, 64, VoxelSize { x: 3, y: 8, z: 2 }).is_err());
        assert!(Layout::new(64, 64, VoxelSize { x: 1, y: 8, z: 2 }).is_err());
        assert!(Layout::new(64, 64, VoxelSize { x: 4, y: 128, z: 2 }).is_err());
        assert!(Layout::new(64, 64, VoxelSize { x: 4, y: 8, z: 512 }).is_err());
        assert!(Layout::new(48, 64, VoxelSize::COARSE).is_err());
        assert!("4,8".parse::<VoxelSize>().is_err());
        assert_eq!("2, 4,1".parse::<VoxelSize>().unwrap(), VoxelSize::FINE);
    }

    #[test]
    fn dirty_tiles_widen_to_pairs_and_reject_bad_rects() {
        let l = Layout::new(256, 256, VoxelSize::COARSE).unwrap();
        // Tile columns are 32 x 64 texels; texel 31 is the odd half of pair 30-31.
        let r = l
            .dirty_tiles(&DirtyRect {
                x: 32,
                y: 63,
                width: 1,
                height: 2,
            })
            .unwrap();
        assert_eq!((r.x0, r.y0, r.x1, r.y1), (1, 0, 1, 1));
        let rect = DirtyRect {
            x: 250,
            y: 0,
            width: 10,
            height: 1,
        };
        assert!(l.dirty_tiles(&rect).is_err());
        let empty = DirtyRect {
            x: 0,
            y: 0,
            width: 0,
            height: 1,
        };
        assert!(l.dirty_tiles(&empty).is_err());
    }
}
