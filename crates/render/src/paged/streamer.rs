//! Reading pages off the render thread: a queue of wanted chunks, replaced
//! each frame (chunks no longer wanted are dropped before they are read),
//! worker threads that read them through the [`PageSource`], and finished
//! pages handed back to the render thread to upload. Where there are no
//! threads (a browser page without workers), [`Streamer::poll`] reads on the
//! calling thread within a time budget, or, for a source whose reads
//! complete on their own ([`PageSource::async_pages`]: a browser's
//! fetches), hands the wanted pages to it and takes back what finished:
//! the one platform seam.

use super::pages::PageIds;
use super::source::{AsyncPages, PageData, PageRef, PageSource};
use std::collections::{HashSet, VecDeque};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Condvar, Mutex};

/// A finished read: the chunk and its page, or why it failed.
pub type PageResult = (u32, Result<PageData, String>);

struct Queue {
    wanted: VecDeque<u32>,
    /// Chunks a worker is reading now.
    reading: HashSet<u32>,
    /// Chunks read and handed over, not yet taken by [`Streamer::poll`]
    /// (still in flight: wanting them again would read them twice).
    finished: HashSet<u32>,
    closed: bool,
}

struct Shared {
    queue: Mutex<Queue>,
    ready: Condvar,
}

/// The wanted-chunk queue and its readers.
pub struct Streamer {
    source: Arc<dyn PageSource>,
    ids: PageIds,
    step: u32,
    shared: Arc<Shared>,
    done_tx: Sender<PageResult>,
    done: Receiver<PageResult>,
    workers: Vec<std::thread::JoinHandle<()>>,
}

impl Streamer {
    /// Read pages of `source` (ids `ids`, pyramids built with `step`) on
    /// `threads` worker threads; 0 reads in [`Streamer::poll`] instead.
    pub fn new(source: Arc<dyn PageSource>, ids: PageIds, step: u32, threads: usize) -> Self {
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue {
                wanted: VecDeque::new(),
                reading: HashSet::new(),
                finished: HashSet::new(),
                closed: false,
            }),
            ready: Condvar::new(),
        });
        let (done_tx, done) = channel();
        let workers = (0..threads)
            .filter_map(|i| {
                let (shared, source, tx) = (shared.clone(), source.clone(), done_tx.clone());
                std::thread::Builder::new()
                    .name(format!("strata-pages-{i}"))
                    .spawn(move || worker(&shared, source.as_ref(), ids, step, &tx))
                    .ok()
            })
            .collect();
        Streamer {
            source,
            ids,
            step,
            shared,
            done_tx,
            done,
            workers,
        }
    }

    /// Make `chunks` (most wanted first) the queue: earlier wants not in it
    /// are dropped unread; chunks being read stay being read.
    pub fn want(&self, chunks: &[u32]) {
        if let Some(reads) = self.async_reads() {
            let pages: Vec<PageRef> = chunks
                .iter()
                .filter_map(|&id| {
                    let (level, cx, cy) = self.ids.locate(id)?;
                    Some(PageRef { id, level, cx, cy })
                })
                .collect();
            reads.want(&pages);
            return;
        }
        let mut q = self.shared.queue.lock().expect("page queue");
        let wanted = chunks
            .iter()
            .copied()
            .filter(|c| !q.reading.contains(c) && !q.finished.contains(c))
            .collect();
        q.wanted = wanted;
        drop(q);
        self.shared.ready.notify_all();
    }

    /// Chunks queued or being read.
    pub fn in_flight(&self) -> usize {
        if let Some(reads) = self.async_reads() {
            return reads.in_flight();
        }
        let q = self.shared.queue.lock().expect("page queue");
        q.wanted.len() + q.reading.len() + q.finished.len()
    }

    /// Whether `chunk` is queued or being read.
    pub fn is_in_flight(&self, chunk: u32) -> bool {
        if let Some(reads) = self.async_reads() {
            return reads.is_in_flight(chunk);
        }
        let q = self.shared.queue.lock().expect("page queue");
        q.reading.contains(&chunk) || q.finished.contains(&chunk) || q.wanted.contains(&chunk)
    }

    /// Finished pages, at most `most`. Without worker threads, first reads
    /// queued chunks here for up to `budget_ms`.
    pub fn poll(&self, most: usize, budget_ms: f64) -> Vec<PageResult> {
        if let Some(reads) = self.async_reads() {
            let (rule, step) = (self.source.mid_rule(), self.step);
            return reads
                .take_finished(most)
                .into_iter()
                .map(|(id, planes)| {
                    let page = planes.and_then(|(h, m)| PageData::from_planes(&h, &m, rule, step));
                    (id, page)
                })
                .collect();
        }
        if self.workers.is_empty() {
            let start = web_time::Instant::now();
            while start.elapsed().as_secs_f64() * 1e3 < budget_ms {
                let next = {
                    let mut q = self.shared.queue.lock().expect("page queue");
                    let next = q.wanted.pop_front();
                    if let Some(c) = next {
                        q.finished.insert(c);
                    }
                    next
                };
                let Some(chunk) = next else { break };
                let _ = self.done_tx.send((
                    chunk,
                    read(self.source.as_ref(), self.ids, chunk, self.step),
                ));
            }
        }
        let taken: Vec<PageResult> = self.done.try_iter().take(most).collect();
        let mut q = self.shared.queue.lock().expect("page queue");
        for (chunk, _) in &taken {
            q.finished.remove(chunk);
        }
        taken
    }
}

impl Streamer {
    /// The source's own asynchronous reads, used where no worker thread runs.
    fn async_reads(&self) -> Option<&dyn AsyncPages> {
        if self.workers.is_empty() {
            self.source.async_pages()
        } else {
            None
        }
    }
}

impl Drop for Streamer {
    fn drop(&mut self) {
        self.shared.queue.lock().expect("page queue").closed = true;
        self.shared.ready.notify_all();
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

/// Read page `id` (of any level).
fn read(source: &dyn PageSource, ids: PageIds, id: u32, step: u32) -> Result<PageData, String> {
    let (level, cx, cy) = ids
        .locate(id)
        .ok_or_else(|| format!("page {id} is outside the world"))?;
    source.read_lod_page(level, cx, cy, step)
}

fn worker(
    shared: &Shared,
    source: &dyn PageSource,
    ids: PageIds,
    step: u32,
    done: &Sender<PageResult>,
) {
    loop {
        let chunk = {
            let mut q = shared.queue.lock().expect("page queue");
            loop {
                if q.closed {
                    return;
                }
                if let Some(c) = q.wanted.pop_front() {
                    q.reading.insert(c);
                    break c;
                }
                q = shared.ready.wait(q).expect("page queue");
            }
        };
        let page = read(source, ids, chunk, step);
        // Counted as finished before it is sent, so that `poll` (which
        // removes it from `finished`) never runs before the insert.
        {
            let mut q = shared.queue.lock().expect("page queue");
            q.reading.remove(&chunk);
            q.finished.insert(chunk);
        }
        if done.send((chunk, page)).is_err() {
            return;
        }
    }
}
