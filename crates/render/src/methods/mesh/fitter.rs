//! The mesh's chunk fits, off the render thread: a queue of jobs, worker
//! threads that fit them, and finished fits handed back to the render thread.
//! Where there are no threads (a browser page), [`Fitter::poll`] fits on the
//! calling thread within a time budget, returning results the same way.
//!
//! Two kinds of job share the queue and the workers:
//! - the paged mesh's wanted chunks ([`Fitter::want`], replaced each frame,
//!   nearest first), whose workers read the pages a chunk's samples lie in
//!   from the [`PageSource`] (never the whole world);
//! - an edit's refits of the whole-world mesh ([`Fitter::push`]), each
//!   carrying a [`Patch`] of the edited level's samples it reads, taken when
//!   the edit was handed over, tagged with the edit's generation; a chunk
//!   queued again before its fit started keeps only the newer job.
//!
//! A chunk is fitted from a 256x256 [`Level`] holding its samples at the
//! origin ([`fit_chunk`]): a chunk's fit depends on its own
//! `(CHUNK + 1)²` samples alone (`strata_mesh::samples`), so the fit equals
//! that chunk of a whole-world fit (tested).

use super::pool::Fitted;
use crate::paged::{PAGE, PageSource};
use std::collections::{HashMap, VecDeque};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Condvar, Mutex};
use strata_level::Level;
use strata_mesh::{CHUNK, ChunkFitter, ChunkLayout, FitOptions, Patch};

/// A finished fit: the chunk, the epoch it was queued in, its generation
/// (0 for a wanted chunk) and its mesh.
type FitResult = (u32, u32, u64, Result<Fitted, String>);

/// A finished fit as [`Fitter::poll`] hands it back: the chunk, the
/// generation its job was pushed with (0 for a wanted chunk), its mesh.
pub type Finished = (u32, u64, Result<Fitted, String>);

/// What every fit is fitted with.
struct FitSpec {
    /// Where wanted chunks read their pages (`None`: jobs bring patches).
    source: Option<Arc<dyn PageSource>>,
    tolerance: f64,
    options: FitOptions,
}

/// One fit to run.
struct Job {
    chunk: u32,
    epoch: u32,
    generation: u64,
    /// The samples to fit (an edit's refit); `None`: read them from the
    /// source's pages.
    patch: Option<Patch>,
}

struct Queue {
    wanted: VecDeque<Job>,
    /// Jobs per chunk being fitted or fitted and not yet polled (an edited
    /// chunk may have more than one).
    busy: HashMap<u32, u32>,
    closed: bool,
}

struct Shared {
    queue: Mutex<Queue>,
    ready: Condvar,
}

/// The wanted-fit queue and its workers.
pub struct Fitter {
    spec: Arc<FitSpec>,
    shared: Arc<Shared>,
    done_tx: Sender<FitResult>,
    done: Receiver<FitResult>,
    workers: Vec<std::thread::JoinHandle<()>>,
    /// Fits queued before the current epoch are dropped (an edit changed
    /// their samples).
    epoch: u32,
    /// Pages decoded on the calling thread (no workers).
    cache: PlaneCache,
    /// The fit's scratch on the calling thread.
    chunk_fitter: ChunkFitter,
}

