//! Saving an edited world so that nothing the user had is lost: the world is
//! written whole into a temporary directory beside the target, then moved
//! into place with renames (atomic within one file system). A crash or a
//! full disk mid-save leaves the target as it was (at worst a stray
//! `.<name>.saving-<pid>` directory beside it); the world the user loaded
//! is never written over unless they asked for it (`overwrite`).

use crate::World;
use crate::error::LevelError;
use crate::io::{WORLD_INI, write_world};
use std::path::{Path, PathBuf};

/// Where a save may go.
#[derive(Clone, Debug, Default)]
pub struct SavePolicy {
    /// The directory the world was loaded from (`None`: made in memory).
    pub source: Option<PathBuf>,
    /// Whether saving into `source` itself is allowed (`--overwrite`).
    pub overwrite: bool,
}

/// What a save wrote.
#[derive(Clone, Debug)]
pub struct Saved {
    /// The world directory, as given.
    pub dir: PathBuf,
    /// The files written (names inside `dir`), `world.ini` last.
    pub files: Vec<String>,
    /// Their total size.
    pub bytes: u64,
}

/// Are `a` and `b` the same directory? Compared canonically when both
/// exist (symlinks, `..`), else by their absolute spelling.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => std::path::absolute(a).ok() == std::path::absolute(b).ok(),
    }
}

/// Save `world` as a world directory at `dir` (see the module comment).
/// Refuses `policy.source` unless `policy.overwrite`, and a `dir` that is
/// an existing file or a non-empty directory without a `world.ini` (so a
/// typo cannot scatter map files into an unrelated folder).
pub fn save_world(dir: &Path, world: &World, policy: &SavePolicy) -> Result<Saved, LevelError> {
    if let Some(source) = &policy.source
        && !policy.overwrite
        && same_dir(dir, source)
    {
        return Err(LevelError::format(
            dir,
            "is the world this session loaded; saving over it needs --overwrite \
             (or save to another directory)",
        ));
    }
    if dir.is_file() {
        return Err(LevelError::format(dir, "is a file, not a world directory"));
    }
    let existing = dir.is_dir();
    if existing && !dir.join(WORLD_INI).exists() && !is_empty_dir(dir)? {
        return Err(LevelError::format(
            dir,
            "is a directory that holds no world (no world.ini): refusing to save into it",
        ));
    }
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| LevelError::format(dir, "names no directory to save into"))?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&parent).map_err(|e| LevelError::io(&parent, e))?;
    let temp = parent.join(format!(".{name}.saving-{}", std::process::id()));
    if temp.exists() {
        std::fs::remove_dir_all(&temp).map_err(|e| LevelError::io(&temp, e))?;
    }
    let written = write_world(&temp, world).and_then(|()| list_files(&temp));
    let files = match written {
        Ok(files) => files,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&temp);
            return Err(e);
        }
    };
    let mut bytes = 0;
    for f in &files {
        let path = temp.join(f);
        bytes += std::fs::metadata(&path)
            .map_err(|e| LevelError::io(&path, e))?
            .len();
    }
    if !existing || is_empty_dir(dir)? {
        // One rename: the directory appears complete or not at all.
        if existing {
            std::fs::remove_dir(dir).map_err(|e| LevelError::io(dir, e))?;
        }
        std::fs::rename(&temp, dir).map_err(|e| LevelError::io(dir, e))?;
    } else {
        // Each file replaced by one rename, `world.ini` last; files of the
        // old world this one does not have (another map name) stay.
        for f in &files {
            let to = dir.join(f);
            std::fs::rename(temp.join(f), &to).map_err(|e| LevelError::io(&to, e))?;
        }
        std::fs::remove_dir(&temp).map_err(|e| LevelError::io(&temp, e))?;
    }
    Ok(Saved {
        dir: dir.to_path_buf(),
        files,
        bytes,
    })
}

fn is_empty_dir(dir: &Path) -> Result<bool, LevelError> {
    Ok(std::fs::read_dir(dir)
        .map_err(|e| LevelError::io(dir, e))?
        .next()
        .is_none())
}

