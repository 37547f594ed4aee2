//! [`ChunkCache`]: decoded chunks of a store under a byte budget, least
//! recently used first out. Reads happen outside the lock, so threads
//! missing different chunks decode them in parallel.
//!
//! The cache is a [`ColumnSource`] (its tiles are the store's chunks, the
//! chunk summaries give each tile's highest top without reading it), so the
//! CPU reference, the region fit and the export read a store through it in
//! bounded memory. Data a reader derives from a chunk (the tracer's
//! max-height pyramid of the chunk) is kept with the chunk, up to 1/16 of
//! the chunk's bytes, and counted in the budget.

use crate::error::StoreError;
use crate::store::{Chunk, WorldStore};
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use strata_level::model::{Column, MidRule, decode_column};
#[cfg(not(target_arch = "wasm32"))]
use strata_level::source::{ColumnSource, SourceError};
use strata_level::source::{DerivedSlot, SourceTile};

/// How the cache has been used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheStats {
    /// Lookups answered from memory.
    pub hits: u64,
    /// Lookups that read a chunk.
    pub misses: u64,
    /// Chunks dropped to stay within the budget.
    pub evictions: u64,
    /// Bytes of decoded chunks (and the data derived from them) held now.
    pub bytes: usize,
    /// Chunks held now.
    pub chunks: usize,
    /// The most `bytes` ever was after a lookup (a chunk being read is
    /// held beside the others until the least recent ones go).
    pub peak_bytes: usize,
}

impl CacheStats {
    /// Hits over lookups, percent (0 before any lookup).
    pub fn hit_rate(&self) -> f64 {
        let n = self.hits + self.misses;
        if n == 0 {
            0.0
        } else {
            100.0 * self.hits as f64 / n as f64
        }
    }
}

/// One cached chunk: its planes and what readers derived from them.
pub struct CachedChunk {
    /// The chunk's planes.
    pub chunk: Arc<Chunk>,
    derived: DerivedSlot,
    /// Derived bytes counted in the cache's `bytes` (changed under its lock).
    charged: Arc<AtomicUsize>,
}

impl CachedChunk {
    /// What the chunk counts for in the budget (call under the cache's lock).
    fn bytes(&self) -> usize {
        self.chunk.bytes() + self.charged.load(Ordering::Relaxed)
    }
}

impl SourceTile for CachedChunk {
    fn planes(&self) -> (&[u8], &[u8]) {
        (&self.chunk.heights, &self.chunk.metas)
    }
    fn derived(&self) -> Option<&DerivedSlot> {
        Some(&self.derived)
    }
}

#[derive(Default)]
struct Lru {
    map: HashMap<(u64, u64), (Arc<CachedChunk>, u64)>,
    /// Last use -> chunk, oldest first.
    order: BTreeMap<u64, (u64, u64)>,
    tick: u64,
    stats: CacheStats,
}

impl Lru {
    fn touch(&mut self, key: (u64, u64)) -> Option<Arc<CachedChunk>> {
        self.tick += 1;
        let tick = self.tick;
        let (chunk, last) = self.map.get_mut(&key)?;
        self.order.remove(last);
        *last = tick;
        self.order.insert(tick, key);
        Some(chunk.clone())
    }

    /// Drop the least recently used chunks until within `budget` (keeping one).
    fn shrink(&mut self, budget: usize) {
        while self.stats.bytes > budget && self.map.len() > 1 {
            let (_, key) = self.order.pop_first().expect("order matches map");
            if let Some((old, _)) = self.map.remove(&key) {
                self.stats.bytes -= old.bytes();
                self.stats.evictions += 1;
            }
        }
        self.stats.chunks = self.map.len();
    }
}

/// A store's decoded chunks within a byte budget.
pub struct ChunkCache {
    store: Arc<WorldStore>,
    budget: usize,
    mid_rule: MidRule,
    lru: Arc<Mutex<Lru>>,
    /// Each chunk's highest top, from the summaries (read once).
    tops: Mutex<Option<Arc<Vec<u8>>>>,
}

impl ChunkCache {
    /// A cache over `store` holding at most `budget` bytes of decoded chunks
    /// (at least one chunk is always kept, whatever the budget).
    pub fn new(store: Arc<WorldStore>, budget: usize, mid_rule: MidRule) -> Self {
        ChunkCache {
            store,
            budget,
            mid_rule,
            lru: Arc::new(Mutex::new(Lru::default())),
            tops: Mutex::new(None),
        }
    }

    /// The store read through.
    pub fn store(&self) -> &Arc<WorldStore> {
        &self.store
    }

    /// The byte budget.
    pub fn budget(&self) -> usize {
        self.budget
    }

    /// Use so far.
    pub fn stats(&self) -> CacheStats {
        self.lru.lock().expect("cache lock").stats
    }

    /// The chunk at grid row `cy`, column `cx`.
    pub fn chunk(&self, cy: u64, cx: u64) -> Result<Arc<Chunk>, StoreError> {
        Ok(self.cached(cy, cx)?.chunk.clone())
    }

