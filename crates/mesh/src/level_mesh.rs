//! The whole level: every chunk fitted in parallel, exact local refit after
//! edits, and the level-wide statistics `strata fit` reports.

use web_time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use strata_level::{DirtyRect, Level};

use crate::emit::ChunkMesh;
use crate::fit::{
    CAUSES, ChunkFitter, FitOptions, LODS, OutlinePart, OutlinePartFit, join_outline_parts,
};
use crate::samples::ChunkLayout;

/// Max vertical error for quality `q` in [0, 1]: `2^(4(1 - q))` height
/// units (q 0 → 16, 0.5 → 4, 1 → 1). `None` outside [0, 1] or for NaN.
pub fn tolerance_for_quality(q: f64) -> Option<f64> {
    (0.0..=1.0).contains(&q).then(|| (4.0 * (1.0 - q)).exp2())
}

/// The fitted mesh of a level: one [`ChunkMesh`] per chunk, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LevelMesh {
    /// Chunk size and counts of the level fitted.
    pub layout: ChunkLayout,
    /// Finest-LOD max error as `f64` bits (so the mesh is `Eq`); read it
    /// with [`LevelMesh::tolerance`]. LOD k has `tolerance · 2^k`.
    pub tolerance_bits: u64,
    /// How it was fitted (a refit fits the same way).
    pub options: FitOptions,
    /// One mesh per chunk, row-major ([`ChunkLayout::index`]).
    pub chunks: Vec<ChunkMesh>,
}

impl LevelMesh {
    /// Finest-LOD max vertical error, height units.
    pub fn tolerance(&self) -> f64 {
        f64::from_bits(self.tolerance_bits)
    }

    /// Fit every chunk of `level` at finest max error `tolerance` (> 0),
    /// in parallel on the current rayon pool. The result does not depend on
    /// the number of threads: chunks are independent and collected in order.
    pub fn fit(level: &Level, tolerance: f64) -> Self {
        Self::fit_with_progress(level, tolerance, &|_, _| {})
    }

    /// [`fit`](Self::fit), calling `progress(chunks done, chunks)` as chunks
    /// finish (from the fitting threads, in no particular order).
    pub fn fit_with_progress(
        level: &Level,
        tolerance: f64,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        Self::fit_with_options(level, tolerance, FitOptions::default(), progress)
    }

    /// [`fit_with_progress`](Self::fit_with_progress) with `options` (e.g.
    /// the outline-constrained fit).
    pub fn fit_with_options(
        level: &Level,
        tolerance: f64,
        options: FitOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        let layout = ChunkLayout::of(level);
        let tol = sanitize(tolerance);
        let total = layout.count();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let chunks = (0..total)
            .into_par_iter()
            .map_init(ChunkFitter::default, |f, i| {
                let (cx, cy) = layout.coords(i);
                let mesh = f.fit_with(level, &layout, cx, cy, tol, options);
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(n, total);
                mesh
            })
            .collect();
        LevelMesh {
            layout,
            tolerance_bits: tol.to_bits(),
            options,
            chunks,
        }
    }

    /// Start a fit that runs a few chunks at a time on the calling thread
    /// ([`FitInSteps::step`]): a browser page has one thread and must give
    /// it back between frames. The finished mesh equals [`fit`](Self::fit)'s.
    pub fn fit_in_steps(level: &Level, tolerance: f64) -> FitInSteps {
        Self::fit_in_steps_with(level, tolerance, FitOptions::default())
    }

    /// [`fit_in_steps`](Self::fit_in_steps) with `options`.
    pub fn fit_in_steps_with(level: &Level, tolerance: f64, options: FitOptions) -> FitInSteps {
        let layout = ChunkLayout::of(level);
        FitInSteps {
            layout,
            tolerance: sanitize(tolerance),
            options,
            fitter: ChunkFitter::default(),
            chunks: Vec::with_capacity(layout.count()),
        }
    }

