//! Render every view of a world with some methods and print one JSON line
//! each (the same `RenderReport` as `strata render --json`), without the CLI:
//! `cargo run --release -p strata-render --example views -- [--level DIR]
//!  [--size WxH] [--frames N] [--no-shadows] [--out DIR] [--view NAME] METHOD...`
//! Without `--level`, the built-in generated world.

use anyhow::Context;
use std::time::Instant;
use strata_camera::Camera;
use strata_render::report::measure_view;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut level, mut size, mut frames, mut shadows) = (None, (1280, 800), 40, true);
    let (mut methods, mut out, mut only) = (Vec::new(), None, None);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--level" => level = Some(args.next().context("--level DIR")?),
            "--size" => {
                let s = args.next().context("--size WxH")?;
                let (w, h) = s.split_once('x').context("WxH")?;
                size = (w.parse()?, h.parse()?);
            }
            "--frames" => frames = args.next().context("--frames N")?.parse()?,
            "--no-shadows" => shadows = false,
            "--out" => out = Some(args.next().context("--out DIR")?),
            "--view" => only = Some(args.next().context("--view NAME")?),
            m => methods.push(m.to_string()),
        }
    }
    let start = Instant::now();
    let world = match level {
        Some(dir) => strata_level::io::load_world(dir.as_ref(), Default::default())?,
        None => strata_level::generate::generate(&Default::default())?,
    };
    eprintln!(
        "world {} ready in {:.1} s",
        world.name,
        start.elapsed().as_secs_f64()
    );
    let gpu = Gpu::headless()?;
    eprintln!("adapter {:?}", gpu.report);
    let settings = MethodSettings {
        shadows,
        ..Default::default()
    };
    let colors = TerrainColors::from_world(&world);
    for method in &methods {
        let mut r = Renderer::new(
            &gpu,
            &world.level,
            &colors,
            method,
            &settings,
            size.0,
            size.1,
        )?;
        for view in world
            .views
            .iter()
            .filter(|v| only.as_ref().is_none_or(|o| o == &v.name))
        {
            let camera = Camera::from_view(&world.level, view, size.0, size.1)?;
            let (report, color, depth) =
                measure_view(&mut r, &world.name, view, &camera, 3, frames)?;
            if let Some(dir) = &out {
                let dir = std::path::Path::new(dir).join(method).join(&view.name);
                strata_render::report::write_outputs(&dir, &report, &color, &depth)?;
            }
            println!("{}", serde_json::to_string(&report)?);
        }
    }
    Ok(())
}
