//! Stores in a directory: telling a store from a Vangers world, creating
//! and opening one, and all-or-nothing edit batches through a journal.
//!
//! # The journal
//!
//! A batch of changed chunks is committed in five steps:
//! 1. the new chunk objects (both planes and the summary chunks they
//!    touch) are written under `DIR/.strata-journal/`, at the same keys as
//!    in the store, and each is fsynced;
//! 2. `manifest.json` (the keys) is written as `manifest.tmp`, fsynced;
//! 3. **commit point**: `manifest.tmp` is renamed to `manifest.json` and
//!    the journal directory fsynced;
//! 4. each object is renamed over its key in the store (one atomic rename
//!    per object), the touched directories fsynced;
//! 5. the journal is removed.
//!
//! Opening a store first looks for a journal: with a `manifest.json` it is
//! replayed (step 4 for the objects still in the journal; renaming is
//! idempotent), without one it is discarded. After a crash at any moment
//! a reopened store is therefore the state before the batch or after it.

use crate::error::StoreError;
use crate::format::{ChunkSummary, HEIGHTS, Layout, METAS, SUMMARY};
use crate::lod::lod_name;
use crate::store::{Chunk, Storage, StoreArray, WorldStore, write_cell};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use strata_level::edit::DirtyRect;
use strata_level::{Level, LevelError, MidRule, World, io};
use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;

/// The file at the root of every Zarr v3 store.
pub const ZARR_JSON: &str = "zarr.json";
/// The journal's directory inside a store.
pub const JOURNAL: &str = ".strata-journal";
const MANIFEST: &str = "manifest.json";
const MANIFEST_TMP: &str = "manifest.tmp";

/// What a world directory holds, by its files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirKind {
    /// A Zarr v3 store (`zarr.json`).
    Store,
    /// A Vangers world (`world.ini`).
    Vangers,
}

/// Tell a store from a Vangers world by the files (`zarr.json` vs
/// `world.ini`); neither is an error that names both.
pub fn dir_kind(dir: &Path) -> Result<DirKind, StoreError> {
    if dir.join(ZARR_JSON).is_file() {
        Ok(DirKind::Store)
    } else if dir.join(io::WORLD_INI).is_file() {
        Ok(DirKind::Vangers)
    } else {
        Err(StoreError::NotAStore { path: dir.into() })
    }
}

/// Load the world in `dir`, a Vangers world or a store, whichever it is.
pub fn load_any(dir: &Path, mid_rule: MidRule) -> Result<World, StoreError> {
    match dir_kind(dir)? {
        DirKind::Vangers => Ok(io::load_world(dir, mid_rule)?),
        DirKind::Store => DirStore::open(dir)?.store().read_world(mid_rule),
    }
}

/// A store in a directory.
#[derive(Debug)]
pub struct DirStore {
    dir: PathBuf,
    store: Arc<WorldStore>,
}

fn fs_storage(dir: &Path) -> Result<Storage, StoreError> {
    let store = FilesystemStore::new(dir)
        .map_err(|e| StoreError::Invalid(format!("{}: {e}", dir.display())))?;
    Ok(Arc::new(store))
}

fn sync_path(path: &Path) -> Result<(), StoreError> {
    File::open(path)
        .and_then(|f| f.sync_all())
        .map_err(|e| StoreError::io(path, e))
}

/// Test hook: with `STRATA_STORE_CRASH_AT=N`, the process aborts at the
/// N-th step of commits (counted over the process), so tests can stop it
/// at an exact point as well as at random times.
fn crash_point() {
    use std::sync::atomic::{AtomicU64, Ordering};
    static STEP: AtomicU64 = AtomicU64::new(0);
    if let Some(at) = std::env::var("STRATA_STORE_CRASH_AT")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        && STEP.fetch_add(1, Ordering::SeqCst) + 1 == at
    {
        std::process::abort();
    }
}

impl DirStore {
    /// Open the store in `dir` (replaying a committed journal, discarding
    /// an uncommitted one) and check it.
    pub fn open(dir: &Path) -> Result<Self, StoreError> {
        if !dir.join(ZARR_JSON).is_file() {
            return Err(StoreError::NotAStore { path: dir.into() });
        }
        recover(dir)?;
        let store = WorldStore::open(fs_storage(dir)?, &dir.display().to_string())?;
        Ok(DirStore {
            dir: dir.into(),
            store: Arc::new(store),
        })
    }

    /// Write `world` as a new store at `dir` (which must not exist or be
    /// empty): written into a sibling temporary directory, renamed into place.
    pub fn create(dir: &Path, world: &World, layout: &Layout) -> Result<Self, StoreError> {
        Self::create_in(dir, &|storage, what| {
            WorldStore::create(storage, world, layout, what)
        })
    }