impl Fitter {
    /// Fit chunks of `source` (`None`: only pushed patches) at `tolerance`
    /// with `options` on `threads` worker threads (0: in [`Fitter::poll`]).
    pub fn new(
        source: Option<Arc<dyn PageSource>>,
        tolerance: f64,
        options: FitOptions,
        threads: usize,
    ) -> Self {
        let spec = Arc::new(FitSpec {
            source,
            tolerance,
            options,
        });
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue {
                wanted: VecDeque::new(),
                busy: HashMap::new(),
                closed: false,
            }),
            ready: Condvar::new(),
        });
        let (done_tx, done) = channel();
        let workers = (0..threads)
            .filter_map(|i| {
                let (shared, spec, tx) = (shared.clone(), spec.clone(), done_tx.clone());
                std::thread::Builder::new()
                    .name(format!("strata-fit-{i}"))
                    .spawn(move || worker(&shared, &spec, &tx))
                    .ok()
            })
            .collect();
        Fitter {
            spec,
            shared,
            done_tx,
            done,
            workers,
            epoch: 0,
            cache: PlaneCache::default(),
            chunk_fitter: ChunkFitter::default(),
        }
    }

    /// Make `chunks` (most wanted first) the queue; chunks being fitted stay.
    pub fn want(&self, chunks: &[u32]) {
        let mut q = self.shared.queue.lock().expect("fit queue");
        let wanted = chunks
            .iter()
            .filter(|c| !q.busy.contains_key(c))
            .map(|&chunk| Job {
                chunk,
                epoch: self.epoch,
                generation: 0,
                patch: None,
            })
            .collect();
        q.wanted = wanted;
        drop(q);
        self.shared.ready.notify_all();
    }

    /// Queue a fit of `patch` as chunk `chunk`, tagged `generation` (an
    /// edit's refit), behind the jobs queued already; a job of the same
    /// chunk still queued (not started) is replaced by this newer one.
    pub fn push(&self, chunk: u32, generation: u64, patch: Patch) {
        let job = Job {
            chunk,
            epoch: self.epoch,
            generation,
            patch: Some(patch),
        };
        let mut q = self.shared.queue.lock().expect("fit queue");
        match q.wanted.iter_mut().find(|j| j.chunk == chunk) {
            Some(queued) => *queued = job,
            None => q.wanted.push_back(job),
        }
        drop(q);
        self.shared.ready.notify_one();
    }

    /// Chunks queued, being fitted, or fitted and not yet polled.
    pub fn in_flight(&self) -> usize {
        let q = self.shared.queue.lock().expect("fit queue");
        q.wanted.len() + q.busy.values().sum::<u32>() as usize
    }

    /// Drop every fit queued or running (an edit changed samples they read).
    pub fn invalidate(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        self.cache = PlaneCache::default();
        self.shared.queue.lock().expect("fit queue").wanted.clear();
    }

    /// Finished fits of the current epoch, at most `most`. Without worker
    /// threads, first fits queued chunks here for up to `budget_ms` (at
    /// least one when any is queued; a chunk's fit is not split).
    pub fn poll(&mut self, most: usize, budget_ms: f64) -> Vec<Finished> {
        if self.workers.is_empty() {
            let start = web_time::Instant::now();
            while let Some(job) = take_job(&self.shared) {
                let done = run_job(&self.spec, job, &mut self.cache, &mut self.chunk_fitter);
                let _ = self.done_tx.send(done);
                if start.elapsed().as_secs_f64() * 1e3 >= budget_ms {
                    break;
                }
            }
        }
        let taken: Vec<FitResult> = self.done.try_iter().take(most).collect();
        self.finish(taken)
    }

    /// Block until at least one fit finishes (none queued or running: at
    /// once), then [`poll`](Self::poll) without a budget. Without worker
    /// threads, fits every queued job here.
    pub fn wait(&mut self, most: usize) -> Vec<Finished> {
        if self.workers.is_empty() {
            return self.poll(most, f64::INFINITY);
        }
        let mut taken = Vec::new();
        if self.in_flight() > 0
            && let Ok(first) = self.done.recv()
        {
            taken.push(first);
        }
        taken.extend(self.done.try_iter().take(most.saturating_sub(1)));
        self.finish(taken)
    }

    /// Mark `taken` no longer busy and keep those of the current epoch.
    fn finish(&self, taken: Vec<FitResult>) -> Vec<Finished> {
        let mut q = self.shared.queue.lock().expect("fit queue");
        for (chunk, ..) in &taken {
            if let Some(n) = q.busy.get_mut(chunk) {
                *n -= 1;
                if *n == 0 {
                    q.busy.remove(chunk);
                }
            }
        }
        drop(q);
        taken
            .into_iter()
            .filter(|(_, epoch, ..)| *epoch == self.epoch)
            .map(|(chunk, _, generation, fit)| (chunk, generation, fit))
            .collect()
    }

    /// Fit `chunk` now, on the calling thread (an edit's refit).
    pub fn fit_now(&mut self, chunk: u32) -> Result<Fitted, String> {
        self.cache = PlaneCache::default();
        fit_chunk(&self.spec, chunk, &mut self.cache, &mut self.chunk_fitter)
    }
}

