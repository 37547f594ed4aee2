//! Saving the edited world (Ctrl+S, script `save DIR`) in the real file
//! format, through [`strata_level::save::save_world`]: a temporary
//! directory and renames, never over the loaded world without
//! `--overwrite`. Not available in a browser (no file system to write to).

use std::path::{Path, PathBuf};
use strata_level::save::SavePolicy;
use strata_level::{Level, World};

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

    /// Write `level` with the loaded world's other files to `dir`; returns
    /// a line for the log naming where it went.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn save(&self, dir: &Path, level: &Level) -> anyhow::Result<String> {
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

    #[cfg(target_arch = "wasm32")]
    pub fn save(&self, _: &Path, _: &Level) -> anyhow::Result<String> {
        anyhow::bail!("saving is not available in the browser (no file system to write to)")
    }
}
