//! The samples one chunk sees: its `(size + 1)²` decoded columns, the last
//! row and column wrapping into the next chunk (the map is a torus).

use strata_level::Level;
use strata_level::model::decode_column;

use crate::predicates::Pt;

/// Flag bit of [`Sample::flags`]: the column is dual (has a slab).
pub const DUAL: u8 = 1;
/// Flag bit: the column and its eight neighbours inside the chunk are all dual.
pub const DUAL_INTERIOR: u8 = 2;

/// One decoded column, laid out for the fitter's inner loop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sample {
    /// `[low, mid, high]`.
    pub z: [u8; 3],
    /// [`DUAL`] and [`DUAL_INTERIOR`] bits.
    pub flags: u8,
    /// Terrain type (0..8) of the floor.
    pub lower_type: u8,
    /// Terrain type (0..8) of the slab (equal to `lower_type` in a single column).
    pub upper_type: u8,
}

impl Sample {
    /// Whether the column has a slab (the [`DUAL`] flag).
    #[inline]
    pub fn dual(&self) -> bool {
        self.flags & DUAL != 0
    }
}

/// Chunk geometry of a level: chunk side per axis (128, or the map side when
/// the map is smaller) and the chunk counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ChunkLayout {
    /// Chunk width, texels.
    pub size_x: u32,
    /// Chunk height, texels.
    pub size_y: u32,
    /// Chunks across the map.
    pub chunks_x: u32,
    /// Chunks down the map.
    pub chunks_y: u32,
}

/// The chunk side of the fit (DESIGN / issue 7).
pub const CHUNK: u32 = 128;

impl ChunkLayout {
    /// The chunks of `level` (its sides are powers of two, so chunks tile it).
    pub fn of(level: &Level) -> Self {
        let size_x = CHUNK.min(level.width());
        let size_y = CHUNK.min(level.height());
        ChunkLayout {
            size_x,
            size_y,
            chunks_x: level.width() / size_x,
            chunks_y: level.height() / size_y,
        }
    }

    /// Number of chunks.
    pub fn count(&self) -> usize {
        self.chunks_x as usize * self.chunks_y as usize
    }

    /// Chunk index (row-major) of chunk `(cx, cy)`.
    pub fn index(&self, cx: u32, cy: u32) -> usize {
        cy as usize * self.chunks_x as usize + cx as usize
    }

    /// `(cx, cy)` of a chunk index.
    pub fn coords(&self, index: usize) -> (u32, u32) {
        let cx = (index % self.chunks_x as usize) as u32;
        let cy = (index / self.chunks_x as usize) as u32;
        (cx, cy)
    }
}

/// The samples of one chunk, row-major with stride `size_x + 1`.
#[derive(Clone, Debug, Default)]
pub struct ChunkSamples {
    /// Chunk width, texels (samples across are `size_x + 1`).
    pub size_x: u32,
    /// Chunk height, texels (samples down are `size_y + 1`).
    pub size_y: u32,
    /// The decoded columns, row-major.
    pub samples: Vec<Sample>,
    /// `low`, `mid`, `high` as separate planes (same indexing as `samples`),
    /// for the vectorised candidate scan.
    pub planes: [Vec<u8>; 3],
    /// Summed-area table of dual samples, stride `size_x + 2`:
    /// `dual_sum[(y + 1) * (sx + 2) + x + 1]` counts duals in `[0, x] x [0, y]`.
    pub dual_sum: Vec<u32>,
    /// Dual samples as bits, [`words_per_row`](Self::words_per_row) `u64`s
    /// per row (bit `x % 64` of word `x / 64`), for scans that visit only
    /// the dual samples of a row.
    pub dual_bits: Vec<u64>,
}

impl ChunkSamples {
    /// Samples per row, `size_x + 1`.
    #[inline]
    pub fn stride(&self) -> usize {
        self.size_x as usize + 1
    }

    /// `u64` words per row of [`dual_bits`](Self::dual_bits).
    #[inline]
    pub fn words_per_row(&self) -> usize {
        self.stride().div_ceil(64)
    }

