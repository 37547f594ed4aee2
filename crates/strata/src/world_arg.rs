//! `--level DIR`: the world a command works on; the built-in generated world
//! when absent, so a newcomer needs no setup.

use anyhow::{Context, bail};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use strata_level::generate::{GENERATOR_VERSION, GenerateParams, generate};
use strata_level::source::ColumnSource;
use strata_level::{MidRule, World, io};
use strata_store::fs::{DirKind, dir_kind};
use strata_store::{ChunkCache, DirStore};

/// The commands that read a store through its chunk cache in bounded
/// memory (named when a whole-world command refuses a large store).
pub const BOUNDED_COMMANDS: &str = "reference, fit, export --region, info, metrics, and render, fly, view and compare with ray-exact, ray-exact-fragment or mesh (paged terrain)";

/// Default byte budget of a store's chunk cache, MiB.
pub const DEFAULT_STORE_CACHE_MIB: u32 = 512;

#[derive(clap::Args, Clone, Debug)]
pub struct WorldArgs {
    /// World directory: a Vangers world (`world.ini` + map + palette) or a Strata store (`zarr.json`). Default: the built-in generated world.
    #[arg(long, value_name = "DIR")]
    pub level: Option<PathBuf>,
    /// Derive the cave ceiling with vange-rs's `+0` convention instead of the original game's `+1`.
    #[arg(long)]
    pub vange_rs_mid: bool,
    /// Byte budget, MiB, of the chunk cache through which commands that read a store in bounded memory (reference, fit, export) read it.
    #[arg(long, value_name = "MIB", default_value_t = DEFAULT_STORE_CACHE_MIB, value_parser = clap::value_parser!(u32).range(1..=1 << 20))]
    pub store_cache: u32,
}

/// A world opened for a command that reads a store in bounded memory.
pub enum Opened {
    /// A Vangers world (or the default world), loaded whole.
    Memory(World),
    /// A store, read through its chunk cache.
    Store(StoreWorld),
}

/// A store opened for reading through its chunk cache.
pub struct StoreWorld {
    /// The store.
    pub store: DirStore,
    /// Its chunk cache (the budget of `--store-cache`).
    pub cache: ChunkCache,
    /// Everything of the world but its map (a 2x1 stand-in level).
    pub shell: World,
}

impl Opened {
    /// Everything of the world but (for a store) its map.
    pub fn world(&self) -> &World {
        match self {
            Opened::Memory(w) => w,
            Opened::Store(s) => &s.shell,
        }
    }

    /// Where the map's columns are read.
    pub fn source(&self) -> &dyn ColumnSource {
        match self {
            Opened::Memory(w) => &w.level,
            Opened::Store(s) => &s.cache,
        }
    }

    /// The store's chunk cache, when a store was opened.
    pub fn cache(&self) -> Option<&ChunkCache> {
        match self {
            Opened::Memory(_) => None,
            Opened::Store(s) => Some(&s.cache),
        }
    }
}

/// The most bytes of map a whole-world command loads: half the memory
/// available now (`/proc/meminfo`), at most 4 GiB; 4 GiB where that cannot
/// be read. `STRATA_WHOLE_WORLD_LIMIT_MIB` sets it (tests, large machines).
pub fn whole_world_limit() -> u64 {
    if let Some(mib) = std::env::var("STRATA_WHOLE_WORLD_LIMIT_MIB")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        return mib << 20;
    }
    let cap = 4u64 << 30;
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        })
        .map_or(cap, |kb| (kb * 1024 / 2).min(cap))
}

impl WorldArgs {
    pub fn mid_rule(&self) -> MidRule {
        if self.vange_rs_mid {
            MidRule::VangeRs
        } else {
            MidRule::Original
        }
    }

    /// The directory the world is loaded from: `--level`, else the default
    /// world's cache (saves must not write over either unasked).
    pub fn source_dir(&self) -> Option<PathBuf> {
        self.level
            .clone()
            .or_else(|| cache_root().map(|root| cache_dir(&root, &GenerateParams::default())))
    }

    /// The world named by `--level`, else the default generated world, read
    /// from the on-disk cache (written there the first time).
    pub fn load(&self) -> anyhow::Result<World> {
        let mid_rule = self.mid_rule();
        if let Some(dir) = &self.level {
            // A Vangers world or a Strata store, told apart by its files; a
            // store too large to load whole is refused before any chunk is read.
            if let Ok(DirKind::Store) = dir_kind(dir) {
                let store = DirStore::open(dir)
                    .with_context(|| format!("opening the store in {}", dir.display()))?;
                check_whole_world(dir, store.store(), whole_world_limit())?;
                return store
                    .store()
                    .read_world(mid_rule)
                    .with_context(|| format!("loading the world in {}", dir.display()));
            }
            return strata_store::load_any(dir, mid_rule)
                .with_context(|| format!("loading the world in {}", dir.display()));
        }
        let mut world = load_default(&GenerateParams::default(), cache_root().as_deref())?;
        world.level.mid_rule = mid_rule;
        Ok(world)
    }
}

