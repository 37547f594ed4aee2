//! `strata generate`: write a generated Vangers-like world directory in the
//! real file format, or a store, optionally with a top-down preview picture.
//!
//! A store is generated chunk by chunk straight into its chunks (on every
//! core, in memory proportional to the chunks in flight), so it can be far
//! larger than memory: up to 65536x65536. Its bytes are the in-memory
//! generator's wherever both apply (the chunked generator's tests).

use anyhow::{Context, bail};
use std::path::PathBuf;
use std::time::Instant;
use strata_level::generate::{
    Chunked, GenerateParams, Knobs, check_chunked_size, check_size, generate_with, landmark_list,
    parse_size, preview,
};
use strata_level::stats::LevelStats;
use strata_level::{World, io};

#[derive(clap::Args)]
pub struct Args {
    /// Directory to write (created if needed).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Seed; the same seed and size give the same bytes.
    #[arg(long, default_value_t = GenerateParams::default().seed)]
    seed: u64,
    /// Map size WIDTHxHEIGHT, powers of two from 256 to 32768 a side and at most 2^28 texels; with `--to store`, up to 65536x65536.
    #[arg(long, default_value = "2048x16384")]
    size: String,
    /// Share of texels under a slab, 0 … 0.5: every slab is replaced by roofs over blobs covering this share (default: the world's own slabs, about 10 %).
    #[arg(long, value_name = "F")]
    dual_fraction: Option<f64>,
    /// Factor on the floor's small relief (bumps, specks), 0 … 4 (default 1).
    #[arg(long, value_name = "R")]
    floor_roughness: Option<f64>,
    /// Write a Vangers world directory or a Strata store (Zarr v3).
    #[arg(long, value_enum, default_value = "vangers")]
    to: super::convert::To,
    /// Overwrite a directory that already holds a world.
    #[arg(long)]
    force: bool,
    /// Also write a top-down shaded picture (PNG) of part of the map.
    #[arg(long, value_name = "PNG")]
    preview: Option<PathBuf>,
    /// The area the preview shows: `X,Y,WIDTHxHEIGHT` in texels (default: 512x512 around the hangar landmark).
    #[arg(long, value_name = "X,Y,WxH", requires = "preview")]
    preview_area: Option<String>,
}

/// `println!` into a String.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let (width, height) = parse_size(&args.size)?;
    let params = GenerateParams {
        seed: args.seed,
        width,
        height,
    };
    let knobs = Knobs {
        dual_fraction: args.dual_fraction,
        floor_roughness: args.floor_roughness,
    };
    knobs.check()?;
    // Sizes first: a bad size must not cost the directory `--force` replaces.
    match args.to {
        super::convert::To::Vangers => {
            if let Err(e) = check_size(width, height) {
                if check_chunked_size(width, height).is_ok() {
                    bail!("{e} (a store takes it: --to store)");
                }
                return Err(e.into());
            }
        }
        super::convert::To::Store => check_chunked_size(width, height)?,
    }
    if args.to == super::convert::To::Store && args.out.exists() {
        if !args.force {
            bail!(
                "{} already exists; pass --force to replace it",
                args.out.display()
            );
        }
        if args.out.join("zarr.json").exists() || args.out.join("world.ini").exists() {
            std::fs::remove_dir_all(&args.out)
                .with_context(|| format!("removing {}", args.out.display()))?;
        }
    }
    if args.out.join("world.ini").exists() && !args.force {
        bail!(
            "{} already holds a world (world.ini); pass --force to overwrite it",
            args.out.display()
        );
    }
    let area = match &args.preview_area {
        Some(text) => Some(parse_area(text)?),
        None => None,
    };
    match args.to {
        super::convert::To::Vangers => in_memory(&args, &params, &knobs, area),
        super::convert::To::Store => chunked(&args, &params, &knobs, area),
    }
}

