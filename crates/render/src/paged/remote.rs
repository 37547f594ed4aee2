//! Pages whose reads complete later (issue 34): [`RemoteChunks`] is the
//! state between the [`super::Streamer`] (which says each frame what it
//! wants, through [`AsyncPages`]) and a pump outside this crate that does
//! the reads (the browser page's `fetch`es: `crates/web/src/stream.rs`).
//! It holds no thread, no timer and no I/O, so natively it is tested as
//! is: the pump asks [`RemoteChunks::start`] for reads to begin (at most
//! its cap in flight, most wanted first), aborts what
//! [`RemoteChunks::take_cancelled`] returns (reads the camera no longer
//! wants), and hands each result to [`RemoteChunks::deliver`]. Failed reads
//! go back to the paged terrain like a failed read of any source (it
//! retries a chunk [`super::PagedOptions::read_tries`] times, then reports
//! it); pages already resident keep drawing whatever the reads do.
//!
//! The planes of the last pages read stay in a small cache (the CPU's
//! copy: the viewer reads the column under a view or a dig's chunks from
//! it); a page not in it is not read on demand here.

use super::PAGE;
use super::source::{AsyncPages, PageData, PageRef, PageSource, Planes};
use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::{Arc, Mutex};
use strata_level::MidRule;

/// What the reads did so far, for the page's overlay and state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RemoteStats {
    /// Reads started.
    pub started: u64,
    /// Reads finished with a page.
    pub done: u64,
    /// Reads failed (each try counts).
    pub failed: u64,
    /// Reads cancelled in flight (no longer wanted).
    pub cancelled: u64,
    /// Bytes fetched (as they came over the wire, both planes).
    pub bytes: u64,
    /// Reads in flight now.
    pub in_flight: u32,
}

#[derive(Default)]
struct State {
    /// Wanted and not started, most wanted first.
    queue: VecDeque<PageRef>,
    /// Started, not delivered.
    started: HashMap<u32, PageRef>,
    /// Started reads no longer wanted, for the pump to abort.
    cancelled: Vec<u32>,
    /// Delivered, not yet taken by the streamer.
    finished: VecDeque<(u32, Result<Planes, String>)>,
    /// The last pages read, by (level, cx, cy), with the tick of their use.
    cache: HashMap<(u32, u32, u32), (Arc<Planes>, u64)>,
    /// Pages the caller read itself ([`RemoteChunks::pin`]), never evicted.
    pinned: HashMap<(u32, u32, u32), Arc<Planes>>,
    tick: u64,
    stats: RemoteStats,
}

/// A world whose pages come from a pump that reads them asynchronously.
pub struct RemoteChunks {
    size: (u32, u32),
    mid_rule: MidRule,
    tops: Vec<u8>,
    lod_levels: u32,
    most_in_flight: usize,
    cache_pages: usize,
    state: Mutex<State>,
}

impl RemoteChunks {
    /// A world of `size` texels (whole pages, powers of two) whose chunk
    /// tops (the coarse level, row-major) are `tops`, with `lod_levels`
    /// coarse levels; at most `most_in_flight` reads at a time, the planes
    /// of the last `cache_pages` pages kept.
    pub fn new(
        size: (u32, u32),
        mid_rule: MidRule,
        tops: Vec<u8>,
        lod_levels: u32,
        most_in_flight: usize,
        cache_pages: usize,
    ) -> anyhow::Result<Self> {
        super::source::check_size(size.0, size.1)?;
        let chunks = (size.0 / PAGE) as usize * (size.1 / PAGE) as usize;
        if tops.len() != chunks {
            anyhow::bail!(
                "{} chunk tops for a {}x{} world of {chunks} chunks",
                tops.len(),
                size.0,
                size.1
            );
        }
        Ok(RemoteChunks {
            size,
            mid_rule,
            tops,
            lod_levels,
            most_in_flight: most_in_flight.max(1),
            cache_pages: cache_pages.max(1),
            state: Mutex::new(State::default()),
        })
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().expect("remote pages")
    }

    /// Reads to begin now: the most wanted not yet started, up to the cap
    /// of reads in flight.
    pub fn start(&self) -> Vec<PageRef> {
        let mut s = self.state();
        let mut out = Vec::new();
        while s.started.len() < self.most_in_flight {
            let Some(page) = s.queue.pop_front() else {
                break;
            };
            s.started.insert(page.id, page);
            s.stats.started += 1;
            out.push(page);
        }
        s.stats.in_flight = s.started.len() as u32;
        out
    }

