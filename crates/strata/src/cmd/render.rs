//! `strata render`: one method, one or more views, on the GPU. Writes
//! `color.png`, `depth.f32` (little-endian f32 depth-buffer values, row-major,
//! 1.0 = sky) and `render.json` per view; `--json` prints one line per view.

use crate::adapter_arg::AdapterArgs;
use crate::paged_arg::{PagedArgs, PagedWorld, open_paged};
use crate::world_arg::WorldArgs;
use anyhow::{Context, bail};
use std::path::PathBuf;
use strata_camera::Camera;
use strata_level::{ViewSpec, views::parse_views};
use strata_render::methods::{Flag, METHODS};
use strata_render::report::{measure_view, write_outputs};
use strata_render::{MethodSettings, Renderer, TerrainColors};

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
    /// Far plane, texels along the view axis (default 600, the paper's):
    /// horizon views of large worlds (paged terrain draws far columns from
    /// coarser levels of detail; see `--lod-pixels`).
    #[arg(long, value_name = "TEXELS", value_parser = parse_far)]
    pub far: Option<f32>,
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
    #[command(flatten)]
    pub paged: PagedArgs,
    /// Paged terrain: most frames drawn per view before the timed ones,
    /// waiting for every page the view reads.
    #[arg(long, default_value_t = 600)]
    pub converge_frames: u32,
    /// Output directory (one sub-directory per view when there are several).
    #[arg(long, default_value = "render-out")]
    pub out: PathBuf,
    /// Print one JSON line per view instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Every method's knobs as flags, as each method's entry in
/// `strata_render::methods::METHODS` declares them (`--ray-steps N`,
/// `--mesh-quality Q`, ...), plus `--no-shadows`; `strata compare` (or
/// anything else that builds a renderer) can `#[command(flatten)]` this.
/// Defaults come from [`MethodSettings::default`], so the help text and the
/// library agree. Values are checked here for their form (positive, in
/// range); each method still checks its own field when it is built.
#[derive(Clone, Debug)]
pub struct MethodArgs {
    settings: MethodSettings,
}

impl MethodArgs {
    pub fn settings(&self) -> MethodSettings {
        self.settings.clone()
    }
}

/// Every method's flags, each once (a method's variants share their knobs).
fn flags() -> Vec<&'static Flag> {
    let mut out: Vec<&'static Flag> = Vec::new();
    for flag in METHODS.iter().flat_map(|m| m.knobs.flags) {
        if !out.iter().any(|f| f.long == flag.long) {
            out.push(flag);
        }
    }
    out
}

const NO_SHADOWS: &str = "no-shadows";

