//! A world directory (DESIGN §1): `world.ini`, the map (`<File Name>.vmc`
//! or `.vmp`), the palette, optionally `<File Name>.vpr`, and our own
//! `views.txt` / `edit.txt`.

use crate::config::WorldConfig;
use crate::error::{LevelError, read_file, write_file};
use crate::model::{Level, MidRule};
use crate::palette::Palette;
use crate::views::{EditSite, ViewSpec, format_views, parse_views};
use crate::{SourceFiles, World, vmc, vmp, vpr};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use web_time::Instant;

/// The world's configuration file, the one every world directory has.
pub const WORLD_INI: &str = "world.ini";
/// Strata's named views of the world (optional).
pub const VIEWS_TXT: &str = "views.txt";
/// Strata's edit fixture of the world (optional).
pub const EDIT_TXT: &str = "edit.txt";

/// The map file a config names inside `dir`.
pub fn map_path(dir: &Path, config: &WorldConfig) -> PathBuf {
    let ext = if config.compressed { "vmc" } else { "vmp" };
    dir.join(format!("{}.{ext}", config.file_name))
}

/// The `.vpr` file a config names inside `dir`.
pub fn vpr_path(dir: &Path, config: &WorldConfig) -> PathBuf {
    dir.join(format!("{}.vpr", config.file_name))
}

/// Decode a map from bytes in the format the config names.
pub fn decode_map(
    bytes: &[u8],
    config: &WorldConfig,
    mid_rule: MidRule,
    path: &Path,
) -> Result<Level, LevelError> {
    let (w, h) = (config.width(), config.height());
    if config.compressed {
        vmc::decode_vmc(bytes, w, h, mid_rule, path)
    } else {
        vmp::decode_vmp(bytes, w, h, mid_rule, path)
    }
}

/// How loading the map went, for `strata info`.
#[derive(Clone, Debug)]
pub struct MapLoad {
    /// The map file read.
    pub path: PathBuf,
    /// Size of the map file.
    pub bytes: u64,
    /// Reading the file into memory, milliseconds.
    pub read_ms: f64,
    /// Decoding it into the two planes, milliseconds.
    pub decode_ms: f64,
}

/// Is this Fostral (by size and file name), whose views are the paper's?
fn is_fostral(config: &WorldConfig) -> bool {
    config.width() == 2048 && config.height() == 16384 && config.file_name == "output"
}

/// Load a world directory, also reporting the map's size and decode time.
pub fn load_world_timed(dir: &Path, mid_rule: MidRule) -> Result<(World, MapLoad), LevelError> {
    let config = WorldConfig::read(&dir.join(WORLD_INI))?;
    let path = map_path(dir, &config);
    let t0 = Instant::now();
    let bytes = read_file(&path)?;
    let t1 = Instant::now();
    let level = decode_map(&bytes, &config, mid_rule, &path)?;
    let t2 = Instant::now();
    let load = MapLoad {
        path,
        bytes: bytes.len() as u64,
        read_ms: (t1 - t0).as_secs_f64() * 1e3,
        decode_ms: (t2 - t1).as_secs_f64() * 1e3,
    };
    // A `.vmc` is kept so that rows left unedited are written back as they
    // were; a `.vmp` is the planes themselves and is rewritten identically.
    let map_source = config.compressed.then(|| Arc::<[u8]>::from(bytes));

    let optional = |path: PathBuf| -> Result<Option<Vec<u8>>, LevelError> {
        if path.exists() {
            read_file(&path).map(Some)
        } else {
            Ok(None)
        }
    };
    let palette = read_file(&dir.join(&config.palette_file))?;
    let vpr_file = vpr_path(dir, &config);
    // Its size is fixed by the map: a wrong one is refused before reading.
    if let Ok(meta) = std::fs::metadata(&vpr_file) {
        vpr::VprLayout::of(&config).check_len(meta.len(), &vpr_file)?;
    }
    let vpr = optional(vpr_file)?;
    let views = optional(dir.join(VIEWS_TXT))?;
    let edit = optional(dir.join(EDIT_TXT))?;
    let mut world = world_from_parts(
        dir_name(dir),
        dir,
        config,
        level,
        WorldFiles {
            palette: &palette,
            vpr: vpr.as_deref(),
            views: views.as_deref(),
            edit: edit.as_deref(),
        },
    )?;
    world.source.vmc = map_source;
    Ok((world, load))
}

/// A world directory's files besides `world.ini` and the map, as bytes
/// (read from disk, or fetched over HTTP by the browser page).
pub struct WorldFiles<'a> {
    /// The `.pal` file.
    pub palette: &'a [u8],
    /// The `.vpr` file, when the world has one.
    pub vpr: Option<&'a [u8]>,
    /// `views.txt`, when present.
    pub views: Option<&'a [u8]>,
    /// `edit.txt`, when present.
    pub edit: Option<&'a [u8]>,
}

