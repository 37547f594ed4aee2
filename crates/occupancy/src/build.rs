//! The CPU build of the pyramid: the twin the GPU build is tested against,
//! bit for bit. Both work one tile column at a time and overwrite every word
//! of it, so an incremental update needs no clearing.

use rayon::prelude::*;
use strata_level::{Column, DirtyRect, Level};

use crate::layout::{
    ALTITUDES, Layout, LayoutError, LevelInfo, TILE, TILE_WORDS, TileRange, VoxelSize,
    morton_decode,
};

/// Voxel-z occupancy of one voxel column: up to 256 bits.
type ZMask = [u64; 4];

/// Set bits `lo..=hi` of a z mask.
fn set_range(mask: &mut ZMask, lo: u32, hi: u32) {
    for (i, word) in mask.iter_mut().enumerate() {
        let base = i as u32 * 64;
        if hi < base || lo >= base + 64 {
            continue;
        }
        let a = lo.saturating_sub(base);
        let b = (hi - base).min(63);
        let bits = if b - a == 63 {
            u64::MAX
        } else {
            ((1u64 << (b - a + 1)) - 1) << a
        };
        *word |= bits;
    }
}

/// The voxel rows `vz` whose altitude range `[vz z, (vz + 1) z]` (closed, so
/// a solid point on a voxel face counts for both voxels) meets a solid
/// interval of `c`. This rule is the one the WGSL build mirrors.
pub fn column_voxel_ranges(c: &Column, z: u32) -> [(u32, u32); 2] {
    // Floor [0, low]: every voxel starting at or below `low`.
    let floor = (0, u32::from(c.low) / z);
    let slab = if c.dual {
        let mid = u32::from(c.mid);
        // vz z + z >= mid  <=>  vz >= ceil(mid / z) - 1
        let lo = mid.div_ceil(z).saturating_sub(1);
        (lo, u32::from(c.high) / z)
    } else {
        floor
    };
    [floor, slab]
}

/// The z mask of level-0 voxel column `(vx, vy)`.
fn voxel_column_mask(level: &Level, voxel: VoxelSize, vx: u32, vy: u32) -> ZMask {
    let mut mask = [0u64; 4];
    for y in vy * voxel.y..(vy + 1) * voxel.y {
        for x in vx * voxel.x..(vx + 1) * voxel.x {
            let c = level.column(i64::from(x), i64::from(y));
            for (lo, hi) in column_voxel_ranges(&c, voxel.z) {
                set_range(&mut mask, lo, hi);
            }
        }
    }
    mask
}

/// Write level-0 tile column `(tx, ty)` into `out` (`column_words` words).
fn build_leaf_column(level: &Level, layout: &Layout, tx: u32, ty: u32, out: &mut [u32]) {
    let info = &layout.levels[0];
    let mut masks = [[0u64; 4]; 64];
    for ly in 0..TILE {
        for lx in 0..TILE {
            let (vx, vy) = (tx * TILE + lx, ty * TILE + ly);
            if vx < info.dims[0] && vy < info.dims[1] {
                masks[(ly * TILE + lx) as usize] = voxel_column_mask(level, layout.voxel, vx, vy);
            }
        }
    }
    for (w, word) in out.iter_mut().enumerate() {
        let tz = w as u32 / TILE_WORDS;
        let wi = w as u32 % TILE_WORDS;
        let mut bits = 0u32;
        for b in 0..32 {
            let (lx, ly, lz) = morton_decode(wi * 32 + b);
            let vz = tz * TILE + lz;
            let m = &masks[(ly * TILE + lx) as usize];
            // Voxels above the grid (vz >= dims z) stay zero: masks never set them.
            if vz < 256 && (m[(vz / 64) as usize] >> (vz % 64)) & 1 != 0 {
                bits |= 1 << b;
            }
        }
        *word = bits;
    }
}

/// Word `w` (0..16) of a parent tile from its child level: the parent tile's
/// octant `w >> 1` is one whole child tile, and each of that child tile's 64
/// bytes (a 2x2x2 block) becomes one parent bit.
fn reduce_word(child: &[u32], child_info: &LevelInfo, ptile: [u32; 3], w: u32) -> u32 {
    let oct = w >> 1;
    let half = w & 1;
    let c = [
        ptile[0] * 2 + (oct & 1),
        ptile[1] * 2 + ((oct >> 1) & 1),
        ptile[2] * 2 + (oct >> 2),
    ];
    if (0..3).any(|i| c[i] >= child_info.tiles[i]) {
        return 0;
    }
    let tile = (c[1] * child_info.tiles[0] + c[0]) * child_info.tiles[2] + c[2];
    let base = (tile * TILE_WORDS + half * 8) as usize;
    let mut bits = 0u32;
    for k in 0..8 {
        let cw = child[base + k];
        for byte in 0..4 {
            if (cw >> (byte * 8)) & 0xff != 0 {
                bits |= 1 << (k as u32 * 4 + byte);
            }
        }
    }
    bits
}

