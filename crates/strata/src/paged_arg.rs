//! `--gpu-budget`: draw a world through paged terrain (issue 33), and the
//! world such a renderer draws ([`PagedWorld`]): a store read chunk by chunk
//! through a cache, never whole, or a world in memory cut into pages.

use crate::world_arg::WorldArgs;
use anyhow::Context;
use std::path::Path;
use std::sync::Arc;
use strata_camera::Camera;
use strata_level::generate::MAX_TEXELS;
use strata_level::{ViewSpec, WorldConfig, views::parse_views};
use strata_render::TerrainColors;
use strata_render::paged::{LevelPages, PageSource, PagedOptions, StorePages};
use strata_store::{ChunkCache, DirKind, DirStore};

#[derive(clap::Args, Clone, Debug)]
pub struct PagedArgs {
    /// Draw through paged terrain within this many GPU bytes (suffixes KiB,
    /// MiB, GiB): pages stream in as the view needs them. Default: paged only
    /// for a store past a whole-world limit (2^28 texels, or the memory a
    /// whole world may take here: STRATA_WHOLE_WORLD_LIMIT_MIB), at 256 MiB.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    pub gpu_budget: Option<u64>,
    /// CPU bytes of decoded chunks kept by a store's chunk cache.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes, default_value = "256MiB")]
    pub cache_budget: u64,
    /// Most pages uploaded per frame.
    #[arg(long, default_value_t = 64)]
    pub upload_pages: u32,
    /// Level of detail of paged terrain: far columns come from coarser
    /// copies of the map where a texel of them spans at most this many
    /// pixels; 0 reads every ray from the map's own texels.
    #[arg(long, value_name = "PIXELS", default_value_t = 1.0, value_parser = parse_lod_pixels)]
    pub lod_pixels: f32,
}

/// A pixel tolerance: 0 (off) or a positive, finite number.
fn parse_lod_pixels(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(p) if p.is_finite() && p >= 0.0 => Ok(p),
        _ => Err(format!(
            "`{text}` is not a pixel tolerance (0 turns the level of detail off; 1 is a texel per pixel)"
        )),
    }
}

/// `123`, `64KiB`, `256MiB`, `1GiB` (also `KB`/`MB`/`GB` as powers of 1000).
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !c.is_ascii_digit() && c != '.')
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num
        .parse()
        .map_err(|_| format!("`{text}` is not a byte count (e.g. 256MiB)"))?;
    let scale = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "kib" | "k" => 1024.0,
        "mib" | "m" => 1048576.0,
        "gib" | "g" => 1073741824.0,
        "kb" => 1e3,
        "mb" => 1e6,
        "gb" => 1e9,
        other => {
            return Err(format!(
                "unknown byte unit `{other}` in `{text}` (B, KiB, MiB, GiB)"
            ));
        }
    };
    if value <= 0.0 || !value.is_finite() {
        return Err(format!("`{text}` must be positive"));
    }
    Ok((value * scale) as u64)
}

/// How a column is read for placing a view's eye.
enum Columns {
    Memory(Arc<strata_level::Level>),
    Store(Arc<ChunkCache>),
}

/// A world drawn through paged terrain.
pub struct PagedWorld {
    pub name: String,
    pub size: (u32, u32),
    pub views: Vec<ViewSpec>,
    pub colors: TerrainColors,
    pub source: Arc<dyn PageSource>,
    columns: Columns,
    /// The store's directory, when the world is a store.
    pub dir: Option<std::path::PathBuf>,
}

impl PagedWorld {
    /// The camera of `view` at `width` x `height` (reads the one column under it).
    pub fn camera(&self, view: &ViewSpec, width: u32, height: u32) -> anyhow::Result<Camera> {
        let column = |x: i64, y: i64| match &self.columns {
            Columns::Memory(level) => Ok(level.column(x, y)),
            Columns::Store(cache) => cache.column(x, y),
        };
        strata_viewer::paged::camera_over(self.size, column, view, width, height)
    }

    /// The store's chunk cache, when the world is a store.
    pub fn cache(&self) -> Option<&Arc<ChunkCache>> {
        match &self.columns {
            Columns::Store(cache) => Some(cache),
            Columns::Memory(_) => None,
        }
    }

