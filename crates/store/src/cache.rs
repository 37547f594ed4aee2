//! [`ChunkCache`]: decoded chunks of a store under a byte budget, least
//! recently used first out. Reads happen outside the lock, so threads
//! missing different chunks decode them in parallel.

use crate::error::StoreError;
use crate::store::{Chunk, WorldStore};
use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex};
use strata_level::model::{Column, MidRule, decode_column};

/// How the cache has been used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheStats {
    /// Lookups answered from memory.
    pub hits: u64,
    /// Lookups that read a chunk.
    pub misses: u64,
    /// Chunks dropped to stay within the budget.
    pub evictions: u64,
    /// Bytes of decoded chunks held now.
    pub bytes: usize,
    /// Chunks held now.
    pub chunks: usize,
}

#[derive(Default)]
struct Lru {
    map: HashMap<(u64, u64), (Arc<Chunk>, u64)>,
    /// Last use -> chunk, oldest first.
    order: BTreeMap<u64, (u64, u64)>,
    tick: u64,
    stats: CacheStats,
}

impl Lru {
    fn touch(&mut self, key: (u64, u64)) -> Option<Arc<Chunk>> {
        self.tick += 1;
        let tick = self.tick;
        let (chunk, last) = self.map.get_mut(&key)?;
        self.order.remove(last);
        *last = tick;
        self.order.insert(tick, key);
        Some(chunk.clone())
    }
}

/// A store's decoded chunks within a byte budget.
pub struct ChunkCache {
    store: Arc<WorldStore>,
    budget: usize,
    mid_rule: MidRule,
    lru: Mutex<Lru>,
}

impl ChunkCache {
    /// A cache over `store` holding at most `budget` bytes of decoded chunks
    /// (at least one chunk is always kept, whatever the budget).
    pub fn new(store: Arc<WorldStore>, budget: usize, mid_rule: MidRule) -> Self {
        ChunkCache {
            store,
            budget,
            mid_rule,
            lru: Mutex::new(Lru::default()),
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
        {
            let mut lru = self.lru.lock().expect("cache lock");
            if let Some(c) = lru.touch((cy, cx)) {
                lru.stats.hits += 1;
                return Ok(c);
            }
        }
        let chunk = Arc::new(self.store.read_chunk(cy, cx)?);
        let mut lru = self.lru.lock().expect("cache lock");
        lru.stats.misses += 1;
        if let Some(c) = lru.touch((cy, cx)) {
            // Another thread read it meanwhile.
            return Ok(c);
        }
        let tick = lru.tick;
        lru.stats.bytes += chunk.bytes();
        lru.map.insert((cy, cx), (chunk.clone(), tick));
        lru.order.insert(tick, (cy, cx));
        while lru.stats.bytes > self.budget && lru.map.len() > 1 {
            let (_, key) = lru.order.pop_first().expect("order matches map");
            if let Some((old, _)) = lru.map.remove(&key) {
                lru.stats.bytes -= old.bytes();
                lru.stats.evictions += 1;
            }
        }
        lru.stats.chunks = lru.map.len();
        Ok(chunk)
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
