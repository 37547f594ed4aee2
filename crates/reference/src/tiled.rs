//! The tracer's view of a map read a tile at a time ([`ColumnSource`], e.g.
//! a store's chunk cache): no whole-map array is ever built. The pyramid's
//! levels are the in-memory tracer's (tiles of 4^l texels); the coarsest,
//! one cell per source tile when tiles are 4^L-texel squares (a store's
//! 256² chunks), comes from the source's tile tops (the chunk summaries'
//! `top_max`) without reading the tile, the finer ones from a small pyramid
//! of each tile built when a ray first descends into it and kept with the
//! tile in the source's cache (4,369 bytes for a 256² chunk: 1/30 of it).
//!
//! Skipping is exact at every level, and texel lines have one float value
//! whatever level crosses them (see `raycast::boundary_t`), so a ray's hit
//! does not depend on the pyramid's shape: results are bit-identical to the
//! in-memory tracer's (`tests/store.rs` holds them to it).

use crate::pyramid::LOG_RATIO;
use crate::raycast::Grid;
use std::sync::Arc;
use strata_level::model::{decode_column, pair_is_dual};
use strata_level::source::{ColumnSource, SourceError, SourceTile};
use strata_level::{Column, MidRule};

/// Max tops of one tile's cells of 4^l texels, l = 1..=levels.len().
pub(crate) struct TilePyramid {
    /// Level l at index l - 1, row-major, `cols >> 2l` cells across.
    levels: Vec<Vec<u8>>,
}

impl TilePyramid {
    /// Bytes a pyramid of `top` levels over a `rows x cols` tile holds.
    fn bytes(rows: u32, cols: u32, top: usize) -> usize {
        (1..=top)
            .map(|l| ((rows >> (2 * l)) * (cols >> (2 * l))) as usize)
            .sum()
    }

    /// Levels 1..=top of the tile with planes `heights`, `metas`.
    fn build(heights: &[u8], metas: &[u8], rows: u32, cols: u32, top: usize) -> Self {
        let mut levels: Vec<Vec<u8>> = Vec::with_capacity(top);
        let ratio = 1usize << LOG_RATIO;
        for l in 1..=top {
            let (w, h) = ((cols >> (2 * l)) as usize, (rows >> (2 * l)) as usize);
            let mut cells = vec![0u8; w * h];
            match levels.last() {
                // The first level from the texels: a dual pair's two
                // columns both reach `high` (the odd texel's height), a
                // single texel its own height.
                None => {
                    for (r, (hr, mr)) in heights
                        .chunks_exact(cols as usize)
                        .zip(metas.chunks_exact(cols as usize))
                        .enumerate()
                    {
                        let row = &mut cells[(r / ratio) * w..(r / ratio + 1) * w];
                        for (p, (hp, mp)) in hr.chunks_exact(2).zip(mr.chunks_exact(2)).enumerate()
                        {
                            let top = if pair_is_dual(mp[0], mp[1]) {
                                hp[1]
                            } else {
                                hp[0].max(hp[1])
                            };
                            let cell = &mut row[2 * p / ratio];
                            *cell = (*cell).max(top);
                        }
                    }
                }
                Some(finer) => {
                    let fw = w * ratio;
                    for (i, v) in finer.iter().enumerate() {
                        let (fx, fy) = (i % fw, i / fw);
                        let cell = &mut cells[(fy / ratio) * w + fx / ratio];
                        *cell = (*cell).max(*v);
                    }
                }
            }
            levels.push(cells);
        }
        TilePyramid { levels }
    }
}

/// A source read tile by tile, with its coarse tops.
pub(crate) struct TiledGrid<'a> {
    pub(crate) source: &'a dyn ColumnSource,
    mid_rule: MidRule,
    /// Map size minus one (sides are powers of two).
    wmask: i64,
    hmask: i64,
    /// Tile rows and columns.
    rows: u32,
    cols: u32,
    rows_log: u32,
    cols_log: u32,
    /// Tiles across.
    grid_cols: u64,
    /// The coarsest pyramid level (0: none).
    top: usize,
    /// Each tile's highest top, when the source knows them.
    tops: Option<Vec<u8>>,
    global_max: u8,
}

