//! [`ColumnSource`]: where a reader gets a map's texel columns from, without
//! knowing whether the map is a [`Level`] in memory or a store read a chunk
//! at a time through a cache with a byte budget (`strata-store`'s
//! `ChunkCache`). The CPU reference, the region fit and the export read
//! through it, so a world larger than memory is read in bounded memory.
//!
//! The unit of reading is a *tile* (a store's chunk; a level is one tile):
//! readers ask for a tile once and decode its columns themselves, because a
//! lookup per texel through a shared cache costs a lock each. A tile can
//! keep data a reader derived from it ([`DerivedSlot`], e.g. the tracer's
//! max-height pyramid of the tile) for as long as the source keeps the tile,
//! counted in the source's budget.

use crate::model::{Column, Level, MidRule, decode_column};
use std::any::Any;
use std::sync::{Arc, OnceLock};

/// A tile could not be read (a store's chunk missing, corrupt, unreadable).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SourceError(pub String);

/// Data derived from a tile, shared between readers.
pub type Derived = Arc<dyn Any + Send + Sync>;

/// Charges the source's budget with `bytes` of derived data.
pub type Charge = Box<dyn Fn(usize) + Send + Sync>;

/// A slot where a reader keeps data derived from a tile (set once, then
/// shared). The source charges its byte budget with it through `charge`;
/// values above `limit` bytes are made but not kept.
pub struct DerivedSlot {
    value: OnceLock<(Derived, usize)>,
    limit: usize,
    charge: Option<Charge>,
}

impl DerivedSlot {
    /// A slot that keeps values of at most `limit` bytes, calling `charge`
    /// with the size of the one it keeps.
    pub fn new(limit: usize, charge: Option<Charge>) -> Self {
        DerivedSlot {
            value: OnceLock::new(),
            limit,
            charge,
        }
    }

    /// Bytes of the value kept (0: none).
    pub fn bytes(&self) -> usize {
        self.value.get().map_or(0, |v| v.1)
    }

    /// The value kept, else `make()` (kept when it is at most the limit's
    /// `bytes` and the slot is still empty). A slot holding another type
    /// (another reader's) answers with a fresh, unkept value.
    pub fn get_or_make<T: Any + Send + Sync>(
        &self,
        bytes: usize,
        make: impl FnOnce() -> T,
    ) -> Arc<T> {
        if let Some((v, _)) = self.value.get() {
            return match v.clone().downcast::<T>() {
                Ok(t) => t,
                Err(_) => Arc::new(make()),
            };
        }
        let made = Arc::new(make());
        if bytes > self.limit {
            return made;
        }
        let mut kept_now = false;
        let (v, _) = self.value.get_or_init(|| {
            kept_now = true;
            (made.clone() as Derived, bytes)
        });
        if kept_now && let Some(charge) = &self.charge {
            charge(bytes);
        }
        v.clone().downcast::<T>().unwrap_or(made)
    }
}

/// One tile of a [`ColumnSource`]: its two planes, row-major, `rows * cols`
/// bytes each (the source's [`ColumnSource::tile_shape`]).
pub trait SourceTile: Send + Sync {
    /// The height and meta planes.
    fn planes(&self) -> (&[u8], &[u8]);
    /// Where readers keep data derived from this tile; `None`: nowhere (a
    /// reader then derives it on each use).
    fn derived(&self) -> Option<&DerivedSlot> {
        None
    }
}

/// A map's texel columns, read a tile at a time. The map wraps in x and y;
/// both sides are powers of two, tiles too, and tiles divide the map.
pub trait ColumnSource: Sync {
    /// Map (width, height), texels.
    fn size(&self) -> (u32, u32);
    /// How `mid` is decoded.
    fn mid_rule(&self) -> MidRule;
    /// Tile (rows, columns); columns are even, so pairs never straddle tiles.
    fn tile_shape(&self) -> (u32, u32);
    /// The tile at tile row `ty`, column `tx` (inside the grid).
    fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError>;
    /// The highest column top of every tile, tile grid row-major, when the
    /// source knows them without reading tiles (a store's chunk summaries).
    fn tile_tops(&self) -> Result<Option<Vec<u8>>, SourceError> {
        Ok(None)
    }
    /// The whole map, when it is in memory (readers take their fast path).
    fn as_level(&self) -> Option<&Level> {
        None
    }

    /// The decoded column at texel (x, y), wrapping. One tile lookup per
    /// call: for many columns read tiles with [`tile`](Self::tile).
    fn column(&self, x: i64, y: i64) -> Result<Column, SourceError> {
        if let Some(level) = self.as_level() {
            return Ok(level.column(x, y));
        }
        let (w, h) = self.size();
        let (rows, cols) = self.tile_shape();
        let x = (x & i64::from(w - 1)) as u64;
        let y = (y & i64::from(h - 1)) as u64;
        let tile = self.tile(y / u64::from(rows), x / u64::from(cols))?;
        let (heights, metas) = tile.planes();
        let (ry, rx) = (
            (y % u64::from(rows)) as usize,
            (x % u64::from(cols)) as usize,
        );
        let row = ry * cols as usize..(ry + 1) * cols as usize;
        Ok(decode_column(
            &heights[row.clone()],
            &metas[row],
            rx,
            self.mid_rule(),
        ))
    }
}