    /// Number of dual samples in `[x0, x1] x [y0, y1]` (inclusive, in range).
    #[inline]
    pub fn duals_in(&self, x0: i32, y0: i32, x1: i32, y1: i32) -> u32 {
        let sw = self.size_x as usize + 2;
        let at = |x: i32, y: i32| self.dual_sum[y as usize * sw + x as usize];
        (at(x1 + 1, y1 + 1) + at(x0, y0)).wrapping_sub(at(x0, y1 + 1) + at(x1 + 1, y0))
    }

    /// The sample at chunk-local `(x, y)` (in `0..=size`).
    #[inline]
    pub fn at(&self, x: i32, y: i32) -> &Sample {
        &self.samples[y as usize * self.stride() + x as usize]
    }

    /// Make `self` the floor of `src`: every sample single at its `low`
    /// (`mid = high = low`), types kept; what the outline fit's floor
    /// triangulation is fitted on.
    pub fn floor_of(&mut self, src: &ChunkSamples) {
        self.size_x = src.size_x;
        self.size_y = src.size_y;
        self.samples.clear();
        self.samples.extend(src.samples.iter().map(|s| Sample {
            z: [s.z[0]; 3],
            flags: 0,
            ..*s
        }));
        for plane in &mut self.planes {
            plane.clear();
            plane.extend_from_slice(&src.planes[0]);
        }
        self.dual_sum.clear();
        self.dual_sum.resize(src.dual_sum.len(), 0);
        self.dual_bits.clear();
        self.dual_bits.resize(src.dual_bits.len(), 0);
    }

    /// Decode chunk `(cx, cy)` of `level` into `self`, reusing the buffer.
    pub fn load(&mut self, level: &Level, layout: &ChunkLayout, cx: u32, cy: u32) {
        self.size_x = layout.size_x;
        self.size_y = layout.size_y;
        let (nx, ny) = (layout.size_x as usize + 1, layout.size_y as usize + 1);
        self.samples.clear();
        self.samples.reserve(nx * ny);
        let x0 = cx * layout.size_x;
        let y0 = cy * layout.size_y;
        let wmask = level.width() - 1;
        for j in 0..ny as u32 {
            let (heights, metas) = level.row((y0 + j) & (level.height() - 1));
            for i in 0..nx as u32 {
                let c = decode_column(heights, metas, ((x0 + i) & wmask) as usize, level.mid_rule);
                self.samples.push(Sample {
                    z: [c.low, c.mid, c.high],
                    flags: if c.dual { DUAL } else { 0 },
                    lower_type: c.lower_type,
                    upper_type: c.upper_type,
                });
            }
        }
        for (f, plane) in self.planes.iter_mut().enumerate() {
            plane.clear();
            plane.extend(self.samples.iter().map(|s| s.z[f]));
        }
        let sw = nx + 1;
        self.dual_sum.clear();
        self.dual_sum.resize(sw * (ny + 1), 0);
        let words = nx.div_ceil(64);
        self.dual_bits.clear();
        self.dual_bits.resize(words * ny, 0);
        for j in 0..ny {
            let mut run = 0;
            for i in 0..nx {
                let dual = self.samples[j * nx + i].flags & DUAL;
                run += u32::from(dual);
                self.dual_bits[j * words + i / 64] |= u64::from(dual) << (i % 64);
                self.dual_sum[(j + 1) * sw + i + 1] = self.dual_sum[j * sw + i + 1] + run;
            }
        }
        // Interior of a dual region, judged inside the chunk only so that a
        // chunk's fit (and its accounting) depends on its own samples alone.
        for j in 0..ny {
            for i in 0..nx {
                if self.samples[j * nx + i].flags & DUAL == 0 {
                    continue;
                }
                let mut all = true;
                for jj in j.saturating_sub(1)..(j + 2).min(ny) {
                    for ii in i.saturating_sub(1)..(i + 2).min(nx) {
                        all &= self.samples[jj * nx + ii].flags & DUAL != 0;
                    }
                }
                if all {
                    self.samples[j * nx + i].flags |= DUAL_INTERIOR;
                }
            }
        }
    }
}