    /// The paging options from the flags.
    pub fn options(args: &PagedArgs) -> PagedOptions {
        PagedOptions {
            gpu_budget: args
                .gpu_budget
                .unwrap_or(strata_render::paged::DEFAULT_GPU_BUDGET),
            upload_pages: args.upload_pages,
            lod_pixels: args.lod_pixels,
            ..Default::default()
        }
    }
}

/// The world to draw paged, when it must be: `--gpu-budget` given, or a
/// store past a whole-world limit (texels or memory). `None`: draw it whole, as before.
pub fn open_paged(world: &WorldArgs, paged: &PagedArgs) -> anyhow::Result<Option<PagedWorld>> {
    let store_dir = match &world.level {
        Some(dir) if strata_store::dir_kind(dir)? == DirKind::Store => Some(dir.clone()),
        _ => None,
    };
    if let Some(dir) = store_dir {
        let store = DirStore::open(&dir)
            .with_context(|| format!("opening the store in {}", dir.display()))?;
        let (w, h) = (store.store().width(), store.store().height());
        // Past either whole-world limit (the texture's texels, or the memory
        // a whole world may take here) a store is drawn paged by default.
        let past_memory = store.store().map_bytes() > crate::world_arg::whole_world_limit();
        if paged.gpu_budget.is_none() && u64::from(w) * u64::from(h) <= MAX_TEXELS && !past_memory {
            return Ok(None);
        }
        return open_store(&dir, store, world, paged).map(Some);
    }
    if paged.gpu_budget.is_none() {
        return Ok(None);
    }
    let w = world.load()?;
    let level = Arc::new(w.level.clone());
    Ok(Some(PagedWorld {
        name: w.name.clone(),
        size: (w.level.width(), w.level.height()),
        views: w.views.clone(),
        colors: TerrainColors::from_world(&w),
        source: Arc::new(LevelPages::new(level.clone())?),
        columns: Columns::Memory(level),
        dir: None,
    }))
}

fn open_store(
    dir: &Path,
    store: DirStore,
    world: &WorldArgs,
    paged: &PagedArgs,
) -> anyhow::Result<PagedWorld> {
    let mid_rule = world.mid_rule();
    let attrs = store.store().attrs().clone();
    let config = WorldConfig::parse_store_bytes(attrs.world_ini.as_bytes(), &dir.join("zarr.json"))
        .with_context(|| format!("the world.ini of the store in {}", dir.display()))?;
    let palette = strata_level::Palette::from_bytes(&attrs.palette, &dir.join("zarr.json"))
        .with_context(|| format!("the palette of the store in {}", dir.display()))?;
    let views = parse_views(&attrs.views)
        .with_context(|| format!("the views of the store in {}", dir.display()))?;
    let cache = Arc::new(ChunkCache::new(
        store.store().clone(),
        paged.cache_budget as usize,
        mid_rule,
    ));
    let source = Arc::new(StorePages::new(cache.clone(), mid_rule)?);
    Ok(PagedWorld {
        name: attrs.name.clone(),
        size: (attrs.width, attrs.height),
        views,
        colors: TerrainColors {
            palette: palette.colors,
            begin: config.begin_colors,
            end: config.end_colors,
        },
        source,
        columns: Columns::Store(cache),
        dir: Some(dir.to_path_buf()),
    })
}

#[cfg(test)]
mod tests {
    use super::parse_bytes;

    #[test]
    fn byte_counts_parse_with_units_and_refuse_nonsense() {
        assert_eq!(parse_bytes("256MiB"), Ok(256 << 20));
        assert_eq!(parse_bytes("4 MiB"), Ok(4 << 20));
        assert_eq!(parse_bytes("1GiB"), Ok(1 << 30));
        assert_eq!(parse_bytes("1000"), Ok(1000));
        assert_eq!(parse_bytes("2MB"), Ok(2_000_000));
        assert!(parse_bytes("lots").is_err());
        assert!(parse_bytes("0").is_err());
        assert!(parse_bytes("3 parsecs").is_err());
    }
}