/// The raw planes of the `width x height` texels from (x0, y0), wrapping,
/// row-major: what a region's fit needs (pairs decode from raw bytes).
pub fn read_window(
    source: &dyn ColumnSource,
    x0: i64,
    y0: i64,
    width: u32,
    height: u32,
) -> Result<(Vec<u8>, Vec<u8>), SourceError> {
    let (w, h) = source.size();
    let n = width as usize * height as usize;
    let (mut hs, mut ms) = (vec![0u8; n], vec![0u8; n]);
    if let Some(level) = source.as_level() {
        for j in 0..height as usize {
            let (hr, mr) = level.row(((y0 + j as i64) & i64::from(h - 1)) as u32);
            for i in 0..width as usize {
                let x = ((x0 + i as i64) & i64::from(w - 1)) as usize;
                hs[j * width as usize + i] = hr[x];
                ms[j * width as usize + i] = mr[x];
            }
        }
        return Ok((hs, ms));
    }
    let (rows, cols) = source.tile_shape();
    let (rows, cols) = (i64::from(rows), i64::from(cols));
    // Tile by tile: each tile the window touches is read once per pass
    // over its rows' band.
    let mut j = 0i64;
    while j < i64::from(height) {
        let y = (y0 + j) & i64::from(h - 1);
        let band = (rows - y % rows).min(i64::from(height) - j);
        let mut i = 0i64;
        while i < i64::from(width) {
            let x = (x0 + i) & i64::from(w - 1);
            let run = (cols - x % cols).min(i64::from(width) - i);
            let tile = source.tile((y / rows) as u64, (x / cols) as u64)?;
            let (th, tm) = tile.planes();
            for r in 0..band {
                let src = ((y % rows + r) * cols + x % cols) as usize;
                let dst = ((j + r) * i64::from(width) + i) as usize;
                hs[dst..dst + run as usize].copy_from_slice(&th[src..src + run as usize]);
                ms[dst..dst + run as usize].copy_from_slice(&tm[src..src + run as usize]);
            }
            i += run;
        }
        j += band;
    }
    Ok((hs, ms))
}

/// A level handed out as one tile (borrowing its planes).
struct LevelTile<'a>(&'a Level);

impl SourceTile for LevelTile<'_> {
    fn planes(&self) -> (&[u8], &[u8]) {
        (self.0.heights(), self.0.metas())
    }
}

impl ColumnSource for Level {
    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }
    fn mid_rule(&self) -> MidRule {
        self.mid_rule
    }
    fn tile_shape(&self) -> (u32, u32) {
        (self.height(), self.width())
    }
    fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError> {
        if (ty, tx) != (0, 0) {
            return Err(SourceError(format!(
                "tile ({ty}, {tx}) of a level, which is one tile"
            )));
        }
        Ok(Arc::new(LevelTile(self)))
    }
    fn as_level(&self) -> Option<&Level> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level read as 4x8 tiles without its fast path.
    struct Tiled(Level);
    struct Owned(Vec<u8>, Vec<u8>, DerivedSlot);
    impl SourceTile for Owned {
        fn planes(&self) -> (&[u8], &[u8]) {
            (&self.0, &self.1)
        }
        fn derived(&self) -> Option<&DerivedSlot> {
            Some(&self.2)
        }
    }
    impl ColumnSource for Tiled {
        fn size(&self) -> (u32, u32) {
            self.0.size()
        }
        fn mid_rule(&self) -> MidRule {
            self.0.mid_rule
        }
        fn tile_shape(&self) -> (u32, u32) {
            (4, 8)
        }
        fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError> {
            let (h, m) = read_window(&self.0, tx as i64 * 8, ty as i64 * 4, 8, 4)?;
            Ok(Arc::new(Owned(h, m, DerivedSlot::new(16, None))))
        }
    }

    fn level() -> Level {
        let (w, h) = (32u32, 16u32);
        let heights = (0..w * h).map(|i| (i * 37 % 251) as u8).collect();
        let metas = (0..w * h)
            .map(|i| {
                if (i / 2) % 3 == 0 {
                    0x40 | (i as u8 & 3)
                } else {
                    0
                }
            })
            .collect();
        Level::from_planes(w, h, heights, metas, MidRule::Original).unwrap()
    }

    #[test]
    fn tiled_reads_equal_the_level() {
        let l = level();
        let t = Tiled(l.clone());
        for (x, y) in [(0, 0), (5, 3), (31, 15), (-1, -1), (40, 17), (9, 4)] {
            assert_eq!(t.column(x, y).unwrap(), l.column(x, y));
            assert_eq!(ColumnSource::column(&l, x, y).unwrap(), l.column(x, y));
        }
        let (h, m) = read_window(&t, 29, 14, 7, 5).unwrap();
        let (h2, m2) = read_window(&l, 29, 14, 7, 5).unwrap();
        assert_eq!((h, m), (h2, m2));
        assert!(l.tile(1, 0).is_err());
    }

    #[test]
    fn a_slot_keeps_one_value_within_its_limit() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let charged = Arc::new(AtomicUsize::new(0));
        let c = charged.clone();
        let slot = DerivedSlot::new(
            10,
            Some(Box::new(move |b| {
                c.fetch_add(b, Ordering::SeqCst);
            })),
        );
        assert_eq!(*slot.get_or_make(8, || 1u32), 1);
        assert_eq!(*slot.get_or_make(8, || 2u32), 1, "kept");
        assert_eq!(*slot.get_or_make(8, || 3u64), 3, "another type: fresh");
        assert_eq!((slot.bytes(), charged.load(Ordering::SeqCst)), (8, 8));
        let big = DerivedSlot::new(4, None);
        assert_eq!(*big.get_or_make(8, || 5u8), 5);
        assert_eq!(big.bytes(), 0, "above the limit: not kept");
    }
}