    /// Reads in flight that are no longer wanted (abort them; a late
    /// delivery of one is dropped).
    pub fn take_cancelled(&self) -> Vec<u32> {
        std::mem::take(&mut self.state().cancelled)
    }

    /// The result of read `page` (`bytes` fetched for it). Dropped when the
    /// read was cancelled meanwhile.
    pub fn deliver(&self, page: PageRef, result: Result<Planes, String>, bytes: u64) {
        let mut s = self.state();
        s.stats.bytes += bytes;
        if s.started.remove(&page.id).is_none() {
            return;
        }
        s.stats.in_flight = s.started.len() as u32;
        match &result {
            Ok(planes) => {
                s.stats.done += 1;
                s.tick += 1;
                let tick = s.tick;
                s.cache.insert(
                    (page.level, page.cx, page.cy),
                    (Arc::new(planes.clone()), tick),
                );
                if s.cache.len() > self.cache_pages
                    && let Some(oldest) = s.cache.iter().min_by_key(|(_, v)| v.1).map(|(k, _)| *k)
                {
                    s.cache.remove(&oldest);
                }
            }
            Err(_) => s.stats.failed += 1,
        }
        s.finished.push_back((page.id, result));
    }

    /// The planes of page (`cx`, `cy`) of `level` if read lately.
    pub fn cached(&self, level: u32, cx: u32, cy: u32) -> Option<Arc<Planes>> {
        let mut s = self.state();
        if let Some(p) = s.pinned.get(&(level, cx, cy)) {
            return Some(p.clone());
        }
        s.tick += 1;
        let tick = s.tick;
        let entry = s.cache.get_mut(&(level, cx, cy))?;
        entry.1 = tick;
        Some(entry.0.clone())
    }

    /// Keep `planes` as page (`cx`, `cy`) of `level` for good (read by the
    /// caller itself: the chunks under the world's views, where the viewer
    /// places its camera).
    pub fn pin(&self, level: u32, cx: u32, cy: u32, planes: Planes) {
        self.state()
            .pinned
            .insert((level, cx, cy), Arc::new(planes));
    }

    /// What the reads did so far.
    pub fn stats(&self) -> RemoteStats {
        self.state().stats
    }

    /// The planes of page (`cx`, `cy`) of `level`, from the cache.
    fn cached_or_error(&self, level: u32, cx: u32, cy: u32) -> Result<Arc<Planes>, String> {
        self.cached(level, cx, cy).ok_or_else(|| {
            let what = if level == 0 {
                format!("chunk ({cx}, {cy})")
            } else {
                format!("level-of-detail {level} page ({cx}, {cy})")
            };
            format!("{what} has not been fetched yet")
        })
    }
}

impl AsyncPages for RemoteChunks {
    fn want(&self, pages: &[PageRef]) {
        let mut s = self.state();
        let wanted: HashSet<u32> = pages.iter().map(|p| p.id).collect();
        let dropped: Vec<u32> = s
            .started
            .keys()
            .copied()
            .filter(|id| !wanted.contains(id))
            .collect();
        for id in dropped {
            s.started.remove(&id);
            s.cancelled.push(id);
            s.stats.cancelled += 1;
        }
        s.stats.in_flight = s.started.len() as u32;
        let done: HashSet<u32> = s.finished.iter().map(|f| f.0).collect();
        s.queue = pages
            .iter()
            .copied()
            .filter(|p| !s.started.contains_key(&p.id) && !done.contains(&p.id))
            .collect();
    }

    fn take_finished(&self, most: usize) -> Vec<(u32, Result<Planes, String>)> {
        let mut s = self.state();
        let n = most.min(s.finished.len());
        s.finished.drain(..n).collect()
    }

    fn in_flight(&self) -> usize {
        let s = self.state();
        s.queue.len() + s.started.len() + s.finished.len()
    }

    fn is_in_flight(&self, id: u32) -> bool {
        let s = self.state();
        s.started.contains_key(&id)
            || s.queue.iter().any(|p| p.id == id)
            || s.finished.iter().any(|f| f.0 == id)
    }
}

impl PageSource for RemoteChunks {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn mid_rule(&self) -> MidRule {
        self.mid_rule
    }

    fn chunk_tops(&self) -> Result<Vec<u8>, String> {
        Ok(self.tops.clone())
    }

    fn read_page(&self, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        self.read_lod_page(0, cx, cy, step)
    }