    /// Refit every chunk whose samples intersect `dirty` from scratch, so the
    /// result equals a fresh [`fit`](Self::fit) of the edited level. Returns
    /// the indices (ascending) of the chunks whose mesh actually changed.
    pub fn refit(&mut self, level: &Level, dirty: &[DirtyRect]) -> Vec<usize> {
        let layout = ChunkLayout::of(level);
        if layout != self.layout {
            // A different map size: nothing local survives.
            *self = Self::fit_with_options(level, self.tolerance(), self.options, &|_, _| {});
            return (0..self.chunks.len()).collect();
        }
        let ids = dirty_chunks(&layout, level.width(), level.height(), dirty);
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let fresh = fit_chunks(level, self.tolerance(), self.options, &ids, threads);
        let mut changed = Vec::new();
        for (&i, mesh) in ids.iter().zip(fresh) {
            // Compared by content hash, so this works after
            // [`release_indices`](Self::release_indices) too.
            let old = &self.chunks[i].stats;
            if (old.hash, old.indices) != (mesh.stats.hash, mesh.stats.indices) {
                self.chunks[i] = mesh;
                changed.push(i);
            }
        }
        changed
    }

    /// Drop the CPU copies of the index lists (after uploading them); the
    /// statistics and content hashes stay, and a later refit fills in the
    /// chunks it changes. The fit itself needs nothing else: it refits from
    /// the level.
    pub fn release_indices(&mut self) {
        for c in &mut self.chunks {
            c.indices = Vec::new();
        }
    }

    /// Level-wide totals.
    pub fn stats(&self) -> MeshStats {
        let mut s = MeshStats {
            tolerance: self.tolerance(),
            ..MeshStats::default()
        };
        for c in &self.chunks {
            s.add_chunk(c);
        }
        s
    }
}

impl MeshStats {
    /// Count one more chunk's mesh in (for fits that keep only totals,
    /// e.g. a store's region fitted in bounded memory).
    pub fn add_chunk(&mut self, c: &ChunkMesh) {
        self.chunks += 1;
        self.planar_vertices += u64::from(c.stats.planar_vertices);
        self.gpu_indices += u64::from(c.stats.indices);
        for k in 0..LODS {
            let l = &c.stats.lods[k];
            self.lods[k].planar += u64::from(l.planar);
            self.lods[k].slab += u64::from(l.slab);
            self.lods[k].wall += u64::from(l.wall);
            self.lods[k].border_walls += u64::from(l.border_walls);
            self.lods[k].emitted += u64::from(l.emitted());
        }
        for k in 0..CAUSES {
            self.causes[k] += u64::from(c.stats.causes[k]);
        }
        self.gpu_bytes = self.gpu_indices * 2;
        self.cpu_bytes = (self.chunks * std::mem::size_of::<ChunkRange>()) as u64;
    }
}

/// A fit in progress, chunk by chunk in order (see
/// [`LevelMesh::fit_in_steps`]).
pub struct FitInSteps {
    layout: ChunkLayout,
    tolerance: f64,
    options: FitOptions,
    fitter: ChunkFitter,
    chunks: Vec<ChunkMesh>,
}

impl FitInSteps {
    /// Fit chunks of `level` (the level the fit started on) until
    /// `keep_going()` says stop (asked after each chunk) or none is left;
    /// true once every chunk is fitted.
    pub fn step(&mut self, level: &Level, mut keep_going: impl FnMut() -> bool) -> bool {
        while self.chunks.len() < self.layout.count() {
            let (cx, cy) = self.layout.coords(self.chunks.len());
            let mesh =
                self.fitter
                    .fit_with(level, &self.layout, cx, cy, self.tolerance, self.options);
            self.chunks.push(mesh);
            if !keep_going() {
                break;
            }
        }
        self.is_done()
    }

    /// Whether every chunk is fitted.
    pub fn is_done(&self) -> bool {
        self.chunks.len() == self.layout.count()
    }

    /// Chunks fitted, of all.
    pub fn progress(&self) -> f32 {
        self.chunks.len() as f32 / self.layout.count().max(1) as f32
    }

    /// The mesh, once [`is_done`](Self::is_done) (`None` before).
    pub fn finish(self) -> Option<LevelMesh> {
        self.is_done().then(|| LevelMesh {
            layout: self.layout,
            tolerance_bits: self.tolerance.to_bits(),
            options: self.options,
            chunks: self.chunks,
        })
    }
}

