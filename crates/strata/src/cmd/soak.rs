//! `strata soak`: the viewer under a long scripted session (issue 20): a
//! generated world, a script of N actions (digs, undos, method switches,
//! window resizes, A/B splits, flying, views) run through `strata view`
//! in a real window (an Xvfb it starts when `DISPLAY` is unset), sampling
//! the process's RSS and the renderer's retained GPU bytes every K actions
//! (script `memory`). Prints start / end / peak and writes `soak.json`. A
//! bench command: its numbers are reported, not asserted.

use anyhow::{Context, bail};
use serde::Serialize;
use std::path::PathBuf;
use std::process::Command;
use strata_level::generate::{GenerateParams, generate, parse_size};

#[derive(clap::Args)]
pub struct Args {
    /// Actions in the script.
    #[arg(long, value_name = "N", default_value_t = 10_000)]
    pub actions: u32,
    /// Sample memory every N actions.
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub sample_every: u32,
    /// The generated world's size.
    #[arg(long, value_name = "WxH", default_value = "256x512")]
    pub world: String,
    /// Seed of the world and of the action sequence.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Window size (the picture is the window's, render scale 1).
    #[arg(long, value_name = "WxH", default_value = "160x100", value_parser = crate::cmd::render::parse_size)]
    pub size: (u32, u32),
    /// Methods switched between (default: every method).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub methods: Vec<String>,
    /// Draw the 1024² shadow map every frame (off by default: on a CPU
    /// rasteriser it is most of a frame, 0.4 s an action instead of 0.09).
    #[arg(long)]
    pub shadows: bool,
    /// Where the world, the script, the viewer's log and soak.json go.
    #[arg(long, value_name = "DIR", default_value = "out/soak")]
    pub out: PathBuf,
}

/// One `memory` line of the viewer.
#[derive(Clone, Debug, Default, Serialize)]
struct Sample {
    frames: u64,
    rss_bytes: u64,
    gpu_bytes: u64,
    method_cpu_bytes: u64,
    undo_bytes: u64,
    undo_depth: u64,
    kept: u64,
}

impl Sample {
    fn parse(line: &str) -> Option<Sample> {
        let rest = line.strip_prefix("memory ")?;
        let mut s = Sample::default();
        for pair in rest.split_whitespace() {
            let (key, value) = pair.split_once('=')?;
            let value: u64 = value.parse().ok()?;
            match key {
                "frames" => s.frames = value,
                "rss_bytes" => s.rss_bytes = value,
                "gpu_bytes" => s.gpu_bytes = value,
                "method_cpu_bytes" => s.method_cpu_bytes = value,
                "undo_bytes" => s.undo_bytes = value,
                "undo_depth" => s.undo_depth = value,
                "kept" => s.kept = value,
                _ => {}
            }
        }
        Some(s)
    }
}

/// xorshift64*: a reproducible action sequence needs no more than this.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn fraction(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * (self.below(1000) as f32 / 1000.0)
    }
}

