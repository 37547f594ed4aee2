//! `strata render`: one method, one or more views, on the GPU. Writes
//! `color.png`, `depth.f32` (little-endian f32 depth-buffer values, row-major,
//! 1.0 = sky) and `render.json` per view; `--json` prints one line per view.

use crate::adapter_arg::AdapterArgs;
use crate::world_arg::WorldArgs;
use anyhow::{Context, bail};
use std::path::PathBuf;
use strata_camera::Camera;
use strata_level::{ViewSpec, views::parse_views};
use strata_render::report::{measure_view, write_outputs};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// Method: ray, ray-compute (and whatever else `strata_render::methods::METHODS` lists).
    #[arg(long, default_value = "ray")]
    pub method: String,
    /// One view `X,Y:YAW:EYE[:under]` (needs --pitch).
    #[arg(long, value_name = "SPEC", conflicts_with_all = ["views", "view_name"], requires = "pitch")]
    pub view: Option<String>,
    /// Pitch of --view, degrees (negative looks down).
    #[arg(long, allow_hyphen_values = true)]
    pub pitch: Option<f32>,
    /// Every view of a views file (`NAME X,Y:YAW:EYE[:under] PITCH` per line).
    #[arg(long, value_name = "FILE", conflicts_with = "view_name")]
    pub views: Option<PathBuf>,
    /// One of the world's own views, by name. With no view option: all of them.
    #[arg(long, value_name = "NAME")]
    pub view_name: Option<String>,
    /// Image size.
    #[arg(long, default_value = "1280x800", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Timed frames per view.
    #[arg(long, default_value_t = 40)]
    pub frames: u32,
    /// Untimed warm-up frames after the first.
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    #[command(flatten)]
    pub method_args: MethodArgs,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// Output directory (one sub-directory per view when there are several).
    #[arg(long, default_value = "render-out")]
    pub out: PathBuf,
    /// Print one JSON line per view instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Every method's setting as flags; `strata compare` (or anything else that
/// builds a renderer) can `#[command(flatten)]` this. Defaults come from
/// [`MethodSettings::default`], so the help text and the library agree.
/// Values are checked here for their form (positive, in range); each method
/// still checks its own field when it is built.
#[derive(clap::Args, Clone, Debug)]
pub struct MethodArgs {
    /// `ray`, `ray-compute`: forward samples per ray.
    #[arg(long, value_name = "N", value_parser = parse_positive,
          default_value_t = MethodSettings::default().ray_steps)]
    pub ray_steps: u32,
    /// `voxel`, `voxel-compute`: occupancy voxel size in texels, X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_voxel_size,
          default_value_t = Triple(MethodSettings::default().voxel_size))]
    pub voxel_size: Triple<u32>,
    /// `voxel`, `voxel-compute`: traversal step budget.
    #[arg(long, value_name = "N", value_parser = parse_positive,
          default_value_t = MethodSettings::default().voxel_steps)]
    pub voxel_steps: u32,
    /// `sliced`: horizontal slices.
    #[arg(long, value_name = "N", value_parser = parse_positive,
          default_value_t = MethodSettings::default().slices)]
    pub slices: u32,
    /// `sliced`: per pixel, the exact surface crossing on the ray up to the nearest kept slice (a full-screen pass after the slices).
    #[arg(long)]
    pub sliced_refine: bool,
    /// `scattered`: grid density X,Y,Z in screen terms (4 → 1.25 samples per pixel across, 1 per pixel along, 1.25 per pixel of projected height), or one D for all three.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_density,
          default_value_t = Triple(MethodSettings::default().scatter_density))]
    pub scatter_density: Triple<f32>,
    /// `mesh`: fit quality q in [0, 1]; max error 2^(4(1-q)) height units.
    #[arg(long, value_name = "Q", value_parser = parse_quality,
          default_value_t = MethodSettings::default().mesh_quality)]
    pub mesh_quality: f32,
    /// `mesh`: constrain the fit to the single/double region outline.
    #[arg(long)]
    pub mesh_outline: bool,
    /// `mesh`: LOD by projected error: the most a chunk's max error may cover on screen, in pixels.
    #[arg(long, value_name = "PX", value_parser = parse_lod_pixels,
          default_value_t = MethodSettings::default().mesh_lod_pixels)]
    pub mesh_lod_pixels: f32,
    /// `mesh`, a diagnostic: shade with the height-field gradient normal instead of the flat one.
    #[arg(long)]
    pub mesh_gradient_normal: bool,
    /// Turn the shared shadow map off.
    #[arg(long)]
    pub no_shadows: bool,
}