/// What the renderer keeps on the CPU per chunk once the buffers are
/// uploaded: where its data lives and its LOD ranges. (`cpu_bytes` counts
/// this table; a [`LevelMesh`] after [`LevelMesh::release_indices`] keeps
/// about the same: per-chunk statistics and hashes.) The fit itself is not retained — a refit
/// recomputes the dirty chunks from the level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChunkRange {
    /// First index of the chunk in an index buffer holding every chunk's list.
    pub first_index: u32,
    /// Number of indices of the chunk (all LODs).
    pub index_count: u32,
    /// [`ChunkMesh::lods`], relative to `first_index`.
    pub lods: [[(u32, u32); 2]; LODS],
}

fn sanitize(tol: f64) -> f64 {
    if tol.is_finite() && tol > 0.0 {
        tol
    } else {
        1.0
    }
}

/// Fit chunks `ids` of `level` from scratch on up to `threads` threads
/// (scoped threads, none when `threads` is 1), in `ids` order: what an
/// edit's refit runs. The outline fit's two triangulations of a chunk are
/// independent and run as two jobs, so a crater over a few chunks waits for
/// the slower half of the slowest chunk, not the whole of it.
pub fn fit_chunks(
    level: &Level,
    tolerance: f64,
    options: FitOptions,
    ids: &[usize],
    threads: usize,
) -> Vec<ChunkMesh> {
    let layout = ChunkLayout::of(level);
    let tol = sanitize(tolerance);
    enum Done {
        Whole(ChunkMesh),
        Part(Box<OutlinePartFit>),
    }
    let parts: &[Option<OutlinePart>] = if options.outline {
        &[Some(OutlinePart::Floor), Some(OutlinePart::Slab)]
    } else {
        &[None]
    };
    let jobs: Vec<(usize, Option<OutlinePart>)> = ids
        .iter()
        .flat_map(|&i| parts.iter().map(move |&p| (i, p)))
        .collect();
    // Thread `t` of `n` takes jobs t, t + n, ..: a chunk's two parts go to
    // two threads whenever there are two.
    let run = |t: usize, n: usize| -> Vec<Done> {
        let mut fitter = ChunkFitter::default();
        jobs.iter()
            .skip(t)
            .step_by(n)
            .map(|&(i, part)| {
                let (cx, cy) = layout.coords(i);
                match part {
                    None => Done::Whole(fitter.fit_with(level, &layout, cx, cy, tol, options)),
                    Some(p) => Done::Part(Box::new(fitter.fit_outline_part(
                        level,
                        &layout,
                        (cx, cy),
                        tol,
                        p,
                    ))),
                }
            })
            .collect()
    };
    let n = threads.clamp(1, jobs.len().max(1));
    let mut by_thread: Vec<std::vec::IntoIter<Done>> = if n < 2 {
        vec![run(0, 1).into_iter()]
    } else {
        std::thread::scope(|s| {
            let run = &run;
            let handles: Vec<_> = (0..n).map(|t| s.spawn(move || run(t, n))).collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("chunk fit thread panicked").into_iter())
                .collect()
        })
    };
    // Back in job order: job k is thread k % n's next result.
    let mut done = (0..jobs.len()).filter_map(|k| by_thread[k % n].next());
    let mut meshes = Vec::with_capacity(ids.len());
    while let Some(first) = done.next() {
        meshes.push(match first {
            Done::Whole(mesh) => mesh,
            Done::Part(floor) => match done.next() {
                Some(Done::Part(slab)) => join_outline_parts(*floor, *slab),
                _ => unreachable!("an outline chunk's parts come in pairs"),
            },
        });
    }
    meshes
}

/// Chunks whose sample square (including the shared last row and column)
/// contains a texel of a dirty rectangle. A texel's column depends on its
/// pair partner, so rectangles are widened to whole pairs first.
pub fn dirty_chunks(
    layout: &ChunkLayout,
    width: u32,
    height: u32,
    dirty: &[DirtyRect],
) -> Vec<usize> {
    let mut mark = vec![false; layout.count()];
    let axis = |lo: i64, hi: i64, size: i64, n: i64| -> Vec<i64> {
        // Chunk c holds samples [c·size, c·size + size]: c from ceil(lo/size) - 1 to floor(hi/size).
        let first = (lo + size - 1).div_euclid(size) - 1;
        let last = hi.div_euclid(size);
        let mut cs: Vec<i64> = (first..=last).map(|c| c.rem_euclid(n)).collect();
        cs.sort_unstable();
        cs.dedup();
        cs
    };
    for r in dirty {
        if r.width == 0 || r.height == 0 {
            continue;
        }
        let x0 = i64::from(r.x.min(width - 1) & !1);
        let x1 = (i64::from(r.x) + i64::from(r.width) - 1).min(i64::from(width) - 1) | 1;
        let y0 = i64::from(r.y.min(height - 1));
        let y1 = (i64::from(r.y) + i64::from(r.height) - 1).min(i64::from(height) - 1);
        let xs = axis(x0, x1, i64::from(layout.size_x), i64::from(layout.chunks_x));
        let ys = axis(y0, y1, i64::from(layout.size_y), i64::from(layout.chunks_y));
        for &cy in &ys {
            for &cx in &xs {
                mark[layout.index(cx as u32, cy as u32)] = true;
            }
        }
    }
    mark.iter()
        .enumerate()
        .filter_map(|(i, &m)| m.then_some(i))
        .collect()
}

