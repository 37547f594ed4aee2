//! `strata reference`: the CPU reference of one view, every view of a views
//! file, or the world's own views; pictures + raw data per view in
//! `--out/<view name>/` (see `strata_reference::output`), served from the
//! reference cache when it has them.

use crate::world_arg::{Opened, WorldArgs};
use anyhow::{Context, bail};
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;
use strata_level::{ViewSpec, views::parse_views};
use strata_reference::output::{FORMAT_NOTE, ViewHeader, write_color, write_view};
use strata_reference::{
    REFERENCE_VERSION, ReferenceCache, ReferenceSettings, TerrainRamps, Tracer, camera_for_view,
    render_color_checked,
};

/// Stores up to this many texels are hashed (streamed, a few seconds) so
/// their references are cached like a loaded world's (the key is the same
/// content hash); larger ones are computed each time (hashing would read
/// the whole store).
const HASHED_STORE_TEXELS: u64 = 1 << 28;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// One view, `X,Y:YAW:EYE[:under]` (eye above the top surface, or the floor with `under`).
    #[arg(
        long,
        value_name = "SPEC",
        conflicts_with = "views",
        requires = "pitch",
        allow_hyphen_values = true
    )]
    pub view: Option<String>,
    /// Pitch of `--view`, degrees in [-90, 90] (negative looks down).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub pitch: Option<f32>,
    /// Name of `--view` (its output subdirectory).
    #[arg(long, default_value = "view")]
    pub name: String,
    /// Every view of a views file (`NAME X,Y:YAW:EYE[:under] PITCH` per line).
    /// With neither --view nor --views: the world's own views.
    #[arg(long, value_name = "FILE")]
    pub views: Option<PathBuf>,
    /// Image size in pixels. The focal length stays 512 px at every size.
    #[arg(long, default_value = "1280x800", value_parser = parse_image_size)]
    pub size: (u32, u32),
    /// Output directory; each view goes to `OUT/<view name>/`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Print one JSON line per view instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Always compute; neither read nor write the reference cache.
    #[arg(long)]
    pub no_cache: bool,
    /// Shade color.png without the shadow map (as `compare --no-shadows`).
    #[arg(long)]
    pub no_shadows: bool,
    /// Cache directory. Default: $STRATA_CACHE_DIR/reference, else ~/.cache/strata/reference.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Far plane, texels along the view axis (default 600, the paper's), as
    /// `render --far` and `fly --far`: horizon views of large worlds.
    #[arg(long, value_name = "TEXELS", value_parser = super::render::parse_far)]
    pub far: Option<f32>,
}

/// One line of `--json` output.
#[derive(Serialize)]
struct ViewSummary<'a> {
    view: &'a str,
    /// Percent of pixels that are sky.
    sky_fraction: f64,
    distance_min: Option<f32>,
    distance_median: Option<f32>,
    distance_max: Option<f32>,
    /// Seconds to compute (0 when served from the cache).
    seconds: f64,
    from_cache: bool,
    width: u32,
    height: u32,
    out: String,
    /// A store's chunk cache after this view (absent for a world in memory).
    #[serde(skip_serializing_if = "Option::is_none")]
    store_cache: Option<strata_store::CacheStats>,
}

/// `WxH` with both positive.
pub fn parse_image_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{text}` is not WIDTHxHEIGHT (e.g. 1280x800)"))?;
    let dim = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}` in `{text}` is not a positive whole number of pixels"))
    };
    let (w, h) = (dim(w)?, dim(h)?);
    if w == 0 || h == 0 {
        return Err(format!("image size {w}x{h} must be positive"));
    }
    if u64::from(w) * u64::from(h) > 1 << 28 {
        return Err(format!("image size {w}x{h} is unreasonably large"));
    }
    Ok((w, h))
}