impl<'a> TiledGrid<'a> {
    pub(crate) fn new(source: &'a dyn ColumnSource, accelerate: bool) -> Result<Self, SourceError> {
        let (w, h) = source.size();
        let (rows, cols) = source.tile_shape();
        let ok = |v: u32| v.is_power_of_two();
        if !(ok(w) && ok(h) && ok(rows) && ok(cols) && rows <= h && cols <= w && cols >= 2) {
            return Err(SourceError(format!(
                "a {w}x{h} map in {cols}x{rows} tiles: sides must be powers of two, tiles even and inside the map"
            )));
        }
        let (tops, top, global_max) = if accelerate {
            let top = (rows.min(cols).trailing_zeros() / LOG_RATIO) as usize;
            let tops = source.tile_tops()?;
            let expected = u64::from(w / cols) * u64::from(h / rows);
            if let Some(t) = &tops
                && t.len() as u64 != expected
            {
                return Err(SourceError(format!(
                    "{} tile tops for {expected} tiles",
                    t.len()
                )));
            }
            // Without tops the map's highest point is unknown (finding it
            // would read every tile): every altitude is possible.
            let global_max = tops
                .as_ref()
                .map_or(u8::MAX, |t| t.iter().copied().max().unwrap_or(0));
            (tops, top, global_max)
        } else {
            // As the in-memory unaccelerated tracer: no levels, no ceiling.
            (None, 0, u8::MAX)
        };
        Ok(TiledGrid {
            source,
            mid_rule: source.mid_rule(),
            wmask: i64::from(w - 1),
            hmask: i64::from(h - 1),
            rows,
            cols,
            rows_log: rows.trailing_zeros(),
            cols_log: cols.trailing_zeros(),
            grid_cols: u64::from(w / cols),
            top,
            tops,
            global_max,
        })
    }

    /// Make tile (ty, tx) the cursor's current one (its first slot).
    #[inline]
    fn enter(&self, cur: &mut TileCursor<'a>, ty: u64, tx: u64) -> Option<()> {
        match cur.slots.iter().position(|s| s.key == (ty, tx)) {
            Some(0) => {}
            Some(i) => cur.slots[..=i].rotate_right(1),
            None => match self.source.tile(ty, tx) {
                Ok(tile) => {
                    if cur.slots.len() == CURSOR_TILES {
                        cur.slots.pop();
                    }
                    cur.slots.insert(
                        0,
                        Slot {
                            key: (ty, tx),
                            tile,
                            pyramid: None,
                        },
                    );
                }
                Err(e) => {
                    cur.error = Some(e);
                    return None;
                }
            },
        }
        Some(())
    }

    /// The pyramid of the cursor's current tile (built on first use, kept
    /// with the tile in the source's cache). Borrowed, not cloned: the
    /// `Arc`'s count is shared between threads, so touching it per step
    /// would bounce its cache line between cores.
    #[inline]
    fn pyramid<'c>(&self, cur: &'c mut TileCursor<'a>) -> &'c TilePyramid {
        let slot = &mut cur.slots[0];
        if slot.pyramid.is_none() {
            let (rows, cols, top) = (self.rows, self.cols, self.top);
            let tile = &slot.tile;
            let make = || {
                let (h, m) = tile.planes();
                TilePyramid::build(h, m, rows, cols, top)
            };
            slot.pyramid = Some(match tile.derived() {
                Some(d) => d.get_or_make(TilePyramid::bytes(rows, cols, top), make),
                None => Arc::new(make()),
            });
        }
        slot.pyramid.as_deref().expect("set above")
    }
}