/// A Vangers world: the whole map in memory, then written.
fn in_memory(
    args: &Args,
    params: &GenerateParams,
    knobs: &Knobs,
    area: Option<preview::Region>,
) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let world = generate_with(params, knobs)?;
    let generate_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    io::write_world(&args.out, &world)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let write_s = t1.elapsed().as_secs_f64();
    let stats = LevelStats::compute(&world.level);
    // Collected and written once: a closed pipe (`| head`) is not an error worth a panic.
    let mut out = String::new();
    outln!(
        out,
        "wrote {} ({}x{}, seed {}): generated in {generate_s:.2} s, written in {write_s:.2} s",
        args.out.display(),
        params.width,
        params.height,
        args.seed
    );
    outln!(
        out,
        "dual {:.2} %  roughness floor {:.2}  surface {:.2} ({:.2}x)  heights {}..{}",
        stats.dual_percent,
        stats.roughness_floor,
        stats.roughness_surface,
        stats.roughness_surface / stats.roughness_floor.max(1e-9),
        stats.height_min,
        stats.height_max
    );
    describe(&mut out, &world, &landmark_list(params)?);
    if let Some(png) = &args.preview {
        let area = area.unwrap_or_else(|| default_area(&world));
        write_preview(&world, area, png)?;
        outln!(
            out,
            "preview of {},{} {}x{}: {}",
            area.x,
            area.y,
            area.width,
            area.height,
            png.display()
        );
    }
    if world.config.map_power_x != 11 {
        outln!(
            out,
            "note: the original game's loader accepts only 2048-wide maps (Map Power X=11); vange-rs takes the size from world.ini"
        );
    }
    let _ = std::io::Write::write_all(&mut std::io::stdout(), out.as_bytes());
    Ok(())
}

/// A store: each chunk generated where it is written, in parallel, never
/// the whole map; the figures come from the chunk summaries.
fn chunked(
    args: &Args,
    params: &GenerateParams,
    knobs: &Knobs,
    area: Option<preview::Region>,
) -> anyhow::Result<()> {
    use std::sync::atomic::{AtomicU64, Ordering};
    use strata_store::{Chunk, DirStore, Layout, StoreError};
    let t0 = Instant::now();
    let generator = Chunked::new(params, knobs)?;
    let world = generator.world_without_planes();
    let layout = Layout::default();
    let (w, h) = (params.width, params.height);
    let (ch, cw) = layout.chunk_for(w, h);
    let total = u64::from(w / cw) * u64::from(h / ch);
    let done = AtomicU64::new(0);
    // Progress on stderr for worlds that take minutes (every 10 %).
    let tell = total >= 4096;
    let make = |cy: u64, cx: u64| {
        let n = (cw * ch) as usize;
        let (mut heights, mut metas) = (vec![0u8; n], vec![0u8; n]);
        let rect = (cx as u32 * cw, cy as u32 * ch, cw, ch);
        generator
            .fill(rect, &mut heights, &mut metas)
            .map_err(|e| StoreError::Invalid(e.to_string()))?;
        let k = done.fetch_add(1, Ordering::Relaxed) + 1;
        if tell && k.is_multiple_of(total / 10) {
            eprintln!("  {k}/{total} chunks, {:.0} s", t0.elapsed().as_secs_f64());
        }
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights,
            metas,
        })
    };
    DirStore::create_with(&args.out, &world, (w, h), &layout, &make)
        .with_context(|| format!("writing the store {}", args.out.display()))?;
    let total_s = t0.elapsed().as_secs_f64();
    // The coarse levels far terrain is drawn from (`strata_store::lod`).
    let t1 = std::time::Instant::now();
    let store = DirStore::build_lods(&args.out, &|k, n| {
        if tell {
            eprintln!(
                "  level of detail {k}/{n}, {:.0} s",
                t1.elapsed().as_secs_f64()
            );
        }
    })
    .with_context(|| format!("writing the levels of detail of {}", args.out.display()))?;
    let lod_s = t1.elapsed().as_secs_f64();
    let sums = store.store().summaries()?;
    let dual: u64 = sums.iter().map(|s| u64::from(s.dual_texels)).sum();
    let low = sums.iter().map(|s| s.low_min).min().unwrap_or(0);
    let top = sums.iter().map(|s| s.top_max).max().unwrap_or(0);
    let texels = u64::from(w) * u64::from(h);
    let mut out = String::new();
    outln!(
        out,
        "wrote {} ({w}x{h}, seed {}, {total} chunks of {cw}x{ch}): generated and written in {total_s:.2} s, {} levels of detail in {lod_s:.2} s",
        args.out.display(),
        args.seed,
        store.store().lod_levels()
    );
    outln!(
        out,
        "dual {:.2} %  heights {low}..{top}  (from the chunk summaries; `strata info` for roughness on worlds that fit in memory)",
        dual as f64 * 100.0 / texels as f64
    );
    describe(&mut out, &world, &generator.landmarks());
    if let Some(png) = &args.preview {
        let area = area.unwrap_or_else(|| default_area_of(&world, w, h));
        // The area and the margins the shading reads (1 texel around,
        // 48 up-left for the cast shadows), generated alone.
        let margin = 50;
        let side = |n: u32, map: u32| (n + 2 * margin).next_power_of_two().min(map);
        let (pw, ph) = (side(area.width, w), side(area.height, h));
        let (px, py) = (area.x - i64::from(margin), area.y - i64::from(margin));
        let patch = generator.patch(px, py, pw, ph)?;
        // `patch` starts at an even column: the area's place in it.
        let odd = px.rem_euclid(i64::from(w)) & 1;
        let inner = preview::Region {
            x: i64::from(margin) + odd,
            y: i64::from(margin),
            ..area
        };
        let rgb = preview::shade(&patch, &world.palette, &world.config, inner);
        save_rgb(rgb, area, png)?;
        outln!(
            out,
            "preview of {},{} {}x{}: {}",
            area.x,
            area.y,
            area.width,
            area.height,
            png.display()
        );
    }
    let _ = std::io::Write::write_all(&mut std::io::stdout(), out.as_bytes());
    Ok(())
}

