//! `strata generate`: write a generated Vangers-like world directory in the
//! real file format, optionally with a top-down preview picture.

use anyhow::{Context, bail};
use std::path::PathBuf;
use std::time::Instant;
use strata_level::generate::{
    GenerateParams, Knobs, generate_with, landmark_list, parse_size, preview,
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
    /// Map size WIDTHxHEIGHT, powers of two from 256 to 32768 a side.
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
    let t0 = Instant::now();
    let world = generate_with(&params, &knobs)?;
    let generate_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    match args.to {
        super::convert::To::Vangers => io::write_world(&args.out, &world)
            .with_context(|| format!("writing {}", args.out.display()))?,
        super::convert::To::Store => {
            strata_store::DirStore::create(&args.out, &world, &strata_store::Layout::default())
                .with_context(|| format!("writing the store {}", args.out.display()))?;
        }
    }
    let write_s = t1.elapsed().as_secs_f64();
    let mut out_notes = String::new();
    if world.config.map_power_x != 11 {
        outln!(
            out_notes,
            "note: the original game's loader accepts only 2048-wide maps (Map Power X=11); vange-rs takes the size from world.ini"
        );
    }
    let stats = LevelStats::compute(&world.level);
    // Collected and written once: a closed pipe (`| head`) is not an error worth a panic.
    let mut out = String::new();
    outln!(
        out,
        "wrote {} ({width}x{height}, seed {}): generated in {generate_s:.2} s, written in {write_s:.2} s",
        args.out.display(),
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
    outln!(out, "landmarks:");
    for (name, what, x, y) in landmark_list(&params)? {
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
    out.push_str(&out_notes);
    let _ = std::io::Write::write_all(&mut std::io::stdout(), out.as_bytes());
    Ok(())
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
    let (w, h) = (world.level.width().min(512), world.level.height().min(512));
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