/// Tiles a cursor keeps at hand: a ray crosses a few chunks, and the next
/// ray of the same thread mostly the same ones. They are held outside the
/// source's budget (at most this many chunks per thread).
const CURSOR_TILES: usize = 4;

struct Slot<'a> {
    key: (u64, u64),
    tile: Arc<dyn SourceTile + 'a>,
    pyramid: Option<Arc<TilePyramid>>,
}

/// Per thread: the tiles being read (most recent first), their pyramids,
/// and a read error.
#[derive(Default)]
pub(crate) struct TileCursor<'a> {
    slots: Vec<Slot<'a>>,
    pub(crate) error: Option<SourceError>,
}

impl<'a> Grid for TiledGrid<'a> {
    type Cursor = TileCursor<'a>;

    fn top_level(&self) -> usize {
        self.top
    }

    fn global_max(&self) -> u8 {
        self.global_max
    }

    #[inline]
    fn tile_max(&self, cur: &mut TileCursor<'a>, level: usize, cx: i64, cy: i64) -> Option<u8> {
        let shift = LOG_RATIO as usize * level;
        let (x, y) = ((cx << shift) & self.wmask, (cy << shift) & self.hmask);
        let (tx, ty) = ((x >> self.cols_log) as u64, (y >> self.rows_log) as u64);
        if level == self.top
            && let Some(tops) = &self.tops
        {
            // The tile's highest top: exact when the cell is the tile, an
            // upper bound (so still an exact skip) when the tile is larger.
            return Some(tops[(ty * self.grid_cols + tx) as usize]);
        }
        self.enter(cur, ty, tx)?;
        let p = self.pyramid(cur);
        let across = (self.cols >> shift) as i64;
        let (lx, ly) = (
            (x & i64::from(self.cols - 1)) >> shift,
            (y & i64::from(self.rows - 1)) >> shift,
        );
        Some(p.levels[level - 1][(ly * across + lx) as usize])
    }

    #[inline]
    fn column(&self, cur: &mut TileCursor<'a>, x: i64, y: i64) -> Option<Column> {
        let (x, y) = (x & self.wmask, y & self.hmask);
        let (tx, ty) = ((x >> self.cols_log) as u64, (y >> self.rows_log) as u64);
        self.enter(cur, ty, tx)?;
        let (h, m) = cur.slots[0].tile.planes();
        let cols = self.cols as usize;
        let start = (y & i64::from(self.rows - 1)) as usize * cols;
        Some(decode_column(
            &h[start..start + cols],
            &m[start..start + cols],
            (x & i64::from(self.cols - 1)) as usize,
            self.mid_rule,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::Level;

    #[test]
    fn tile_pyramid_holds_cell_maxima() {
        let (w, h) = (64u32, 64u32);
        let heights: Vec<u8> = (0..w * h).map(|i| ((i * 97) % 241) as u8).collect();
        let metas: Vec<u8> = (0..w * h)
            .map(|i| if (i / 2) % 5 == 0 { 0x40 } else { 0 })
            .collect();
        let level =
            Level::from_planes(w, h, heights.clone(), metas.clone(), MidRule::Original).unwrap();
        let p = TilePyramid::build(&heights, &metas, h, w, 3);
        assert_eq!(TilePyramid::bytes(h, w, 3), 16 * 16 + 4 * 4 + 1);
        for l in 1..=3usize {
            let s = 1i64 << (2 * l);
            let across = 64 / s;
            for cy in 0..across {
                for cx in 0..across {
                    let mut m = 0;
                    for y in cy * s..(cy + 1) * s {
                        for x in cx * s..(cx + 1) * s {
                            m = m.max(level.column(x, y).top());
                        }
                    }
                    assert_eq!(
                        p.levels[l - 1][(cy * across + cx) as usize],
                        m,
                        "{l} {cx} {cy}"
                    );
                }
            }
        }
    }
}