/// The script: `actions` actions, a `memory` sample every `every`, and
/// counts per kind.
fn script(
    actions: u32,
    every: u32,
    seed: u64,
    methods: &[String],
    views: &[String],
    size: (u32, u32),
) -> (String, Vec<(&'static str, u32)>) {
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut out = String::from("view edit\nmemory\n");
    let mut counts: Vec<(&'static str, u32)> = [
        "dig", "undo", "method", "window", "split", "fly", "turn", "view",
    ]
    .iter()
    .map(|k| (*k, 0))
    .collect();
    let sizes = [
        size,
        (size.0 * 5 / 4, size.1 * 5 / 4),
        (size.0 * 3 / 4, size.1 * 3 / 4),
    ];
    for i in 1..=actions {
        let roll = rng.below(100);
        let kind = match roll {
            0..30 => {
                let (x, y) = (rng.fraction(0.2, 0.8), rng.fraction(0.4, 0.95));
                out.push_str(&format!("dig {x:.3} {y:.3}\n"));
                0
            }
            30..45 => {
                out.push_str("undo\n");
                1
            }
            45..58 => {
                let m = &methods[rng.below(methods.len() as u64) as usize];
                out.push_str(&format!("method {m}\n"));
                2
            }
            58..65 => {
                let (w, h) = sizes[rng.below(sizes.len() as u64) as usize];
                out.push_str(&format!("window {w} {h}\n"));
                3
            }
            65..73 => {
                if rng.below(3) == 0 {
                    out.push_str("split off\n");
                } else {
                    let m = &methods[rng.below(methods.len() as u64) as usize];
                    out.push_str(&format!("split {m}\n"));
                }
                4
            }
            73..85 => {
                let (f, r, u) = (
                    rng.fraction(-20.0, 20.0),
                    rng.fraction(-20.0, 20.0),
                    rng.fraction(-5.0, 5.0),
                );
                out.push_str(&format!("fly {f:.1} {r:.1} {u:.1}\n"));
                5
            }
            85..95 => {
                let (r, u) = (rng.fraction(-30.0, 30.0), rng.fraction(-5.0, 5.0));
                out.push_str(&format!("turn {r:.1} {u:.1}\n"));
                6
            }
            _ => {
                let v = &views[rng.below(views.len() as u64) as usize];
                out.push_str(&format!("view {v}\n"));
                7
            }
        };
        counts[kind].1 += 1;
        if i % every == 0 || i == actions {
            out.push_str("memory\n");
        }
    }
    (out, counts)
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.actions == 0 || args.sample_every == 0 {
        bail!("--actions and --sample-every must be at least 1");
    }
    let (width, height) = parse_size(&args.world)?;
    let methods: Vec<String> = if args.methods.is_empty() {
        strata_render::methods::names()
            .into_iter()
            .map(String::from)
            .collect()
    } else {
        for m in &args.methods {
            strata_render::methods::entry(m)?;
        }
        args.methods.clone()
    };
    let world = generate(&GenerateParams {
        seed: args.seed,
        width,
        height,
    })?;
    let world_dir = args.out.join("world");
    let _ = std::fs::remove_dir_all(&world_dir);
    strata_level::io::write_world(&world_dir, &world)?;
    let mut views: Vec<String> = world.views.iter().map(|v| v.name.clone()).collect();
    views.push("edit".into());
    let (text, counts) = script(
        args.actions,
        args.sample_every,
        args.seed,
        &methods,
        &views,
        args.size,
    );
    let script_path = args.out.join("soak.txt");
    std::fs::write(&script_path, text)
        .with_context(|| format!("writing {}", script_path.display()))?;
    let display = strata_viewer::x_display::XDisplay::open()?;
    let runtime = args.out.join("xdg");
    std::fs::create_dir_all(&runtime)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&runtime, std::fs::Permissions::from_mode(0o700))?;
    }
    let log_path = args.out.join("view.log");
    let stdout_path = args.out.join("view.out");
    eprintln!(
        "strata soak: {} actions through `strata view` at {}x{} on {} ({}x{} world); log in {}",
        args.actions,
        args.size.0,
        args.size.1,
        display.name,
        width,
        height,
        log_path.display()
    );
    let start = std::time::Instant::now();
    let mut view = Command::new(std::env::current_exe()?);
    view.args(["view", "--level"])
        .arg(&world_dir)
        .args(["--size", &format!("{}x{}", args.size.0, args.size.1)])
        .args(["--render-scale", "1", "--no-vsync", "--script"])
        .arg(&script_path)
        .arg("--out")
        .arg(args.out.join("view"))
        .env("DISPLAY", &display.name)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", &runtime)
        .stdout(std::fs::File::create(&stdout_path)?)
        .stderr(std::fs::File::create(&log_path)?);
    if !args.shadows {
        view.arg("--no-shadows");
    }
    let status = view.status().context("starting strata view")?;
    let seconds = start.elapsed().as_secs_f64();
    let stdout = std::fs::read_to_string(&stdout_path)?;
    let samples: Vec<Sample> = stdout.lines().filter_map(Sample::parse).collect();
    if !status.success() {
        let log = std::fs::read_to_string(&log_path).unwrap_or_default();
        let tail: Vec<&str> = log.lines().rev().take(15).collect();
        bail!(
            "strata view failed after {seconds:.0} s ({} samples):\n{}",
            samples.len(),
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        );
    }
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        bail!("the viewer printed no memory samples");
    };
    let peak = |f: fn(&Sample) -> u64| samples.iter().map(f).max().unwrap_or(0);
    // The start sample comes before any method but `ray` is built; the
    // first sample with every method kept is the fair baseline for growth.
    let all_kept = samples
        .iter()
        .find(|s| s.kept as usize >= methods.len())
        .unwrap_or(first);
    println!(
        "soak: {} actions ({}) in {seconds:.0} s, {} frames, {} samples",
        args.actions,
        counts
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect::<Vec<_>>()
            .join(", "),
        last.frames,
        samples.len()
    );
    println!(
        "{:<34} {:>10} {:>16} {:>10} {:>10}",
        "", "start", "all methods kept", "end", "peak"
    );
    let row = |name: &str, f: fn(&Sample) -> u64| {
        println!(
            "{name:<34} {:>10.1} {:>16.1} {:>10.1} {:>10.1}",
            mib(f(first)),
            mib(f(all_kept)),
            mib(f(last)),
            mib(peak(f))
        );
    };
    row("process RSS, MiB", |s| s.rss_bytes);
    row("renderer GPU bytes, MiB", |s| s.gpu_bytes);
    row("methods' CPU bytes, MiB", |s| s.method_cpu_bytes);
    row("undo snapshots, MiB", |s| s.undo_bytes);
    let json = serde_json::json!({
        "actions": args.actions,
        "counts": counts.iter().map(|(k, n)| (k.to_string(), *n)).collect::<std::collections::BTreeMap<_, _>>(),
        "seconds": seconds,
        "window": [args.size.0, args.size.1],
        "world": [width, height],
        "methods": methods,
        "samples": samples,
    });
    let json_path = args.out.join("soak.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&json)?)?;
    println!("samples in {}", json_path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_has_the_actions_asked_for_and_parses() {
        let methods = vec!["ray".to_string(), "mesh".to_string()];
        let views = vec!["edit".to_string()];
        let (text, counts) = script(1000, 100, 3, &methods, &views, (160, 100));
        let parsed = strata_viewer::Script::parse(&text).unwrap();
        let memory = text.lines().filter(|l| *l == "memory").count();
        assert_eq!(memory, 11, "one at the start, one every 100 actions");
        assert_eq!(parsed.commands.len(), 1 + 1000 + memory);
        assert_eq!(counts.iter().map(|(_, n)| n).sum::<u32>(), 1000);
        assert!(counts.iter().all(|(_, n)| *n > 0), "{counts:?}");
        // Reproducible from the seed.
        assert_eq!(script(1000, 100, 3, &methods, &views, (160, 100)).0, text);
    }

    #[test]
    fn memory_lines_parse() {
        let s = Sample::parse(
            "memory frames=12 rss_bytes=1024 gpu_bytes=2048 method_cpu_bytes=3 undo_bytes=4 \
             undo_depth=1 kept=2",
        )
        .unwrap();
        assert_eq!(
            (s.frames, s.rss_bytes, s.gpu_bytes, s.kept),
            (12, 1024, 2048, 2)
        );
        assert!(Sample::parse("score ray: …").is_none());
    }
}