    fn lod_levels(&self) -> u32 {
        self.lod_levels
    }

    fn read_lod_page(&self, level: u32, cx: u32, cy: u32, step: u32) -> Result<PageData, String> {
        let p = self.cached_or_error(level, cx, cy)?;
        PageData::from_planes(&p.0, &p.1, self.mid_rule, step)
    }

    fn async_pages(&self) -> Option<&dyn AsyncPages> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{LevelPages, PageIds, Streamer};
    use super::*;

    /// A pump that reads from a world in memory, in the order it is told.
    fn planes_of(level: &strata_level::Level, cx: u32, cy: u32) -> Planes {
        let w = level.width() as usize;
        let (mut h, mut m) = (Vec::new(), Vec::new());
        for y in cy * PAGE..(cy + 1) * PAGE {
            let row = y as usize * w + (cx * PAGE) as usize;
            h.extend_from_slice(&level.heights()[row..row + PAGE as usize]);
            m.extend_from_slice(&level.metas()[row..row + PAGE as usize]);
        }
        (h, m)
    }

    #[test]
    fn the_streamer_drives_capped_cancellable_reads_to_the_same_pages() {
        let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 4,
            width: 1024,
            height: 512,
        })
        .unwrap();
        let level = Arc::new(world.level.clone());
        let whole = LevelPages::new(level.clone()).unwrap();
        let tops = whole.chunk_tops().unwrap();
        let remote = Arc::new(
            RemoteChunks::new((1024, 512), level.mid_rule, tops.clone(), 0, 3, 4).unwrap(),
        );
        assert!(RemoteChunks::new((1024, 512), level.mid_rule, vec![0; 3], 0, 3, 4).is_err());
        let ids = PageIds::new((4, 2), 0);
        let streamer = Streamer::new(remote.clone(), ids, 1, 0);
        streamer.want(&[5, 1, 2, 7, 0]);
        assert_eq!(streamer.in_flight(), 5);
        // The cap: three reads at a time, most wanted first.
        let first: Vec<u32> = remote.start().iter().map(|p| p.id).collect();
        assert_eq!(first, [5, 1, 2]);
        assert!(remote.start().is_empty(), "the cap holds");
        // The camera moves on: 1 and 7 are no longer wanted.
        streamer.want(&[5, 2, 0, 6]);
        let mut cancelled = remote.take_cancelled();
        cancelled.sort_unstable();
        assert_eq!(cancelled, [1]);
        let next: Vec<u32> = remote.start().iter().map(|p| p.id).collect();
        assert_eq!(next, [0], "one slot freed by the cancel");
        // Deliveries: a late one of the cancelled read is dropped; a failure
        // comes back as an error.
        let at = |id: u32| {
            let (_, cx, cy) = ids.locate(id).unwrap();
            PageRef {
                id,
                level: 0,
                cx,
                cy,
            }
        };
        remote.deliver(at(1), Ok(planes_of(&level, 1, 0)), 10);
        remote.deliver(at(2), Err("HTTP 500".into()), 20);
        for id in [5, 0] {
            let (_, cx, cy) = ids.locate(id).unwrap();
            remote.deliver(at(id), Ok(planes_of(&level, cx, cy)), 100);
        }
        let got = streamer.poll(64, 0.0);
        let order: Vec<u32> = got.iter().map(|g| g.0).collect();
        assert_eq!(order, [2, 5, 0]);
        assert_eq!(got[0].1.as_ref().unwrap_err(), "HTTP 500");
        for (id, page) in &got[1..] {
            let (_, cx, cy) = ids.locate(*id).unwrap();
            assert_eq!(page.as_ref().unwrap(), &whole.read_page(cx, cy, 1).unwrap());
        }
        let stats = remote.stats();
        assert_eq!(
            (
                stats.started,
                stats.done,
                stats.failed,
                stats.cancelled,
                stats.bytes
            ),
            (4, 2, 1, 1, 230)
        );
        // What was read is in the cache; what was not is a clear error.
        assert_eq!(
            remote.read_page(3, 1, 1).unwrap_err(),
            "chunk (3, 1) has not been fetched yet"
        );
        assert_eq!(
            remote.read_page(0, 0, 1).unwrap(),
            whole.read_page(0, 0, 1).unwrap()
        );
        // A failed page is wanted again: it is read again.
        streamer.want(&[2]);
        assert_eq!(remote.start().iter().map(|p| p.id).collect::<Vec<_>>(), [2]);
        assert!(streamer.is_in_flight(2));
    }
}