    /// The chunk at grid row `cy`, column `cx`, with its derived-data slot.
    pub fn cached(&self, cy: u64, cx: u64) -> Result<Arc<CachedChunk>, StoreError> {
        {
            let mut lru = self.lru.lock().expect("cache lock");
            if let Some(c) = lru.touch((cy, cx)) {
                lru.stats.hits += 1;
                return Ok(c);
            }
        }
        let chunk = Arc::new(self.store.read_chunk(cy, cx)?);
        // Derived data is charged when a reader keeps it, and may push the
        // cache over its budget only until the least recent chunks go.
        let weak: Weak<Mutex<Lru>> = Arc::downgrade(&self.lru);
        let (budget, key) = (self.budget, (cy, cx));
        let charged = Arc::new(AtomicUsize::new(0));
        let counter = charged.clone();
        let charge = Box::new(move |bytes: usize| {
            if let Some(lru) = weak.upgrade() {
                let mut lru = lru.lock().expect("cache lock");
                // Only while this very entry is held: an evicted one is no
                // longer counted (its bytes went with it), and a re-read of
                // the same chunk is another entry.
                let held = lru
                    .map
                    .get(&key)
                    .is_some_and(|(e, _)| Arc::ptr_eq(&e.charged, &counter));
                if held {
                    counter.fetch_add(bytes, Ordering::Relaxed);
                    lru.stats.bytes += bytes;
                    lru.shrink(budget);
                    lru.stats.peak_bytes = lru.stats.peak_bytes.max(lru.stats.bytes);
                }
            }
        });
        let entry = Arc::new(CachedChunk {
            derived: DerivedSlot::new(chunk.bytes() / 16, Some(charge)),
            chunk,
            charged,
        });
        let mut lru = self.lru.lock().expect("cache lock");
        lru.stats.misses += 1;
        if let Some(c) = lru.touch((cy, cx)) {
            // Another thread read it meanwhile.
            return Ok(c);
        }
        let tick = lru.tick;
        lru.stats.bytes += entry.bytes();
        lru.map.insert((cy, cx), (entry.clone(), tick));
        lru.order.insert(tick, (cy, cx));
        lru.shrink(self.budget);
        lru.stats.peak_bytes = lru.stats.peak_bytes.max(lru.stats.bytes);
        Ok(entry)
    }

    /// Forget the given chunks (after an edit rewrote them).
    pub fn invalidate(&self, cells: &[(u64, u64)]) {
        let mut lru = self.lru.lock().expect("cache lock");
        for key in cells {
            if let Some((old, last)) = lru.map.remove(key) {
                lru.order.remove(&last);
                lru.stats.bytes -= old.bytes();
            }
        }
        lru.stats.chunks = lru.map.len();
        drop(lru);
        *self.tops.lock().expect("cache lock") = None;
    }

    /// Each chunk's highest column top (grid row-major), from the summary
    /// array alone (read once; [`Self::invalidate`] forgets it).
    pub fn chunk_tops(&self) -> Result<Arc<Vec<u8>>, StoreError> {
        let mut tops = self.tops.lock().expect("cache lock");
        if let Some(t) = &*tops {
            return Ok(t.clone());
        }
        let t: Arc<Vec<u8>> = Arc::new(self.store.summaries()?.iter().map(|s| s.top_max).collect());
        *tops = Some(t.clone());
        Ok(t)
    }

    /// The decoded column at texel (x, y), wrapping in both directions.
    pub fn column(&self, x: i64, y: i64) -> Result<Column, StoreError> {
        let (w, h) = (self.store.width(), self.store.height());
        let (x, y) = ((x & i64::from(w - 1)) as u32, (y & i64::from(h - 1)) as u32);
        let (ch, cw) = self.store.chunk_shape();
        let chunk = self.chunk(u64::from(y / ch), u64::from(x / cw))?;
        let (ry, rx) = ((y % ch) as usize, (x % cw) as usize);
        let row = ry * cw as usize..(ry + 1) * cw as usize;
        Ok(decode_column(
            &chunk.heights[row.clone()],
            &chunk.metas[row],
            rx,
            self.mid_rule,
        ))
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn source_error(e: StoreError) -> SourceError {
    SourceError(e.to_string())
}

// zarrs' storage is neither Send nor Sync on wasm32 (one thread there), and
// column sources are shared between threads.
#[cfg(not(target_arch = "wasm32"))]
impl ColumnSource for ChunkCache {
    fn size(&self) -> (u32, u32) {
        (self.store.width(), self.store.height())
    }
    fn mid_rule(&self) -> MidRule {
        self.mid_rule
    }
    fn tile_shape(&self) -> (u32, u32) {
        self.store.chunk_shape()
    }
    fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError> {
        Ok(self.cached(ty, tx).map_err(source_error)?)
    }
    fn tile_tops(&self) -> Result<Option<Vec<u8>>, SourceError> {
        // The summaries' top_max uses the original mid rule, but a column's
        // top (`high` or `low`) does not depend on the rule.
        Ok(Some(self.chunk_tops().map_err(source_error)?.to_vec()))
    }
}