/// The occupancy pyramid, on the CPU.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pyramid {
    /// The shape: levels, tiles and offsets.
    pub layout: Layout,
    /// The bits, `layout.total_words` words laid out by [`Layout`]; public for
    /// the GPU upload and the bit-for-bit tests.
    pub words: Vec<u32>,
}

/// What an update rebuilt.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UpdateStats {
    /// Level-0 tile columns rebuilt.
    pub leaf_columns: u32,
    /// Tile columns re-reduced on coarser levels.
    pub reduced_columns: u32,
}

impl Pyramid {
    /// Build the whole pyramid from a level. Errors: [`LayoutError::BadMap`]
    /// for a side that is not a power of two, [`LayoutError::BadSize`] for a
    /// voxel size the map cannot hold, [`LayoutError::TooLarge`] past 2^32 words.
    pub fn build(level: &Level, voxel: VoxelSize) -> Result<Pyramid, LayoutError> {
        let layout = Layout::new(level.width(), level.height(), voxel)?;
        let mut p = Pyramid {
            words: vec![0; layout.total_words as usize],
            layout,
        };
        let ranges: Vec<TileRange> = (0..p.layout.levels.len())
            .map(|l| p.layout.all_tiles(l))
            .collect();
        p.rebuild(level, &ranges);
        Ok(p)
    }

    /// Bring the pyramid up to date after edits inside `rects`: rebuild the
    /// level-0 tile columns they touch, then every ancestor tile column.
    /// `level` must already hold the edits. Errors: [`LayoutError::BadMap`]
    /// when `level` is not the size the pyramid was built for,
    /// [`LayoutError::BadRect`] for an empty rectangle or one reaching past
    /// the map (dirty rectangles do not wrap).
    pub fn update(
        &mut self,
        level: &Level,
        rects: &[DirtyRect],
    ) -> Result<UpdateStats, LayoutError> {
        if level.width() != self.layout.map_width || level.height() != self.layout.map_height {
            return Err(LayoutError::BadMap {
                width: level.width(),
                height: level.height(),
            });
        }
        let mut stats = UpdateStats::default();
        for rect in rects {
            let mut r = self.layout.dirty_tiles(rect)?;
            let mut chain = Vec::with_capacity(self.layout.levels.len());
            for l in 0..self.layout.levels.len() {
                if l == 0 {
                    stats.leaf_columns += r.columns();
                } else {
                    stats.reduced_columns += r.columns();
                }
                chain.push(r);
                r = r.parent();
            }
            self.rebuild(level, &chain);
        }
        Ok(stats)
    }

    /// Rebuild `ranges[l]` of each level `l`, finest first.
    fn rebuild(&mut self, level: &Level, ranges: &[TileRange]) {
        for (l, r) in ranges.iter().enumerate() {
            let info = self.layout.levels[l];
            let cw = info.column_words() as usize;
            let (below, here) = self.words.split_at_mut(info.offset as usize);
            let here = &mut here[..info.words() as usize];
            // Tile rows are contiguous runs of tile columns: rebuild row by row in parallel.
            let row_words = cw * info.tiles[0] as usize;
            let layout = &self.layout;
            let child = if l > 0 {
                let ci = layout.levels[l - 1];
                Some((
                    &below[ci.offset as usize..(ci.offset + ci.words()) as usize],
                    ci,
                ))
            } else {
                None
            };
            here.par_chunks_mut(row_words)
                .enumerate()
                .filter(|(ty, _)| (r.y0..=r.y1).contains(&(*ty as u32)))
                .for_each(|(ty, row)| {
                    let ty = ty as u32;
                    for tx in r.x0..=r.x1 {
                        let out = &mut row[tx as usize * cw..(tx as usize + 1) * cw];
                        match child {
                            None => build_leaf_column(level, layout, tx, ty, out),
                            Some((cwords, ci)) => {
                                for (w, word) in out.iter_mut().enumerate() {
                                    let tz = w as u32 / TILE_WORDS;
                                    *word = reduce_word(
                                        cwords,
                                        &ci,
                                        [tx, ty, tz],
                                        w as u32 % TILE_WORDS,
                                    );
                                }
                            }
                        }
                    }
                });
        }
    }

    /// Is cell `(x, y, z)` of `level` occupied? Cells outside the grid are empty.
    pub fn occupied(&self, level: usize, x: u32, y: u32, z: u32) -> bool {
        let info = &self.layout.levels[level];
        if x >= info.dims[0] || y >= info.dims[1] || z >= info.dims[2] {
            return false;
        }
        let (w, b) = info.locate(x, y, z);
        (self.words[w as usize] >> b) & 1 != 0
    }

    /// Number of occupied cells on a level.
    pub fn count(&self, level: usize) -> u64 {
        let info = &self.layout.levels[level];
        self.words[info.offset as usize..(info.offset + info.words()) as usize]
            .iter()
            .map(|w| u64::from(w.count_ones()))
            .sum()
    }

    /// Bytes of the GPU buffer this pyramid fills.
    pub fn bytes(&self) -> u64 {
        self.layout.bytes()
    }
}

/// Altitude voxel rows on level 0 (kept for callers sizing z loops).
pub fn altitude_voxels(voxel: VoxelSize) -> u32 {
    ALTITUDES / voxel.z
}