/// The landmarks, views and edit site, for the report.
fn describe(out: &mut String, world: &World, landmarks: &[(String, String, u32, u32)]) {
    outln!(out, "landmarks:");
    for (name, what, x, y) in landmarks {
        outln!(out, "  {name:<8} {x:>5},{y:<5}  {what}");
    }
    outln!(out, "views (views.txt):");
    for v in &world.views {
        outln!(out, "  {v}");
    }
    if let Some(edit) = &world.edit {
        outln!(
            out,
            "edit site (edit.txt): crater {},{} radius {} depth {}, camera {} {}",
            edit.centre_x,
            edit.centre_y,
            edit.radius,
            edit.depth,
            edit.camera.spec_string(),
            edit.camera.pitch
        );
    }
}

fn parse_area(text: &str) -> anyhow::Result<preview::Region> {
    let bad =
        || anyhow::anyhow!("preview area `{text}` is not X,Y,WIDTHxHEIGHT (e.g. 0,0,512x512)");
    let mut parts = text.split(',');
    let (Some(x), Some(y), Some(size), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(bad());
    };
    let (width, height) = parse_size(size).map_err(|_| bad())?;
    if width == 0 || height == 0 || u64::from(width) * u64::from(height) > 1 << 26 {
        bail!("preview area {width}x{height} must be non-empty and at most 2^26 pixels");
    }
    Ok(preview::Region {
        x: x.trim().parse().map_err(|_| bad())?,
        y: y.trim().parse().map_err(|_| bad())?,
        width,
        height,
    })
}

/// 512x512 around the hangar view (the whole map when smaller).
fn default_area(world: &World) -> preview::Region {
    default_area_of(world, world.level.width(), world.level.height())
}

/// [`default_area`] of a `width x height` map (a store's world has no level).
fn default_area_of(world: &World, width: u32, height: u32) -> preview::Region {
    let (w, h) = (width.min(512), height.min(512));
    let centre = world
        .views
        .iter()
        .find(|v| v.name == "hangar")
        .map(|v| (v.x as i64, v.y as i64))
        .unwrap_or((0, 0));
    preview::Region {
        x: centre.0 - i64::from(w / 2),
        y: centre.1 - i64::from(h / 2),
        width: w,
        height: h,
    }
}

pub fn write_preview(
    world: &World,
    area: preview::Region,
    png: &std::path::Path,
) -> anyhow::Result<()> {
    let rgb = preview::shade(&world.level, &world.palette, &world.config, area);
    save_rgb(rgb, area, png)
}

fn save_rgb(rgb: Vec<u8>, area: preview::Region, png: &std::path::Path) -> anyhow::Result<()> {
    let image =
        image::RgbImage::from_raw(area.width, area.height, rgb).context("preview buffer size")?;
    image
        .save(png)
        .with_context(|| format!("writing the preview {}", png.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preview_areas_parse_or_explain() {
        let r = parse_area("-10,20,64x32").unwrap();
        assert_eq!((r.x, r.y, r.width, r.height), (-10, 20, 64, 32));
        for bad in [
            "",
            "1,2",
            "1,2,3",
            "a,2,4x4",
            "1,2,4x4,5",
            "1,2,0x4",
            "0,0,65536x65536",
        ] {
            assert!(parse_area(bad).is_err(), "{bad}");
        }
    }
}
