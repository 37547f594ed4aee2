//! `cargo run -p strata-example-drive -- [METHOD] [--size WxH] [--seconds S] [--frames N --out DIR]`
//!
//! With a display: a window drawing the terrain with METHOD (default `mesh`)
//! and a vehicle driving across it, back and forth, until closed (or for
//! `--seconds S`). With
//! `--frames N --out DIR` (no display needed): N frames along the road as
//! PNGs, and a line per frame saying whether the vehicle shows.

mod window;

use std::path::PathBuf;
use strata_example_drive::{Drive, HEADLESS_COLOR, Offscreen, open_gpu, vehicle};

struct Args {
    method: String,
    size: (u32, u32),
    frames: Option<u32>,
    out: Option<PathBuf>,
    /// Close the window after this many seconds (a smoke test under Xvfb).
    seconds: Option<f32>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut args = Args {
        method: "mesh".into(),
        size: (960, 600),
        frames: None,
        out: None,
        seconds: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .ok_or_else(|| anyhow::anyhow!("{name} needs a value"))
        };
        match a.as_str() {
            "--frames" => {
                let v = value("--frames")?;
                args.frames = Some(
                    v.parse()
                        .map_err(|_| anyhow::anyhow!("--frames {v:?}: not a frame count"))?,
                );
            }
            "--out" => args.out = Some(value("--out")?.into()),
            "--seconds" => {
                let v = value("--seconds")?;
                args.seconds =
                    Some(v.parse().ok().filter(|s: &f32| *s > 0.0).ok_or_else(|| {
                        anyhow::anyhow!("--seconds {v:?}: not a positive number")
                    })?);
            }
            "--size" => {
                let v = value("--size")?;
                args.size = v
                    .split_once('x')
                    .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
                    .filter(|&(w, h)| w > 0 && h > 0)
                    .ok_or_else(|| anyhow::anyhow!("--size {v:?}: expected WxH, e.g. 960x600"))?;
            }
            "-h" | "--help" => {
                println!("drive [METHOD] [--size WxH] [--seconds S] [--frames N --out DIR]");
                std::process::exit(0);
            }
            m if !m.starts_with('-') => args.method = m.to_string(),
            other => anyhow::bail!("unknown argument {other:?}"),
        }
    }
    Ok(args)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("drive: {e:#}");
        std::process::exit(1);
    }
}

fn run() -> anyhow::Result<()> {
    let args = parse_args()?;
    match (args.frames, &args.out) {
        (Some(frames), Some(out)) => headless(&args.method, args.size, frames, out),
        (None, None) => window::run(&args.method, args.size, args.seconds),
        _ => anyhow::bail!("the headless mode needs both --frames N and --out DIR"),
    }
}

/// No window: the same frames into textures of a window's usual formats.
fn headless(
    method: &str,
    size: (u32, u32),
    frames: u32,
    out: &std::path::Path,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .map_err(|e| anyhow::anyhow!("cannot create --out {}: {e}", out.display()))?;
    let gpu = open_gpu(strata_render::AdapterChoice::default().instance(), None)?;
    let mut drive = Drive::new(&gpu, method, HEADLESS_COLOR, size)?;
    let targets = Offscreen::new(&gpu.device, size);
    for f in 0..frames {
        let t = f as f32 / (frames.max(2) - 1) as f32;
        let start = std::time::Instant::now();
        let centre = drive
            .draw(Some(t), &targets.color_view, None, &targets.depth_view)?
            .expect("a vehicle was drawn");
        let rgba = targets.read_rgba(&gpu)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let seen = drive.camera.project(centre).and_then(|p| {
            let (x, y) = (p.x as i64, p.y as i64);
            let inside = x >= 0 && y >= 0 && x < i64::from(size.0) && y < i64::from(size.1);
            inside.then(|| {
                let k = ((y as u32 * size.0 + x as u32) * 4) as usize;
                vehicle::is_vehicle_pixel([rgba[k], rgba[k + 1], rgba[k + 2]])
            })
        });
        println!(
            "frame {f}: vehicle at ({:.0}, {:.0}, {:.1}): {} ({ms:.0} ms with read-back)",
            centre.x,
            centre.y,
            centre.z,
            match seen {
                Some(true) => "visible",
                Some(false) => "hidden by terrain",
                None => "off screen",
            }
        );
        let path = out.join(format!("drive-{method}-{f:03}.png"));
        image::save_buffer(
            &path,
            &rgba,
            size.0,
            size.1,
            image::ExtendedColorType::Rgba8,
        )
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
    }
    println!("wrote {frames} frames to {}", out.display());
    Ok(())
}