impl MethodArgs {
    pub fn settings(&self) -> MethodSettings {
        MethodSettings {
            ray_steps: self.ray_steps,
            voxel_size: self.voxel_size.0,
            voxel_steps: self.voxel_steps,
            slices: self.slices,
            sliced_refine: self.sliced_refine,
            scatter_density: self.scatter_density.0,
            mesh_quality: self.mesh_quality,
            mesh_outline: self.mesh_outline,
            mesh_lod_pixels: self.mesh_lod_pixels,
            mesh_gradient_normal: self.mesh_gradient_normal,
            shadows: !self.no_shadows,
        }
    }
}

/// Three values written `X,Y,Z` (clap shows defaults through `Display`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triple<T>(pub [T; 3]);

impl<T: std::fmt::Display> std::fmt::Display for Triple<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = &self.0;
        write!(f, "{x},{y},{z}")
    }
}

fn parse_positive(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(v) if v > 0 => Ok(v),
        Ok(_) => Err("must be at least 1 (got 0)".into()),
        Err(_) => Err(format!("`{text}` is not a positive whole number")),
    }
}

fn parse_positive_f32(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a positive number")),
    }
}

fn parse_voxel_size(text: &str) -> Result<Triple<u32>, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [x, y, z] = parts[..] else {
        return Err(format!(
            "`{text}` is not X,Y,Z (three voxel sizes in texels, e.g. 4,8,2)"
        ));
    };
    let size = |t| parse_positive(t).map_err(|e| format!("voxel size {e}"));
    Ok(Triple([size(x)?, size(y)?, size(z)?]))
}

fn parse_density(text: &str) -> Result<Triple<f32>, String> {
    let v = text
        .split(',')
        .map(|t| parse_positive_f32(t).map_err(|e| format!("density {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    match v[..] {
        [d] => Ok(Triple([d; 3])),
        [x, y, z] => Ok(Triple([x, y, z])),
        _ => Err(format!(
            "`{text}` is not X,Y,Z or D (samples per unit, e.g. 4,4,4)"
        )),
    }
}

fn parse_quality(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(q) if (0.0..=1.0).contains(&q) => Ok(q),
        Ok(q) => Err(format!("mesh quality {q} is outside [0, 1]")),
        Err(_) => Err(format!("`{text}` is not a number in [0, 1]")),
    }
}

fn parse_lod_pixels(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(p) if p.is_finite() && p > 0.0 => Ok(p),
        _ => Err(format!(
            "mesh LOD tolerance `{text}` is not a positive number of pixels"
        )),
    }
}

pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once('x')
        .ok_or("size must be WxH, e.g. 1280x800")?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("width `{w}` is not a number"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("height `{h}` is not a number"))?;
    if w == 0 || h == 0 {
        return Err(format!("size {w}x{h} must be positive"));
    }
    Ok((w, h))
}

