//! Saving the edited world (Ctrl+S, script `save DIR`) in the real file
//! format, through [`strata_level::save::save_world`]: a temporary
//! directory and renames, never over the loaded world without
//! `--overwrite`. Not available in a browser (no file system to write to).
//!
//! A world opened from a Strata store is saved as a store: in place (with
//! `--overwrite`) only the chunks edited since the last save are written,
//! all or nothing ([`strata_store::DirStore::commit_rects`]: the journal
//! makes a crash leave the store before or after the save, never between);
//! to another directory a new store is written whole, and later saves there
//! write only the chunks edited since. An existing store this session did
//! not write is never written into (that would mix two worlds).

use std::path::{Path, PathBuf};
use strata_level::save::SavePolicy;
use strata_level::{DirtyRect, Level, World};

/// Where saves go (`strata view --save-to DIR --overwrite`).
#[derive(Clone, Debug, Default)]
pub struct SaveOptions {
    /// The loaded world's directory and whether saving over it is allowed.
    pub policy: SavePolicy,
    /// Where Ctrl+S saves; default: the loaded world's directory with
    /// `--overwrite`, else `<out>/<world name>-edited`.
    pub dir: Option<PathBuf>,
}

/// The world's files besides the map, kept to write the edited map with.
pub struct Saver {
    /// The loaded world with a 2x1 stand-in for its level (the viewer's own
    /// copy of the level is the edited one).
    world: World,
    // Read only where there is a file system to save to.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    options: SaveOptions,
    /// Where Ctrl+S saves.
    pub default_dir: PathBuf,
    /// Stores this session may write edits into (native only).
    #[cfg(not(target_arch = "wasm32"))]
    stores: StoreTargets,
}

/// The stores a session saves into: the store it opened (when it opened
/// one) and those it wrote, each with the edits made since its last save.
#[cfg(not(target_arch = "wasm32"))]
#[derive(Default)]
struct StoreTargets {
    /// Whether the world was opened from a store (saves then write stores).
    opened_store: bool,
    /// Each store's directory (canonical) and the rectangles edited since
    /// it was last saved.
    known: Vec<(PathBuf, Vec<DirtyRect>)>,
}

#[cfg(not(target_arch = "wasm32"))]
impl StoreTargets {
    fn of(source: Option<&Path>) -> Self {
        let store = source.filter(|d| {
            matches!(
                strata_store::fs::dir_kind(d),
                Ok(strata_store::fs::DirKind::Store)
            )
        });
        StoreTargets {
            opened_store: store.is_some(),
            known: store
                .and_then(|d| d.canonicalize().ok())
                .map(|d| vec![(d, Vec::new())])
                .unwrap_or_default(),
        }
    }

    fn pending(&mut self, dir: &Path) -> Option<&mut Vec<DirtyRect>> {
        let dir = dir.canonicalize().ok()?;
        self.known
            .iter_mut()
            .find(|(d, _)| *d == dir)
            .map(|(_, p)| p)
    }
}

impl Saver {
    /// Takes `world`'s level out (returned) and keeps the rest.
    pub fn new(mut world: World, options: SaveOptions, out: &Path) -> (Saver, Level) {
        let stand_in = Level::flat(2, 1, 0, 0).expect("2x1 is a valid map size");
        let level = std::mem::replace(&mut world.level, stand_in);
        let default_dir = match (&options.dir, &options.policy) {
            (Some(dir), _) => dir.clone(),
            (
                None,
                SavePolicy {
                    source: Some(source),
                    overwrite: true,
                },
            ) => source.clone(),
            (None, _) => out.join(format!("{}-edited", world.name)),
        };
        let saver = Saver {
            #[cfg(not(target_arch = "wasm32"))]
            stores: StoreTargets::of(options.policy.source.as_deref()),
            world,
            options,
            default_dir,
        };
        (saver, level)
    }

    /// The loaded world, its level a stand-in.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Whether saving over the loaded world is allowed (`--overwrite`).
    pub fn overwrite(&self) -> bool {
        self.options.policy.overwrite
    }

    /// Note an edit: the stores this session saves into will need those
    /// rectangles' chunks written.
    pub fn record_edit(&mut self, dirty: &[DirtyRect]) {
        #[cfg(not(target_arch = "wasm32"))]
        for (_, pending) in &mut self.stores.known {
            pending.extend(dirty.iter().copied());
        }
        #[cfg(target_arch = "wasm32")]
        let _ = dirty;
    }