/// The gaps of a chunk's slab: its unit squares `[x, x+1] x [y, y+1]` with
/// no dual sample at any corner. A point over such a square is at least half
/// a texel from every slab column, so the outline fit draws no slab there
/// ([`crate::triangulation::Triangulation::slab_edge`]).
#[derive(Clone, Debug, Default)]
pub struct GapSquares {
    /// Squares per row (`size_x`).
    width: i32,
    /// Summed-area table of `gap`, stride `width + 1`.
    sum: Vec<u32>,
}

impl GapSquares {
    /// The gaps of `chunk`.
    pub fn load(&mut self, chunk: &ChunkSamples) {
        let (w, h) = (chunk.size_x as i32, chunk.size_y as i32);
        self.width = w;
        let sw = w as usize + 1;
        self.sum.clear();
        self.sum.resize(sw * (h as usize + 1), 0);
        for y in 0..h {
            let mut run = 0;
            for x in 0..w {
                run += u32::from(chunk.duals_in(x, y, x + 1, y + 1) == 0);
                let (x, y) = (x as usize, y as usize);
                self.sum[(y + 1) * sw + x + 1] = self.sum[y * sw + x + 1] + run;
            }
        }
    }

    /// Whether any square of `[x0, x1) x [y0, y1)` is a gap.
    #[inline]
    fn any_in(&self, x0: i32, y0: i32, x1: i32, y1: i32) -> bool {
        let sw = self.width as usize + 1;
        let at = |x: i32, y: i32| self.sum[y as usize * sw + x as usize];
        at(x1, y1) + at(x0, y0) != at(x0, y1) + at(x1, y0)
    }

    /// Does segment `a`-`b` between two dual samples of the chunk pass over
    /// no gap? Exactly: no gap square's open interior meets the open
    /// segment.
    pub fn clear(&self, a: Pt, b: Pt) -> bool {
        let (dx, dy) = ((b[0] - a[0]).abs(), (b[1] - a[1]).abs());
        // On a grid line it meets no square's interior (its samples are
        // the error scan's). Within two texels each way, every square it
        // crosses has an end for a corner (the ends are dual: see
        // `Triangulation::slab_edge`). With no gap in its bounding box, it
        // crosses none.
        if dx == 0
            || dy == 0
            || (dx <= 2 && dy <= 2)
            || !self.any_in(
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[0].max(b[0]),
                a[1].max(b[1]),
            )
        {
            return true;
        }
        // Along the axis it advances less on, one strip at a time: a range
        // query per strip.
        if dx <= dy {
            Self::strips(a, b, |i, first, last| {
                !self.any_in(i, first, i + 1, last + 1)
            })
        } else {
            let t = |p: Pt| [p[1], p[0]];
            Self::strips(t(a), t(b), |i, first, last| {
                !self.any_in(first, i, last + 1, i + 1)
            })
        }
    }

    /// For each column `i` of squares between `a` and `b` (`a[0] != b[0]`,
    /// `a[1] != b[1]`): the rows `first..=last` of the squares the segment
    /// crosses there, while `clear(i, first, last)` holds.
    fn strips(a: Pt, b: Pt, mut clear: impl FnMut(i32, i32, i32) -> bool) -> bool {
        let (a, b) = if a[0] <= b[0] { (a, b) } else { (b, a) };
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        // Over x in (i, i+1) the segment's y spans the open interval
        // between y(i) and y(i+1), here times dx.
        let y_dx = |x: i32| a[1] * dx + (x - a[0]) * dy;
        (a[0]..b[0]).all(|i| {
            let (y0, y1) = (y_dx(i), y_dx(i + 1));
            let first = y0.min(y1).div_euclid(dx);
            let last = (y0.max(y1) + dx - 1).div_euclid(dx) - 1;
            clear(i, first, last)
        })
    }
}