pub fn run(args: Args) -> anyhow::Result<()> {
    // Written, not println!ed: a closed pipe (`| head`) is an error, not a panic.
    let mut out = std::io::stdout().lock();
    // A store is read through its chunk cache; a Vangers world is loaded.
    let opened = args.world.open()?;
    let world = opened.world();
    let source = opened.source();
    let views: Vec<ViewSpec> = match (&args.view, &args.views) {
        (Some(spec), _) => {
            let pitch = args.pitch.context("--view needs --pitch DEG")?;
            vec![ViewSpec::parse(&args.name, spec, pitch).context("--view")?]
        }
        (None, Some(file)) => {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("reading views file {}", file.display()))?;
            parse_views(&text).with_context(|| format!("views file {}", file.display()))?
        }
        (None, None) => world.views.clone(),
    };
    if views.is_empty() {
        bail!(
            "no views: give --view SPEC --pitch DEG or --views FILE (the world has none of its own)"
        );
    }
    for v in &views {
        if v.name.is_empty() || v.name.contains(['/', '\\']) || v.name == "." || v.name == ".." {
            bail!("view name `{}` cannot be a directory name", v.name);
        }
    }
    let (w, h) = args.size;
    // Resolve every camera first, so a bad view fails before any work.
    let cameras = views
        .iter()
        .map(|v| {
            let mut c = camera_for_view(source, v, w, h).context("resolving the camera")?;
            if let Some(far) = args.far {
                c.far = far;
            }
            Ok(c)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    // The cache key: the map's content hash (a store's streamed, equal to
    // the same map's loaded whole), or none for a store too large to hash.
    let level_hash = match &opened {
        Opened::Memory(world) => Some(world.level.content_hash()),
        Opened::Store(s) => {
            let texels = u64::from(s.store.store().width()) * u64::from(s.store.store().height());
            if texels <= HASHED_STORE_TEXELS && !args.no_cache {
                Some(
                    s.store
                        .store()
                        .content_hash(args.world.mid_rule())
                        .context("hashing the store's map")?,
                )
            } else {
                if !args.no_cache {
                    eprintln!(
                        "note: a {texels}-texel store is not hashed (that would read all of it), so its references are computed, not cached"
                    );
                }
                None
            }
        }
    };
    let tracer = Tracer::over(source).context("preparing the tracer")?;
    let cache = ReferenceCache::new(
        args.cache_dir
            .clone()
            .unwrap_or_else(strata_reference::default_cache_dir),
    );
    if !args.json {
        writeln!(
            out,
            "{:<14} {:>7} {:>9} {:>9} {:>9} {:>8}  cache",
            "view", "sky %", "min", "median", "max", "seconds"
        )?;
    }
    let ramps = TerrainRamps::from_world(world);
    let shadows = !args.no_shadows;
    for (view, camera) in views.iter().zip(&cameras) {
        let start = Instant::now();
        let context = "reference cache (use --no-cache to bypass)";
        let (reference, color, from_cache) = match (&level_hash, args.no_cache) {
            (Some(level_hash), false) => {
                let (r, r_hit) = cache
                    .get_or_compute_traced(&tracer, level_hash, camera)
                    .context(context)?;
                let (c, c_hit) = cache
                    .get_or_compute_color(&tracer, level_hash, camera, &ramps, shadows)
                    .context(context)?;
                (r, c, r_hit && c_hit)
            }
            _ => (
                tracer
                    .try_render(camera, &ReferenceSettings::default())
                    .with_context(|| format!("view {}", view.name))?,
                render_color_checked(&tracer, &ramps, camera, shadows)
                    .with_context(|| format!("view {}", view.name))?,
                false,
            ),
        };
        // A store read failing under the cached path is caught here.
        if let Some(e) = tracer.error() {
            bail!("view {}: {e}", view.name);
        }
        let seconds = if from_cache {
            0.0
        } else {
            start.elapsed().as_secs_f64()
        };
        let summary = reference.distance_summary();
        let header = ViewHeader {
            width: w,
            height: h,
            camera: *camera,
            view: Some(view.clone()),
            level_hash: level_hash
                .clone()
                .unwrap_or_else(|| "not hashed (a large store)".into()),
            reference_version: REFERENCE_VERSION,
            sky_fraction: reference.sky_fraction(),
            distance_min: summary.map(|s| s.0),
            distance_median: summary.map(|s| s.1),
            distance_max: summary.map(|s| s.2),
            seconds,
            from_cache,
            format: FORMAT_NOTE.to_string(),
        };
        let dir = args.out.join(&view.name);
        write_view(&dir, &header, &reference)?;
        write_color(&dir, &color)?;
        if args.json {
            let line = ViewSummary {
                view: &view.name,
                sky_fraction: header.sky_fraction,
                distance_min: header.distance_min,
                distance_median: header.distance_median,
                distance_max: header.distance_max,
                seconds,
                from_cache,
                width: w,
                height: h,
                out: dir.display().to_string(),
                store_cache: opened.cache().map(|c| c.stats()),
            };
            writeln!(out, "{}", serde_json::to_string(&line)?)?;
        } else {
            let f = |v: Option<f32>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
            writeln!(
                out,
                "{:<14} {:>7.2} {:>9} {:>9} {:>9} {:>8.3}  {}",
                view.name,
                header.sky_fraction,
                f(header.distance_min),
                f(header.distance_median),
                f(header.distance_max),
                seconds,
                if from_cache { "hit" } else { "computed" }
            )?;
        }
    }
    if let (Some(c), false) = (opened.cache(), args.json) {
        let st = c.stats();
        writeln!(
            out,
            "store cache: {} hits, {} misses ({:.1} % hit), {} evictions, peak {:.1} of {} MiB",
            st.hits,
            st.misses,
            st.hit_rate(),
            st.evictions,
            st.peak_bytes as f64 / f64::from(1u32 << 20),
            c.budget() >> 20
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::parse_image_size;

    #[test]
    fn sizes() {
        assert_eq!(parse_image_size("1280x800"), Ok((1280, 800)));
        assert!(parse_image_size("0x800").is_err());
        assert!(parse_image_size("-5x800").is_err());
        assert!(parse_image_size("1280").is_err());
    }
}