/// Per-LOD totals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LodTotals {
    /// Floor triangles ([`LodStats::planar`](crate::LodStats::planar)).
    pub planar: u64,
    /// Slab top + cave ceiling triangles.
    pub slab: u64,
    /// Wall triangles.
    pub wall: u64,
    /// Wall triangles on chunk borders (included in `wall`).
    pub border_walls: u64,
    /// Every triangle drawn: `planar + slab + wall`.
    pub emitted: u64,
}

/// Level-wide totals of a fit.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MeshStats {
    /// Number of chunks.
    pub chunks: usize,
    /// Finest-LOD max error, height units.
    pub tolerance: f64,
    /// Sum over chunks of finest planar vertices (border vertices counted in
    /// both chunks that share them, as they are uploaded).
    pub planar_vertices: u64,
    /// Indices of all chunks and LODs (each LOD-shared triangle once).
    pub gpu_indices: u64,
    /// Triangle totals per LOD (0 the finest).
    pub lods: [LodTotals; LODS],
    /// Insertions: floor, slab interior, single/double boundary, chunk border.
    pub causes: [u64; CAUSES],
    /// Bytes of the index buffers (`u16` indices; there is no vertex buffer).
    pub gpu_bytes: u64,
    /// Bytes the renderer keeps on the CPU: one [`ChunkRange`] per chunk.
    pub cpu_bytes: u64,
}

/// Fit `level` and time it (wall clock, current rayon pool).
pub fn timed_fit(level: &Level, tolerance: f64) -> (LevelMesh, f64) {
    timed_fit_with(level, tolerance, FitOptions::default())
}

/// [`timed_fit`] with `options`.
pub fn timed_fit_with(level: &Level, tolerance: f64, options: FitOptions) -> (LevelMesh, f64) {
    let t = Instant::now();
    let mesh = LevelMesh::fit_with_options(level, tolerance, options, &|_, _| {});
    (mesh, t.elapsed().as_secs_f64())
}

/// How long a fit took.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FitTiming {
    /// Worker threads of the pool the fit ran on.
    pub threads: usize,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// CPU time of all threads (the machine may be shared), where known.
    pub cpu_seconds: Option<f64>,
}

/// Fit on a pool of `threads` workers (0: one per core) and time it.
pub fn fit_on_threads(
    level: &Level,
    tolerance: f64,
    threads: usize,
) -> Result<(LevelMesh, FitTiming), rayon::ThreadPoolBuildError> {
    fit_on_threads_with(level, tolerance, threads, FitOptions::default())
}

/// [`fit_on_threads`] with `options`.
pub fn fit_on_threads_with(
    level: &Level,
    tolerance: f64,
    threads: usize,
    options: FitOptions,
) -> Result<(LevelMesh, FitTiming), rayon::ThreadPoolBuildError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    // Start the workers first so one CPU reading covers them all.
    pool.broadcast(|_| ());
    Ok(pool.install(|| {
        let cpu0 = crate::cpu_time::process_cpu_seconds();
        let (mesh, wall_seconds) = timed_fit_with(level, tolerance, options);
        let cpu_seconds = crate::cpu_time::process_cpu_seconds()
            .zip(cpu0)
            .map(|(b, a)| b - a);
        let timing = FitTiming {
            threads: rayon::current_num_threads(),
            wall_seconds,
            cpu_seconds,
        };
        (mesh, timing)
    }))
}
