//! `--level DIR`: the world a command works on; the built-in generated world
//! when absent, so a newcomer needs no setup.

use anyhow::Context;
use std::path::{Path, PathBuf};
use strata_level::generate::{GENERATOR_VERSION, GenerateParams, generate};
use strata_level::{MidRule, World, io};

#[derive(clap::Args, Clone, Debug)]
pub struct WorldArgs {
    /// World directory: a Vangers world (`world.ini` + map + palette) or a Strata store (`zarr.json`). Default: the built-in generated world.
    #[arg(long, value_name = "DIR")]
    pub level: Option<PathBuf>,
    /// Derive the cave ceiling with vange-rs's `+0` convention instead of the original game's `+1`.
    #[arg(long)]
    pub vange_rs_mid: bool,
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
            // A Vangers world or a Strata store, told apart by its files.
            return strata_store::load_any(dir, mid_rule)
                .with_context(|| format!("loading the world in {}", dir.display()));
        }
        let mut world = load_default(&GenerateParams::default(), cache_root().as_deref())?;
        world.level.mid_rule = mid_rule;
        Ok(world)
    }
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