fn select_views(args: &Args, world: &strata_level::World) -> anyhow::Result<Vec<ViewSpec>> {
    let views = match (&args.view, &args.views, &args.view_name) {
        (Some(spec), _, _) => {
            let pitch = args.pitch.context("--view needs --pitch DEG")?;
            vec![ViewSpec::parse("view", spec, pitch).context("--view")?]
        }
        (None, Some(file), _) => {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("reading views file {}", file.display()))?;
            parse_views(&text).with_context(|| format!("views file {}", file.display()))?
        }
        (None, None, Some(name)) => {
            let v = world.views.iter().find(|v| &v.name == name).cloned();
            let names: Vec<&str> = world.views.iter().map(|v| v.name.as_str()).collect();
            vec![v.with_context(|| {
                format!(
                    "the world has no view `{name}`; it has: {}",
                    names.join(", ")
                )
            })?]
        }
        (None, None, None) => world.views.clone(),
    };
    if views.is_empty() {
        bail!("no views: give --view SPEC --pitch DEG, --views FILE or --view-name NAME");
    }
    for v in &views {
        if v.name.is_empty() || v.name.contains(['/', '\\']) || v.name == "." || v.name == ".." {
            bail!("view name `{}` cannot be a directory name", v.name);
        }
    }
    Ok(views)
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    strata_render::methods::entry(&args.method)?;
    let world = args.world.load()?;
    let views = select_views(&args, &world)?;
    let (w, h) = args.size;
    let cameras = views
        .iter()
        .map(|v| {
            Camera::from_view(&world.level, v, w, h).with_context(|| format!("view `{}`", v.name))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let settings = args.method_args.settings();
    let gpu = Gpu::open(&args.adapter.choice())?;
    let mut renderer = Renderer::new(
        &gpu,
        &world.level,
        &TerrainColors::from_world(&world),
        &args.method,
        &settings,
        w,
        h,
    )?;
    let setup_ms = renderer.setup_ms();
    if !args.json {
        let r = &gpu.report;
        println!(
            "adapter: {} ({}, driver {} {})",
            r.name, r.backend, r.driver, r.driver_info
        );
        if !r.timestamps {
            println!(
                "no GPU timestamps on this adapter: gpu_ms is null, CPU submit-and-wait reported"
            );
        }
        println!(
            "{:<14} {:>10} {:>10} {:>10} {:>10} {:>12}",
            "view", "gpu ms", "cpu ms", "first ms", "setup ms", "gpu bytes"
        );
    }
    for (view, camera) in views.iter().zip(&cameras) {
        let (report, color, depth) = measure_view(
            &mut renderer,
            &world.name,
            view,
            camera,
            args.warmup,
            args.frames,
        )?;
        let dir = if views.len() == 1 {
            args.out.clone()
        } else {
            args.out.join(&view.name)
        };
        write_outputs(&dir, &report, &color, &depth)?;
        if args.json {
            println!("{}", serde_json::to_string(&report)?);
        } else {
            let gpu = report
                .gpu_ms
                .map(|s| format!("{:.3}", s.mean))
                .unwrap_or_else(|| "n/a".into());
            println!(
                "{:<14} {:>10} {:>10.3} {:>10.1} {:>10.1} {:>12}",
                view.name,
                gpu,
                report.cpu_ms.mean,
                report.prep.first_frame_ms,
                setup_ms,
                report.gpu_bytes
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(clap::Parser)]
    struct Cli {
        #[command(flatten)]
        m: MethodArgs,
    }

    fn parse(args: &[&str]) -> Result<MethodSettings, String> {
        let argv = std::iter::once("t").chain(args.iter().copied());
        Cli::try_parse_from(argv)
            .map(|c| c.m.settings())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn no_flags_give_the_library_defaults() {
        assert_eq!(parse(&[]).unwrap(), MethodSettings::default());
    }

    #[test]
    fn every_setting_has_a_flag() {
        let s = parse(&[
            "--ray-steps=64",
            "--voxel-size=2,4,1",
            "--voxel-steps=50",
            "--slices=256",
            "--scatter-density=2,3,4.5",
            "--mesh-quality=0.75",
            "--no-shadows",
        ])
        .unwrap();
        let want = MethodSettings {
            ray_steps: 64,
            voxel_size: [2, 4, 1],
            voxel_steps: 50,
            slices: 256,
            sliced_refine: false,
            scatter_density: [2.0, 3.0, 4.5],
            mesh_quality: 0.75,
            shadows: false,
            ..MethodSettings::default()
        };
        assert_eq!(s, want);
        assert_eq!(
            parse(&["--scatter-density=3"]).unwrap().scatter_density,
            [3.0; 3]
        );
    }

    #[test]
    fn bad_values_are_clear_errors() {
        for (args, needle) in [
            (&["--slices=0"][..], "at least 1"),
            (&["--ray-steps=many"], "not a positive whole number"),
            (&["--voxel-size=4,8"], "X,Y,Z"),
            (&["--voxel-size=4,0,2"], "voxel size"),
            (&["--scatter-density=1,2"], "X,Y,Z or D"),
            (&["--scatter-density=1,-2,3"], "not a positive number"),
            (&["--mesh-quality=1.5"], "outside [0, 1]"),
            (&["--mesh-quality=high"], "not a number"),
        ] {
            let e = parse(args).unwrap_err();
            assert!(e.contains(needle), "{args:?}: {e}");
        }
    }
}