impl Drop for Fitter {
    fn drop(&mut self) {
        self.shared.queue.lock().expect("fit queue").closed = true;
        self.shared.ready.notify_all();
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
    }
}

impl Queue {
    /// The next queued job, marked busy.
    fn pop(&mut self) -> Option<Job> {
        let job = self.wanted.pop_front()?;
        *self.busy.entry(job.chunk).or_insert(0) += 1;
        Some(job)
    }
}

/// The next queued job, marked busy.
fn take_job(shared: &Shared) -> Option<Job> {
    shared.queue.lock().expect("fit queue").pop()
}

/// Fit `job`: its patch, or its chunk from the source's pages.
fn run_job(
    spec: &FitSpec,
    job: Job,
    cache: &mut PlaneCache,
    fitter: &mut ChunkFitter,
) -> FitResult {
    let fit = match &job.patch {
        Some(patch) => Ok(fit_patch(spec, patch, fitter)),
        None => fit_chunk(spec, job.chunk, cache, fitter),
    };
    (job.chunk, job.epoch, job.generation, fit)
}

fn worker(shared: &Shared, spec: &FitSpec, done: &Sender<FitResult>) {
    let mut cache = PlaneCache::default();
    let mut cache_epoch = 0;
    let mut fitter = ChunkFitter::default();
    loop {
        let job = {
            let mut q = shared.queue.lock().expect("fit queue");
            loop {
                if q.closed {
                    return;
                }
                if let Some(job) = q.pop() {
                    break job;
                }
                q = shared.ready.wait(q).expect("fit queue");
            }
        };
        if job.epoch != cache_epoch {
            // An edit since: the cached pages may be old.
            (cache, cache_epoch) = (PlaneCache::default(), job.epoch);
        }
        if done
            .send(run_job(spec, job, &mut cache, &mut fitter))
            .is_err()
        {
            return;
        }
    }
}

/// A page's two planes: heights and metas, row-major.
type Planes = Arc<(Vec<u8>, Vec<u8>)>;

/// A few pages' planes, most recent last: neighbouring chunks, fitted
/// nearest first, share pages.
#[derive(Default)]
struct PlaneCache {
    pages: Vec<((u32, u32), Planes)>,
}

const PLANE_CACHE_PAGES: usize = 8;

impl PlaneCache {
    fn planes(&mut self, source: &dyn PageSource, page: (u32, u32)) -> Result<Planes, String> {
        if let Some(k) = self.pages.iter().position(|(p, _)| *p == page) {
            let hit = self.pages.remove(k);
            let planes = hit.1.clone();
            self.pages.push(hit);
            return Ok(planes);
        }
        let data = source.read_page(page.0, page.1, 2)?;
        let n = (PAGE * PAGE) as usize;
        let (mut heights, mut metas) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for p in data.pairs.chunks_exact(4) {
            heights.extend_from_slice(&[p[0], p[2]]);
            metas.extend_from_slice(&[p[1], p[3]]);
        }
        let planes = Arc::new((heights, metas));
        if self.pages.len() == PLANE_CACHE_PAGES {
            self.pages.remove(0);
        }
        self.pages.push((page, planes.clone()));
        Ok(planes)
    }
}

/// Side of the level a chunk is fitted from: its samples and the pair
/// neighbour of its last column, at the origin.
const FIT_SIDE: u32 = 256;

