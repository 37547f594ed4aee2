//! An edit's refits of the whole-world mesh, off the frame (issue 35).
//!
//! [`Refits::push`] takes a batch's dirty chunks: each chunk's samples are
//! copied out of the edited level (a [`Patch`]: the chunk's `129²` samples
//! and a column, not the level) and queued on the mesh's [`Fitter`]
//! workers, tagged with the batch's generation; a chunk dirtied again
//! before its fit started keeps only the newest job. [`Refits::upload`]
//! (each frame's `prepare`) writes finished fits into the index pool without
//! waiting, at most [`FITS_PER_FRAME`] a frame, and never a fit older than
//! the one its slot holds. Until then the slot keeps its old triangulation,
//! whose vertices read the edited texture: the frame shows the new
//! altitudes at the old vertices. [`Refits::upload`] with `settle` waits
//! for every outstanding refit (the protocol's checks against a fresh build).

use super::fitter::{Finished, Fitter};
use super::paged::{FIT_BUDGET_MS, FITS_PER_FRAME, refit_threads};
use super::pool::{IndexPool, Slot};
use crate::frame::Shared;
use std::collections::HashMap;
use strata_level::Level;
use strata_mesh::{ChunkLayout, FitOptions, Patch};

pub struct Refits {
    fitter: Fitter,
    /// Batches handed over so far: the newest batch's generation.
    serial: u64,
    /// Per chunk with a refit outstanding: its newest job's generation.
    newest: HashMap<u32, u64>,
    /// Per edited chunk: the generation of the fit its slot holds.
    shown: HashMap<u32, u64>,
    /// Per chunk with a refit outstanding: the batches that dirtied it since
    /// the fit its slot holds, oldest first.
    unshown: HashMap<u32, Vec<u64>>,
}

impl Refits {
    /// Refits at `tolerance` with `options` on [`refit_threads`] workers.
    pub fn new(tolerance: f64, options: FitOptions) -> Self {
        Self::with_threads(tolerance, options, refit_threads())
    }

    /// [`Refits::new`] on `threads` workers (0: fits run in
    /// [`Refits::upload`] within [`FIT_BUDGET_MS`], as in a browser page).
    pub fn with_threads(tolerance: f64, options: FitOptions, threads: usize) -> Self {
        Refits {
            fitter: Fitter::new(None, tolerance, options, threads),
            serial: 0,
            newest: HashMap::new(),
            shown: HashMap::new(),
            unshown: HashMap::new(),
        }
    }

    /// Queue one batch's dirty chunks `ids` (of `layout`) of the edited
    /// `level`: copies of their samples, no fit.
    pub fn push(
        &mut self,
        level: &Level,
        layout: &ChunkLayout,
        ids: &[usize],
    ) -> anyhow::Result<()> {
        self.serial += 1;
        for &i in ids {
            let patch = Patch::read(level, layout, layout.coords(i))
                .map_err(|e| anyhow::anyhow!("mesh chunk {i}: {e}"))?;
            let chunk = i as u32;
            self.fitter.push(chunk, self.serial, patch);
            self.newest.insert(chunk, self.serial);
            self.unshown.entry(chunk).or_default().push(self.serial);
        }
        Ok(())
    }

    /// Write finished refits into `pool`: those done now (fitting here
    /// within [`FIT_BUDGET_MS`] where there are no workers), or with
    /// `settle` every outstanding one, waiting for them.
    pub fn upload(
        &mut self,
        shared: &Shared,
        (pool, slots): (&mut IndexPool, &mut [Slot]),
        settle: bool,
    ) -> anyhow::Result<()> {
        while !self.newest.is_empty() {
            let done = if settle {
                self.fitter.wait(usize::MAX)
            } else {
                self.fitter.poll(FITS_PER_FRAME, FIT_BUDGET_MS)
            };
            if settle && done.is_empty() && self.fitter.in_flight() == 0 {
                anyhow::bail!(
                    "{} mesh chunks wait for a refit that is not queued",
                    self.newest.len()
                );
            }
            self.place(shared, (pool, slots), done)?;
            if !settle {
                break;
            }
        }
        Ok(())
    }

    fn place(
        &mut self,
        shared: &Shared,
        (pool, slots): (&mut IndexPool, &mut [Slot]),
        done: Vec<Finished>,
    ) -> anyhow::Result<()> {
        for (chunk, generation, fit) in done {
            let (mesh, z) =
                fit.map_err(|e| anyhow::anyhow!("refitting mesh chunk {chunk}: {e}"))?;
            if self.shown.get(&chunk).is_some_and(|&g| g >= generation) {
                // A newer fit of this chunk finished first.
                continue;
            }
            let slot = slots
                .get_mut(chunk as usize)
                .ok_or_else(|| anyhow::anyhow!("refitted mesh chunk {chunk} has no slot"))?;
            pool.replace(&shared.device, &shared.queue, slot, &mesh, z);
            self.shown.insert(chunk, generation);
            if let Some(batches) = self.unshown.get_mut(&chunk) {
                batches.retain(|&b| b > generation);
                if batches.is_empty() {
                    self.unshown.remove(&chunk);
                }
            }
            if self.newest.get(&chunk) == Some(&generation) {
                self.newest.remove(&chunk);
            }
        }
        Ok(())
    }

    /// How many of the latest batches the pool does not yet show in full
    /// (0: every batch handed over is drawn).
    pub fn pending(&self) -> u64 {
        self.unshown
            .values()
            .filter_map(|b| b.first())
            .min()
            .map_or(0, |&oldest| self.serial + 1 - oldest)
    }
}