    /// Write a world chunk by chunk as a new store at `dir` (see
    /// [`WorldStore::create_with`]; same rules as [`Self::create`]).
    pub fn create_with(
        dir: &Path,
        world: &World,
        (width, height): (u32, u32),
        layout: &Layout,
        chunk: &crate::store::ChunkFn<'_>,
    ) -> Result<Self, StoreError> {
        Self::create_in(dir, &|storage, what| {
            WorldStore::create_with(storage, world, width, height, layout, what, chunk)
        })
    }

    fn create_in(
        dir: &Path,
        write: &dyn Fn(Storage, &str) -> Result<WorldStore, StoreError>,
    ) -> Result<Self, StoreError> {
        if dir.exists() {
            let empty = dir.is_dir()
                && std::fs::read_dir(dir)
                    .map_err(|e| StoreError::io(dir, e))?
                    .next()
                    .is_none();
            if !empty {
                return Err(StoreError::Invalid(format!(
                    "{}: exists and is not an empty directory; refusing to write a store there",
                    dir.display()
                )));
            }
            std::fs::remove_dir(dir).map_err(|e| StoreError::io(dir, e))?;
        }
        let name = dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .ok_or_else(|| StoreError::Invalid(format!("{}: names no directory", dir.display())))?;
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|e| StoreError::io(&parent, e))?;
        let temp = parent.join(format!(".{name}.creating-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&temp);
        std::fs::create_dir_all(&temp).map_err(|e| StoreError::io(&temp, e))?;
        let made = write(fs_storage(&temp)?, &dir.display().to_string());
        if let Err(e) = made {
            let _ = std::fs::remove_dir_all(&temp);
            return Err(e);
        }
        std::fs::rename(&temp, dir).map_err(|e| StoreError::io(dir, e))?;
        Self::open(dir)
    }

    /// Write the store's level-of-detail levels (replacing any; see
    /// [`crate::lod`]) and open it again. `progress(k, levels)` after each.
    pub fn build_lods(dir: &Path, progress: &dyn Fn(u32, u32)) -> Result<Self, StoreError> {
        let opened = Self::open(dir)?;
        drop(opened);
        let mut store = WorldStore::open(fs_storage(dir)?, &dir.display().to_string())?;
        store.build_lods(progress)?;
        Self::open(dir)
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The store (shared, e.g. with a [`crate::ChunkCache`]).
    pub fn store(&self) -> &Arc<WorldStore> {
        &self.store
    }

    /// Write the chunks of `level` that `rects` touch, all or nothing (see
    /// the module docs). Returns the chunks written.
    pub fn commit_rects(
        &self,
        level: &Level,
        rects: &[DirtyRect],
    ) -> Result<Vec<(u64, u64)>, StoreError> {
        let (ch, cw) = self.store.chunk_shape();
        if (level.width(), level.height()) != (self.store.width(), self.store.height()) {
            return Err(StoreError::Invalid(format!(
                "a {}x{} level cannot be saved into a {}x{} store",
                level.width(),
                level.height(),
                self.store.width(),
                self.store.height()
            )));
        }
        let mut cells = Vec::new();
        for r in rects.iter().filter(|r| r.width > 0 && r.height > 0) {
            for cy in r.y / ch..=(r.y + r.height - 1) / ch {
                for cx in r.x / cw..=(r.x + r.width - 1) / cw {
                    cells.push((u64::from(cy), u64::from(cx)));
                }
            }
        }
        cells.sort_unstable();
        cells.dedup();
        let chunks: Vec<_> = cells
            .iter()
            .map(|&(cy, cx)| (cy, cx, self.store.chunk_of_level(level, cy, cx)))
            .collect();
        self.commit_chunks(&chunks)?;
        Ok(cells)
    }

    /// Write whole chunks, all or nothing (see the module docs).
    pub fn commit_chunks(&self, chunks: &[(u64, u64, Chunk)]) -> Result<(), StoreError> {
        if chunks.is_empty() {
            return Ok(());
        }
        let store = &self.store;
        let journal = self.dir.join(JOURNAL);
        if journal.exists() {
            std::fs::remove_dir_all(&journal).map_err(|e| StoreError::io(&journal, e))?;
        }
        std::fs::create_dir_all(&journal).map_err(|e| StoreError::io(&journal, e))?;
        let jstorage = fs_storage(&journal)?;
        let twin = |array: &StoreArray, name: &str| -> Result<StoreArray, StoreError> {
            Array::new_with_metadata(
                jstorage.clone(),
                &format!("/{name}"),
                array.metadata().clone(),
            )
            .map_err(|e| StoreError::array(name, e))
        };
        let (jh, jm, js) = (
            twin(&store.heights, HEIGHTS)?,
            twin(&store.metas, METAS)?,
            twin(&store.summary, SUMMARY)?,
        );
        // Summaries: the store's, with the batch's chunks recomputed.
        let mut all = store.summaries()?;
        let (_, gx) = store.grid();
        let mut keys = Vec::new();
        for (cy, cx, chunk) in chunks {
            store.write_chunk_into(&jh, &jm, *cy, *cx, chunk)?;
            crash_point();
            all[(cy * gx + cx) as usize] = ChunkSummary::of(
                &chunk.heights,
                &chunk.metas,
                chunk.cols as usize,
                MidRule::Original,
            );
            keys.push(store.heights.chunk_key(&[*cy, *cx]).to_string());
            keys.push(store.metas.chunk_key(&[*cy, *cx]).to_string());
        }
        // The coarse levels over the batch's chunks, in the same batch.
        for (k, cy, cx, chunk) in store.lod_updates(chunks)? {
            let (lh, lm) = store.lod_arrays(k);
            let (jlh, jlm) = (
                twin(lh, &lod_name(k, HEIGHTS))?,
                twin(lm, &lod_name(k, METAS))?,
            );
            write_cell(&jlh, &lod_name(k, HEIGHTS), &[cy, cx], &chunk.heights)?;
            write_cell(&jlm, &lod_name(k, METAS), &[cy, cx], &chunk.metas)?;
            crash_point();
            keys.push(lh.chunk_key(&[cy, cx]).to_string());
            keys.push(lm.chunk_key(&[cy, cx]).to_string());
        }
        let cells: Vec<(u64, u64)> = chunks.iter().map(|&(y, x, _)| (y, x)).collect();
        for idx in store.write_summaries_into(&js, &all, Some(&cells))? {
            keys.push(store.summary.chunk_key(&idx).to_string());
        }
        for key in &keys {
            sync_path(&journal.join(key))?;
        }
        crash_point();
        let tmp = journal.join(MANIFEST_TMP);
        let text = serde_json::to_vec(&keys).expect("keys serialise");
        std::fs::write(&tmp, text).map_err(|e| StoreError::io(&tmp, e))?;
        sync_path(&tmp)?;
        crash_point();
        let manifest = journal.join(MANIFEST);
        std::fs::rename(&tmp, &manifest).map_err(|e| StoreError::io(&manifest, e))?;
        sync_path(&journal)?;
        crash_point();
        apply_journal(&self.dir, &keys)
    }
}

/// Step 4 and 5: move the journal's objects into the store, remove the journal.
fn apply_journal(dir: &Path, keys: &[String]) -> Result<(), StoreError> {
    let journal = dir.join(JOURNAL);
    let mut parents = Vec::new();
    for key in keys {
        let from = journal.join(key);
        let to = dir.join(key);
        if from.exists() {
            if let Some(p) = to.parent() {
                std::fs::create_dir_all(p).map_err(|e| StoreError::io(p, e))?;
                parents.push(p.to_path_buf());
            }
            std::fs::rename(&from, &to).map_err(|e| StoreError::io(&to, e))?;
            crash_point();
        }
    }
    parents.sort();
    parents.dedup();
    for p in &parents {
        sync_path(p)?;
    }
    std::fs::remove_dir_all(&journal).map_err(|e| StoreError::io(&journal, e))?;
    sync_path(dir)
}

/// On open: replay a committed journal, discard an uncommitted one.
fn recover(dir: &Path) -> Result<(), StoreError> {
    let journal = dir.join(JOURNAL);
    if !journal.exists() {
        return Ok(());
    }
    let manifest = journal.join(MANIFEST);
    if manifest.is_file() {
        let bytes = std::fs::read(&manifest).map_err(|e| StoreError::io(&manifest, e))?;
        let keys: Vec<String> = serde_json::from_slice(&bytes).map_err(|e| {
            StoreError::Invalid(format!(
                "{}: a committed journal that does not parse: {e}",
                manifest.display()
            ))
        })?;
        if keys.iter().any(|k| k.contains("..") || k.starts_with('/')) {
            return Err(StoreError::Invalid(format!(
                "{}: a journal key leaves the store",
                manifest.display()
            )));
        }
        apply_journal(dir, &keys)
    } else {
        std::fs::remove_dir_all(&journal).map_err(|e| StoreError::io(&journal, e))
    }
}

/// Convert a Vangers world directory into a store (or copy a store).
pub fn to_store(src: &Path, dst: &Path, layout: &Layout) -> Result<DirStore, StoreError> {
    let world = load_any(src, MidRule::Original)?;
    DirStore::create(dst, &world, layout)
}

/// Convert a store (or a Vangers world) into a Vangers world directory.
pub fn to_vangers(src: &Path, dst: &Path) -> Result<(), StoreError> {
    let world = load_any(src, MidRule::Original)?;
    strata_level::save::save_world(dst, &world, &strata_level::save::SavePolicy::default())
        .map(|_| ())
        .map_err(|e: LevelError| e.into())
}