/// The files of a freshly written world directory, `world.ini` last.
fn list_files(dir: &Path) -> Result<Vec<String>, LevelError> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| LevelError::io(dir, e))? {
        let entry = entry.map_err(|e| LevelError::io(dir, e))?;
        files.push(entry.file_name().to_string_lossy().into_owned());
    }
    files.sort_by_key(|f| (f == WORLD_INI, f.clone()));
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MidRule;
    use crate::generate::{GenerateParams, generate};
    use crate::io::load_world;

    fn temp_root(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("strata-save-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn small_world() -> World {
        generate(&GenerateParams {
            width: 256,
            height: 256,
            seed: 7,
        })
        .unwrap()
    }

    /// Every file of a directory, by name.
    fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).unwrap(),
                )
            })
            .collect();
        out.sort();
        out
    }

    #[test]
    fn edited_world_saved_reloads_to_the_same_bytes() {
        let root = temp_root("reload");
        let source = root.join("source");
        write_world(&source, &small_world()).unwrap();
        let mut world = load_world(&source, MidRule::Original).unwrap();
        let before = world.level.clone();
        let site = site_in(&world);
        let dirty = crate::edit::crater(&mut world.level, &site);
        assert!(!dirty.is_empty(), "the crater changed nothing");
        assert_ne!(world.level, before);

        let policy = SavePolicy {
            source: Some(source.clone()),
            overwrite: false,
        };
        let saved = save_world(&root.join("edited"), &world, &policy).unwrap();
        assert_eq!(saved.files.last().map(String::as_str), Some(WORLD_INI));
        let reloaded = load_world(&saved.dir, MidRule::Original).unwrap();
        assert_eq!(reloaded.level.heights(), world.level.heights());
        assert_eq!(reloaded.level.metas(), world.level.metas());
        assert_eq!(reloaded.palette.colors, world.palette.colors);
        assert_eq!(reloaded.water, world.water);
        assert_eq!(reloaded.views, world.views);
        // Saved again from the reloaded world: byte for byte the same files.
        let again = save_world(&root.join("again"), &reloaded, &policy).unwrap();
        assert_eq!(files(&saved.dir), files(&again.dir));
        // No temporary directory is left behind.
        let stray: Vec<_> = std::fs::read_dir(&root)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".saving-"))
            .collect();
        assert!(stray.is_empty(), "left behind: {stray:?}");
        let _ = std::fs::remove_dir_all(&root);
    }

    /// A crater near the middle of the map, across the wrap-free interior.
    fn site_in(world: &World) -> crate::EditSite {
        crate::EditSite {
            centre_x: i64::from(world.level.width() / 2),
            centre_y: i64::from(world.level.height() / 2),
            radius: 9,
            depth: 6.0,
            ..crate::EditSite::fostral()
        }
    }

    #[test]
    fn the_source_is_kept_unless_overwrite() {
        let root = temp_root("source");
        let source = root.join("source");
        write_world(&source, &small_world()).unwrap();
        let original = files(&source);
        let mut world = load_world(&source, MidRule::Original).unwrap();
        let site = site_in(&world);
        crate::edit::crater(&mut world.level, &site);
        let mut policy = SavePolicy {
            source: Some(source.clone()),
            overwrite: false,
        };
        // Also spelled another way.
        for spelling in [source.clone(), root.join("source/../source")] {
            let err = save_world(&spelling, &world, &policy)
                .unwrap_err()
                .to_string();
            assert!(err.contains("--overwrite"), "{err}");
        }
        assert_eq!(
            files(&source),
            original,
            "a refused save changed the source"
        );
        policy.overwrite = true;
        save_world(&source, &world, &policy).unwrap();
        assert_ne!(files(&source), original);
        let reloaded = load_world(&source, MidRule::Original).unwrap();
        assert_eq!(reloaded.level.heights(), world.level.heights());
        assert_eq!(reloaded.level.metas(), world.level.metas());
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn refuses_a_file_and_a_foreign_directory() {
        let root = temp_root("refuse");
        let world = small_world();
        let policy = SavePolicy::default();
        std::fs::write(root.join("a-file"), b"x").unwrap();
        let err = save_world(&root.join("a-file"), &world, &policy).unwrap_err();
        assert!(err.to_string().contains("a-file"), "{err}");
        let foreign = root.join("photos");
        std::fs::create_dir_all(&foreign).unwrap();
        std::fs::write(foreign.join("cat.jpg"), b"meow").unwrap();
        let err = save_world(&foreign, &world, &policy)
            .unwrap_err()
            .to_string();
        assert!(err.contains("no world.ini"), "{err}");
        assert_eq!(files(&foreign).len(), 1);
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn a_failed_save_leaves_the_target_as_it_was() {
        let root = temp_root("fail");
        let target = root.join("target");
        let world = small_world();
        save_world(&target, &world, &SavePolicy::default()).unwrap();
        let before = files(&target);
        // A world whose config disagrees with its map fails mid-write.
        let mut bad = world.clone();
        bad.level = crate::Level::flat(32, 32, 10, 1).unwrap();
        assert!(save_world(&target, &bad, &SavePolicy::default()).is_err());
        assert_eq!(files(&target), before);
        let stray = std::fs::read_dir(&root).unwrap().count();
        assert_eq!(stray, 1, "a temporary directory was left behind");
        let _ = std::fs::remove_dir_all(&root);
    }
}