/// Mesh chunks across and down a world of `size` texels.
pub fn mesh_grid(size: (u32, u32)) -> (u32, u32) {
    (size.0 / CHUNK, size.1 / CHUNK)
}

/// Fit `patch` (its chunk at the origin) with its altitude range.
fn fit_patch(spec: &FitSpec, patch: &Patch, fitter: &mut ChunkFitter) -> Fitted {
    let mesh = patch.fit(fitter, spec.tolerance, spec.options);
    let z = super::z_range(&patch.level, &patch.layout, 0, &mesh);
    (mesh, z)
}

/// Fit mesh chunk `chunk` of `spec.source` from the pages its samples lie in.
fn fit_chunk(
    spec: &FitSpec,
    chunk: u32,
    cache: &mut PlaneCache,
    fitter: &mut ChunkFitter,
) -> Result<Fitted, String> {
    let source = spec
        .source
        .as_deref()
        .ok_or_else(|| format!("mesh chunk {chunk}: no pages to fit it from"))?;
    let (w, h) = source.size();
    let (across, down) = mesh_grid((w, h));
    if chunk >= across * down {
        return Err(format!("mesh chunk {chunk} is outside the world"));
    }
    let (x0, y0) = ((chunk % across) * CHUNK, (chunk / across) * CHUNK);
    let side = FIT_SIDE as usize;
    let (mut heights, mut metas) = (vec![0u8; side * side], vec![0u8; side * side]);
    // Samples 0..=CHUNK down; across also the pair neighbour of the last
    // column (a column is decoded with its pair).
    for y in 0..=CHUNK {
        let wy = (y0 + y) & (h - 1);
        let mut x = 0;
        while x < CHUNK + 2 {
            let wx = (x0 + x) & (w - 1);
            let page = (wx / PAGE, wy / PAGE);
            let planes = cache
                .planes(source, page)
                .map_err(|e| format!("mesh chunk {chunk}: page {page:?}: {e}"))?;
            // The rest of this page's row in one copy.
            let local = ((wy % PAGE) * PAGE + wx % PAGE) as usize;
            let run = (PAGE - wx % PAGE).min(CHUNK + 2 - x) as usize;
            let at = y as usize * side + x as usize;
            heights[at..at + run].copy_from_slice(&planes.0[local..local + run]);
            metas[at..at + run].copy_from_slice(&planes.1[local..local + run]);
            x += run as u32;
        }
    }
    let level = Level::from_planes(FIT_SIDE, FIT_SIDE, heights, metas, source.mid_rule())
        .map_err(|e| e.to_string())?;
    let layout = ChunkLayout::of(&level);
    Ok(fit_patch(spec, &Patch { level, layout }, fitter))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::paged::LevelPages;
    use strata_mesh::fit_chunks;

    #[test]
    fn a_chunk_fitted_from_its_pages_equals_the_whole_world_fit() {
        let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 5,
            width: 512,
            height: 512,
        })
        .unwrap();
        let level = Arc::new(world.level.clone());
        let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(level.clone()).unwrap());
        let tol = strata_mesh::tolerance_for_quality(0.5).unwrap();
        let layout = ChunkLayout::of(&level);
        // Chunks at the page's start and middle, and at the wrap edges.
        let ids = [0usize, 1, 3, 5, 12, 15];
        for outline in [false, true] {
            let options = FitOptions { outline };
            let whole = fit_chunks(&level, tol, options, &ids, 1);
            let spec = FitSpec {
                source: Some(source.clone()),
                tolerance: tol,
                options,
            };
            let mut cache = PlaneCache::default();
            let mut fitter = ChunkFitter::default();
            for (&i, want) in ids.iter().zip(&whole) {
                let (mesh, z) = fit_chunk(&spec, i as u32, &mut cache, &mut fitter).unwrap();
                assert_eq!(&mesh, want, "chunk {i} outline {outline}");
                assert_eq!(
                    z,
                    super::super::z_range(&level, &layout, i, want),
                    "chunk {i}"
                );
            }
        }
    }

    fn world(seed: u64) -> Level {
        strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed,
            width: 512,
            height: 512,
        })
        .unwrap()
        .level
    }

    /// Every fit `fitter` finishes, polled or waited for, by chunk.
    fn drain(fitter: &mut Fitter, wait: bool) -> Vec<Finished> {
        let mut all = Vec::new();
        while fitter.in_flight() > 0 {
            all.extend(if wait {
                fitter.wait(usize::MAX)
            } else {
                fitter.poll(usize::MAX, 1.0)
            });
        }
        all.sort_by_key(|(c, g, _)| (*c, *g));
        all
    }

    /// The no-thread seam (a browser page): fits run in `poll` within its
    /// budget and come back as the worker threads' do, equal to them.
    #[test]
    fn fits_on_the_calling_thread_equal_the_worker_threads() {
        let level = Arc::new(world(5));
        let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(level.clone()).unwrap());
        let tol = strata_mesh::tolerance_for_quality(0.5).unwrap();
        let options = FitOptions { outline: true };
        let wanted = [0u32, 3, 5, 12, 15];
        let mut results = Vec::new();
        for threads in [0, 2] {
            let mut fitter = Fitter::new(Some(source.clone()), tol, options, threads);
            fitter.want(&wanted);
            // No threads: a poll of a tiny budget fits at least one chunk
            // and leaves the rest queued.
            if threads == 0 {
                let first = fitter.poll(usize::MAX, 1e-6);
                assert_eq!(first.len(), 1);
                assert_eq!(fitter.in_flight(), wanted.len() - 1);
                let mut rest = drain(&mut fitter, false);
                rest.extend(first);
                rest.sort_by_key(|(c, g, _)| (*c, *g));
                results.push(rest);
            } else {
                results.push(drain(&mut fitter, true));
            }
        }
        let chunks: Vec<u32> = results[0].iter().map(|(c, ..)| *c).collect();
        assert_eq!(chunks, wanted);
        assert_eq!(results[0], results[1]);
        let ids: Vec<usize> = wanted.iter().map(|&c| c as usize).collect();
        let whole = fit_chunks(&level, tol, options, &ids, 1);
        for ((c, _, fit), want) in results[0].iter().zip(&whole) {
            assert_eq!(&fit.as_ref().unwrap().0, want, "chunk {c}");
        }
    }

    /// An edit's refits: a patch's fit is the edited level's chunk; a chunk
    /// pushed again before its fit started keeps only the newest job.
    #[test]
    fn pushed_patches_fit_the_edited_chunks_and_coalesce() {
        let (old, new) = (world(5), world(6));
        let layout = ChunkLayout::of(&new);
        let tol = strata_mesh::tolerance_for_quality(0.5).unwrap();
        for threads in [0, 1] {
            let mut fitter = Fitter::new(None, tol, FitOptions::default(), threads);
            let patch =
                |level: &Level, c: usize| Patch::read(level, &layout, layout.coords(c)).unwrap();
            if threads == 0 {
                fitter.push(7, 1, patch(&old, 7));
                fitter.push(2, 1, patch(&old, 2));
                fitter.push(7, 2, patch(&new, 7));
                assert_eq!(fitter.in_flight(), 2, "chunk 7's older job was replaced");
            } else {
                fitter.push(7, 2, patch(&new, 7));
                fitter.push(2, 1, patch(&old, 2));
            }
            let done = drain(&mut fitter, threads > 0);
            let got: Vec<(u32, u64)> = done.iter().map(|(c, g, _)| (*c, *g)).collect();
            assert_eq!(got, [(2, 1), (7, 2)]);
            for ((c, _, fit), level) in done.iter().zip([&old, &new]) {
                let c = *c as usize;
                let want = fit_chunks(level, tol, FitOptions::default(), &[c], 1).remove(0);
                let z = super::super::z_range(level, &layout, c, &want);
                assert_eq!(fit.as_ref().unwrap(), &(want, z), "chunk {c}");
            }
        }
    }
}