impl clap::Args for MethodArgs {
    fn augment_args(mut cmd: clap::Command) -> clap::Command {
        use clap::{Arg, ArgAction};
        let defaults = MethodSettings::default();
        for flag in flags() {
            let arg = Arg::new(flag.long).long(flag.long).help(flag.help);
            cmd = cmd.arg(match flag.value {
                None => arg.action(ArgAction::SetTrue),
                Some(name) => {
                    // Checked when parsed, with the flag's own message.
                    let check = move |text: &str| -> Result<String, String> {
                        (flag.apply)(text, &mut MethodSettings::default())?;
                        Ok(text.to_string())
                    };
                    let default: &'static str = Box::leak((flag.default)(&defaults).into());
                    arg.value_name(name)
                        .value_parser(check)
                        .default_value(default)
                }
            });
        }
        cmd.arg(
            Arg::new(NO_SHADOWS)
                .long(NO_SHADOWS)
                .action(ArgAction::SetTrue)
                .help("Turn the shared shadow map off."),
        )
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

impl clap::FromArgMatches for MethodArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut settings = MethodSettings::default();
        for flag in flags() {
            let value = match flag.value {
                None => matches.get_flag(flag.long).then(|| "true".to_string()),
                Some(_) => matches.get_one::<String>(flag.long).cloned(),
            };
            if let Some(value) = value {
                (flag.apply)(&value, &mut settings)
                    .map_err(|e| clap::Error::raw(clap::error::ErrorKind::ValueValidation, e))?;
            }
        }
        settings.shadows = !matches.get_flag(NO_SHADOWS);
        Ok(MethodArgs { settings })
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
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

fn select_views(args: &Args, world_views: &[ViewSpec]) -> anyhow::Result<Vec<ViewSpec>> {
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
            let v = world_views.iter().find(|v| &v.name == name).cloned();
            let names: Vec<&str> = world_views.iter().map(|v| v.name.as_str()).collect();
            vec![v.with_context(|| {
                format!(
                    "the world has no view `{name}`; it has: {}",
                    names.join(", ")
                )
            })?]
        }
        (None, None, None) => world_views.to_vec(),
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
    if let Some(paged) = open_paged(&args.world, &args.paged)? {
        return run_paged(&args, &paged);
    }
    let world = args.world.load()?;
    let views = select_views(&args, &world.views)?;
    let (w, h) = args.size;
    let cameras = views
        .iter()
        .map(|v| {
            Camera::from_view(&world.level, v, w, h)
                .with_context(|| format!("view `{}`", v.name))
                .map(|c| with_far(c, args.far))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let settings = args.method_args.settings();
    let gpu = args.adapter.open()?;
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

/// `render` over paged terrain: per view, frames until nothing is pending,
/// then the timed frames (the camera is still: no uploads among them).
fn run_paged(args: &Args, world: &PagedWorld) -> anyhow::Result<()> {
    let views = select_views(args, &world.views)?;
    let (w, h) = args.size;
    let cameras = views
        .iter()
        .map(|v| world.camera(v, w, h).map(|c| with_far(c, args.far)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let gpu = args.adapter.open()?;
    let mut renderer = Renderer::new_paged(
        &gpu,
        world.source.clone(),
        &world.colors,
        &args.method,
        &args.method_args.settings(),
        w,
        h,
        PagedWorld::options(&args.paged),
    )?;
    let plan = *renderer.paged_terrain().expect("a paged renderer").plan();
    // The budget and bytes with the mesh's index pool (the plan is the atlas's part).
    let stats = renderer.paged_terrain().expect("a paged renderer").stats();
    if !args.json {
        let r = &gpu.report;
        println!(
            "adapter: {} ({}, driver {} {})",
            r.name, r.backend, r.driver, r.driver_info
        );
        println!(
            "paged: {}x{} world, {} chunks; budget {} B: {} slots, {} B kept on the GPU",
            world.size.0, world.size.1, plan.chunks, stats.gpu_budget, plan.slots, stats.gpu_bytes
        );
        println!(
            "{:<14} {:>10} {:>10} {:>9} {:>9} {:>12}",
            "view", "gpu ms", "cpu ms", "converge", "resident", "paged bytes"
        );
    }
    for (view, camera) in views.iter().zip(&cameras) {
        let frames = renderer
            .converge(camera, args.converge_frames)
            .with_context(|| format!("view `{}`", view.name))?;
        let (mut report, color, depth) = measure_view(
            &mut renderer,
            &world.name,
            view,
            camera,
            args.warmup,
            args.frames,
        )?;
        report.converge_frames = Some(frames);
        let dir = if views.len() == 1 {
            args.out.clone()
        } else {
            args.out.join(&view.name)
        };
        write_outputs(&dir, &report, &color, &depth)?;
        if args.json {
            println!("{}", serde_json::to_string(&report)?);
        } else {
            let paging = report.paging.clone().unwrap_or_default();
            println!(
                "{:<14} {:>10} {:>10.3} {:>9} {:>9} {:>12}",
                view.name,
                report
                    .gpu_ms
                    .map(|s| format!("{:.3}", s.mean))
                    .unwrap_or_else(|| "n/a".into()),
                report.cpu_ms.mean,
                frames,
                paging.resident_pages,
                paging.gpu_bytes
            );
        }
    }
    Ok(())
}

/// `camera` with its far plane at `far`, if given.
fn with_far(mut camera: Camera, far: Option<f32>) -> Camera {
    if let Some(far) = far {
        camera.far = far;
    }
    camera
}

/// A far plane: finite, beyond the near plane, at most 65536 texels.
pub fn parse_far(text: &str) -> Result<f32, String> {
    let far: f32 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a distance in texels"))?;
    if !far.is_finite() || far <= strata_camera::DEFAULT_NEAR || far > 65536.0 {
        return Err(format!(
            "a far plane must lie between the near plane ({}) and 65536 texels, got {text}",
            strata_camera::DEFAULT_NEAR
        ));
    }
    Ok(far)
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