    /// Write `level` with the loaded world's other files to `dir`; returns
    /// a line for the log naming where it went.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn save(&mut self, dir: &Path, level: &Level) -> anyhow::Result<String> {
        if self.stores.opened_store {
            return self.save_store(dir, level);
        }
        let start = web_time::Instant::now();
        let world = World {
            level: level.clone(),
            ..self.world.clone()
        };
        let saved = strata_level::save::save_world(dir, &world, &self.options.policy)?;
        // The level's hash lets a reader check the saved map is the edited one.
        Ok(format!(
            "saved the world to {} ({} files, {:.1} MB, level {}) in {:.2} s",
            saved.dir.display(),
            saved.files.len(),
            saved.bytes as f64 / 1e6,
            &level.content_hash()[..16],
            start.elapsed().as_secs_f64()
        ))
    }

    /// Save a world opened from a store as a store (see the module docs).
    #[cfg(not(target_arch = "wasm32"))]
    fn save_store(&mut self, dir: &Path, level: &Level) -> anyhow::Result<String> {
        use anyhow::Context;
        use strata_store::{DirStore, Layout};
        let start = web_time::Instant::now();
        let policy = &self.options.policy;
        let is_source = policy.source.as_deref().is_some_and(
            |s| matches!((s.canonicalize(), dir.canonicalize()), (Ok(a), Ok(b)) if a == b),
        );
        if is_source && !policy.overwrite {
            anyhow::bail!(
                "{} is the store this session loaded; saving over it needs --overwrite (or save to another directory)",
                dir.display()
            );
        }
        if let Some(pending) = self.stores.pending(dir) {
            let store = DirStore::open(dir)
                .with_context(|| format!("opening the store in {}", dir.display()))?;
            let cells = store
                .commit_rects(level, pending)
                .with_context(|| format!("saving the edits into the store {}", dir.display()))?;
            pending.clear();
            return Ok(format!(
                "saved {} edited chunk(s) into the store {} (all or nothing, level {}) in {:.2} s",
                cells.len(),
                dir.display(),
                &level.content_hash()[..16],
                start.elapsed().as_secs_f64()
            ));
        }
        // Another directory: a new store, whole.
        let world = World {
            level: level.clone(),
            ..self.world.clone()
        };
        let store = DirStore::create(dir, &world, &Layout::default())
            .with_context(|| format!("saving the world as a store in {}", dir.display()))?;
        if let Ok(canonical) = store.dir().canonicalize() {
            self.stores.known.push((canonical, Vec::new()));
        }
        let (gy, gx) = store.store().grid();
        Ok(format!(
            "saved the world as a new store in {} ({} chunks, level {}) in {:.2} s",
            dir.display(),
            gy * gx,
            &level.content_hash()[..16],
            start.elapsed().as_secs_f64()
        ))
    }

    #[cfg(target_arch = "wasm32")]
    pub fn save(&mut self, _: &Path, _: &Level) -> anyhow::Result<String> {
        anyhow::bail!("saving is not available in the browser (no file system to write to)")
    }
}

#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests {
    use super::*;
    use strata_level::edit::{EditRect, fill_single};
    use strata_level::generate::{GenerateParams, generate};
    use strata_level::{MidRule, save::SavePolicy};
    use strata_store::{DirStore, Layout};

    fn edit(level: &mut Level, x: i64, y: i64, h: u8) -> Vec<DirtyRect> {
        let rect = EditRect {
            x,
            y,
            width: 20,
            height: 9,
        };
        fill_single(level, rect, h, 3)
    }

    #[test]
    fn a_store_is_saved_in_place_chunk_by_chunk_and_elsewhere_as_a_store() {
        let root = std::env::temp_dir().join(format!("strata-viewer-save-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let world = generate(&GenerateParams {
            seed: 5,
            width: 256,
            height: 256,
        })
        .unwrap();
        let dir = root.join("store");
        let layout = Layout {
            chunk_height: 64,
            chunk_width: 64,
            gzip_level: 1,
        };
        DirStore::create(&dir, &world, &layout).unwrap();
        let loaded = strata_store::load_any(&dir, MidRule::Original).unwrap();
        let options = |overwrite| SaveOptions {
            policy: SavePolicy {
                source: Some(dir.clone()),
                overwrite,
            },
            dir: None,
        };
        // Without --overwrite the opened store is refused.
        let (mut saver, mut level) = Saver::new(loaded.clone(), options(false), &root);
        saver.record_edit(&edit(&mut level, 250, 10, 200));
        let e = saver.save(&dir, &level).unwrap_err();
        assert!(e.to_string().contains("--overwrite"), "{e}");
        // With it: only the edited chunks (across the map's edge: 2 rects).
        let (mut saver, mut level) = Saver::new(loaded, options(true), &root);
        assert_eq!(saver.default_dir, dir);
        saver.record_edit(&edit(&mut level, 250, 10, 200));
        let line = saver.save(&dir, &level).unwrap();
        assert!(line.contains("2 edited chunk(s)"), "{line}");
        let reread = |d: &Path| {
            DirStore::open(d)
                .unwrap()
                .store()
                .read_level(MidRule::Original)
                .unwrap()
        };
        assert_eq!(reread(&dir), level);
        assert!(!dir.join(strata_store::fs::JOURNAL).exists());
        // Nothing edited since: nothing written.
        assert!(saver.save(&dir, &level).unwrap().contains("0 edited"));
        // Elsewhere: a new store, then edits committed into it.
        let other = root.join("copy");
        saver.record_edit(&edit(&mut level, 100, 100, 30));
        let line = saver.save(&other, &level).unwrap();
        assert!(line.contains("new store"), "{line}");
        assert_eq!(reread(&other), level);
        saver.record_edit(&edit(&mut level, 10, 200, 90));
        assert!(saver.save(&other, &level).unwrap().contains("edited chunk"));
        assert_eq!(reread(&other), level);
        // The opened store got both later edits when saved again.
        saver.save(&dir, &level).unwrap();
        assert_eq!(reread(&dir), level);
        // A store this session did not write is not written into.
        let foreign = root.join("foreign");
        DirStore::create(&foreign, &world, &layout).unwrap();
        let e = saver.save(&foreign, &level).unwrap_err();
        assert!(format!("{e:#}").contains("not an empty directory"), "{e:#}");
        let _ = std::fs::remove_dir_all(&root);
    }
}