impl WorldArgs {
    /// The world for a command that reads a store in bounded memory: a
    /// store is opened (its metadata and nothing else) with a chunk cache
    /// of `--store-cache` MiB; a Vangers world or the default world is
    /// loaded whole, as [`WorldArgs::load`] does.
    pub fn open(&self) -> anyhow::Result<Opened> {
        if let Some(dir) = &self.level
            && let Ok(DirKind::Store) = dir_kind(dir)
        {
            let store = DirStore::open(dir)
                .with_context(|| format!("opening the store in {}", dir.display()))?;
            let shell = store
                .store()
                .world_shell()
                .with_context(|| format!("reading the world in {}", dir.display()))?;
            let cache = ChunkCache::new(
                Arc::clone(store.store()),
                (self.store_cache as usize) << 20,
                self.mid_rule(),
            );
            return Ok(Opened::Store(StoreWorld {
                store,
                cache,
                shell,
            }));
        }
        Ok(Opened::Memory(self.load()?))
    }
}

/// Refuse to load a store whose map is above `limit` bytes, naming its size
/// and the commands that read it in bounded memory.
pub fn check_whole_world(
    dir: &Path,
    store: &strata_store::WorldStore,
    limit: u64,
) -> anyhow::Result<()> {
    let bytes = store.map_bytes();
    if bytes > limit {
        let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
        bail!(
            "the store in {} is {}x{} texels ({:.1} GiB loaded whole), more than this command may load here ({:.1} GiB: half the available memory, at most 4; STRATA_WHOLE_WORLD_LIMIT_MIB sets it). This command needs the whole world in memory; these read a store in bounded memory: {BOUNDED_COMMANDS}",
            dir.display(),
            store.width(),
            store.height(),
            gib(bytes),
            gib(limit)
        );
    }
    Ok(())
}

/// `$STRATA_CACHE_DIR`, else `$XDG_CACHE_HOME/strata`, else `~/.cache/strata`.
pub fn cache_root() -> Option<PathBuf> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("STRATA_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("strata")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("strata")))
}

/// The cache directory of a generated world: keyed by everything its bytes depend on.
pub fn cache_dir(root: &Path, params: &GenerateParams) -> PathBuf {
    root.join(format!(
        "generated-v{GENERATOR_VERSION}-seed{}-{}x{}",
        params.seed, params.width, params.height
    ))
}

/// The generated world for `params`: from the cache when it holds a readable
/// copy, else generated (one line on stderr) and written to the cache. A
/// cache that cannot be written only costs a warning.
pub fn load_default(params: &GenerateParams, root: Option<&Path>) -> anyhow::Result<World> {
    let dir = root.map(|r| cache_dir(r, params));
    if let Some(dir) = &dir
        && dir.join("world.ini").exists()
    {
        match io::load_world(dir, MidRule::Original) {
            Ok(mut world) => {
                world.name = generated_name(params);
                return Ok(world);
            }
            Err(err) => eprintln!(
                "warning: ignoring the cached world in {}: {err}",
                dir.display()
            ),
        }
    }
    eprintln!(
        "generating the default world ({}x{}, seed {}); it is cached for next time",
        params.width, params.height, params.seed
    );
    let world = generate(params).context("generating the default world")?;
    match &dir {
        Some(dir) => {
            if let Err(err) = write_cache(dir, &world) {
                eprintln!(
                    "warning: could not cache the world in {}: {err:#}",
                    dir.display()
                );
            }
        }
        None => eprintln!("warning: no cache directory (set STRATA_CACHE_DIR or HOME); not cached"),
    }
    Ok(world)
}

fn generated_name(params: &GenerateParams) -> String {
    format!("generated-{}", params.seed)
}

/// Write into a temporary sibling and rename, so a reader never sees half a
/// world and two processes filling the cache at once do not collide.
fn write_cache(dir: &Path, world: &World) -> anyhow::Result<()> {
    let parent = dir.parent().context("cache directory has no parent")?;
    std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
    let tmp = parent.join(format!(
        ".{}.tmp-{}",
        dir.file_name().and_then(|n| n.to_str()).unwrap_or("world"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&tmp);
    io::write_world(&tmp, world)?;
    if let Err(err) = std::fs::rename(&tmp, dir) {
        let _ = std::fs::remove_dir_all(&tmp);
        // Another process may have finished first: that copy is as good.
        if !dir.join("world.ini").exists() {
            return Err(err)
                .with_context(|| format!("renaming {} to {}", tmp.display(), dir.display()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_is_written_then_read_back_identically() {
        let root = std::env::temp_dir().join(format!("strata-cache-test-{}", std::process::id()));
        let params = GenerateParams {
            seed: 3,
            width: 256,
            height: 256,
        };
        let fresh = load_default(&params, Some(&root)).unwrap();
        assert!(cache_dir(&root, &params).join("world.ini").exists());
        let cached = load_default(&params, Some(&root)).unwrap();
        assert_eq!(fresh.level.content_hash(), cached.level.content_hash());
        assert_eq!(fresh.views, cached.views);
        assert_eq!(fresh.edit, cached.edit);
        assert_eq!(cached.name, "generated-3");
        // Unusable cache root (a file): still a world, just not cached.
        let file = root.join("not-a-dir");
        std::fs::write(&file, b"x").unwrap();
        let uncached = load_default(&params, Some(&file)).unwrap();
        assert_eq!(uncached.level.content_hash(), fresh.level.content_hash());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn every_default_view_resolves_to_a_camera() {
        let world = generate(&GenerateParams {
            seed: 1997,
            width: 512,
            height: 2048,
        })
        .unwrap();
        for view in &world.views {
            strata_camera::Camera::from_view(&world.level, view, 320, 200)
                .unwrap_or_else(|e| panic!("{}: {e}", view.name));
        }
        let edit = world.edit.unwrap();
        strata_camera::Camera::from_view(&world.level, &edit.camera, 320, 200).unwrap();
    }
}