/// The world from its parsed config, decoded map and the other files'
/// bytes; `dir` names the files in errors (a path, or a URL's).
pub fn world_from_parts(
    name: String,
    dir: &Path,
    config: WorldConfig,
    level: Level,
    files: WorldFiles<'_>,
) -> Result<World, LevelError> {
    let palette = Palette::from_bytes(files.palette, &dir.join(&config.palette_file))?;
    let mut source = SourceFiles::default();
    let water = match files.vpr {
        Some(bytes) => {
            let layout = vpr::VprLayout::of(&config);
            let (levels, format) = vpr::parse_vpr(bytes, &layout, &vpr_path(dir, &config))?;
            if format == vpr::VprFormat::Game {
                source.vpr = Some(Arc::from(bytes));
            }
            Some(levels)
        }
        None => None,
    };
    let fostral = is_fostral(&config);
    let views = match files.views {
        Some(bytes) => {
            let text = String::from_utf8_lossy(bytes);
            parse_views(&text)
                .map_err(|e| LevelError::format(&dir.join(VIEWS_TXT), e.to_string()))?
        }
        None if fostral => fostral_views(),
        None => Vec::new(),
    };
    let edit = match files.edit {
        Some(bytes) => {
            let text = String::from_utf8_lossy(bytes);
            Some(
                EditSite::parse(&text)
                    .map_err(|e| LevelError::format(&dir.join(EDIT_TXT), e.to_string()))?,
            )
        }
        None if fostral => Some(EditSite::fostral()),
        None => None,
    };
    Ok(World {
        name,
        level,
        config,
        palette,
        water,
        views,
        edit,
        source,
    })
}

/// Load a world directory (DESIGN §1). `World.name` is the directory's name.
pub fn load_world(dir: &Path, mid_rule: MidRule) -> Result<World, LevelError> {
    load_world_timed(dir, mid_rule).map(|(world, _)| world)
}

fn dir_name(dir: &Path) -> String {
    let named = |p: &Path| p.file_name().map(|n| n.to_string_lossy().into_owned());
    named(dir)
        .or_else(|| dir.canonicalize().ok().as_deref().and_then(named))
        .unwrap_or_else(|| "world".into())
}

/// Write a world directory (created if needed): `world.ini`, the map
/// (`.vmc` when `config.compressed`, else `.vmp`), the palette, the `.vpr`
/// (the game's layout) when `water` is set, `views.txt` when there are
/// views, `edit.txt` when there is an edit site. What `world.source` holds
/// is reused, so a world read and written back unchanged gives the same
/// `world.ini`, `.vpr` and `.vmc` bytes.
pub fn write_world(dir: &Path, world: &World) -> Result<(), LevelError> {
    let config = &world.config;
    let ini_path = dir.join(WORLD_INI);
    let (lw, lh) = (world.level.width(), world.level.height());
    if (config.width(), config.height()) != (lw, lh) {
        return Err(LevelError::format(
            &ini_path,
            format!(
                "the config's map size {}x{} disagrees with the level's {lw}x{lh}",
                config.width(),
                config.height()
            ),
        ));
    }
    // Built first: a wrong number of water levels fails before any file is written.
    let vpr_file = match &world.water {
        Some(water) => {
            let path = vpr_path(dir, config);
            let layout = vpr::VprLayout::of(config);
            let bytes = vpr::vpr_bytes(water, &layout, world.source.vpr.as_deref(), &path)?;
            Some((path, bytes))
        }
        None => None,
    };
    std::fs::create_dir_all(dir).map_err(|e| LevelError::io(dir, e))?;
    let map = map_path(dir, config);
    if config.compressed {
        let bytes = match &world.source.vmc {
            Some(source) => vmc::encode_vmc_reusing(&world.level, source, &map)?.0,
            None => vmc::encode_vmc(&world.level, &map)?,
        };
        write_file(&map, &bytes)?;
    } else {
        vmp::write_vmp(&map, &world.level)?;
    }
    world.palette.write(&dir.join(&config.palette_file))?;
    if let Some((path, bytes)) = &vpr_file {
        write_file(path, bytes)?;
    }
    if !world.views.is_empty() {
        write_file(&dir.join(VIEWS_TXT), format_views(&world.views).as_bytes())?;
    }
    if let Some(edit) = &world.edit {
        write_file(&dir.join(EDIT_TXT), edit.format().as_bytes())?;
    }
    // world.ini last: a directory with one is complete.
    config.write(&ini_path)
}

/// The paper's twelve Fostral views (DESIGN §2), three per pitch.
pub fn fostral_views() -> Vec<ViewSpec> {
    const VIEWS: [(&str, f32, f32, f32, f32, f32); 12] = [
        ("river", 837.0, 3984.0, 299.0, 78.0, 0.0),
        ("hangar", 1588.0, 4101.0, 286.0, 12.0, 0.0),
        ("ramp", 1513.0, 15659.0, 172.0, 28.0, 0.0),
        ("portal", 1176.0, 11567.0, 293.0, 83.0, -30.0),
        ("entrance", 1764.0, 15254.0, 293.0, 108.0, -30.0),
        ("river-down", 457.0, 12337.0, 158.0, 180.0, -30.0),
        ("stash", 1929.0, 13864.0, 293.0, 161.0, -60.0),
        ("copterig", 1727.0, 4805.0, 199.0, 297.0, -60.0),
        ("wires", 519.0, 14910.0, 293.0, 192.0, -60.0),
        ("spiral", 1554.0, 7798.0, 10.0, 312.0, -90.0),
        ("gorb", 471.0, 892.0, 13.0, 332.0, -90.0),
        ("secret", 237.0, 12065.0, 10.0, 376.0, -90.0),
    ];
    VIEWS
        .iter()
        .map(|&(name, x, y, yaw, eye, pitch)| ViewSpec {
            name: name.into(),
            x,
            y,
            yaw,
            eye,
            under: false,
            pitch,
        })
        .collect()
}
