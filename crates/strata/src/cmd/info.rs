//! `strata info`: a world's size, dual fraction, height range, terrain
//! types, roughness, pair disagreements, and how long its map takes to decode.

use crate::world_arg;
use anyhow::{Context, bail};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use strata_level::generate::GenerateParams;
use strata_level::model::MidRule;
use strata_level::stats::LevelStats;
use strata_level::{Level, World, io, vmc};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Also encode the map as `.vmc` in memory and time decoding that
    /// (done anyway when the world's own map is not a `.vmc`).
    #[arg(long)]
    reencode: bool,
    /// Decode the map file this many more times and report the fastest and
    /// the median (a small benchmark; the first decode may pay for page faults).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
}

/// How the map file loaded.
#[derive(Serialize)]
struct MapFile {
    path: String,
    bytes: u64,
    read_ms: f64,
    /// The first decode, as part of loading the world.
    decode_ms: f64,
    /// With `--repeat N` (N > 1): fastest and median of N more decodes.
    #[serde(skip_serializing_if = "Option::is_none")]
    decode_min_ms: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    decode_median_ms: Option<f64>,
    /// With `--repeat N`: process CPU time per decode, all threads, averaged
    /// (Linux `/proc/self/stat`, 10 ms ticks). Unlike wall time it does not
    /// grow when other processes compete for the cores.
    #[serde(skip_serializing_if = "Option::is_none")]
    decode_cpu_ms: Option<f64>,
    decodes: u32,
}

/// The map encoded as `.vmc` in memory, then decoded again.
#[derive(Serialize)]
struct VmcRoundTrip {
    bytes: u64,
    encode_ms: f64,
    decode_ms: f64,
}

/// The water levels (`.vpr`) as the game reads them.
#[derive(Serialize)]
struct Water {
    /// The world's `.vpr` on disk, when it has one.
    file: Option<String>,
    bytes: Option<u64>,
    /// The size the game's and vange-rs's readers require for this map.
    expected_bytes: u64,
    /// `game`, `older Strata` (read, not yet rewritten), `generated` (not
    /// on disk), or `absent` (level 0 everywhere).
    layout: &'static str,
    sections: usize,
    min: i32,
    max: i32,
}

fn water(world: &World, dir: Option<&Path>) -> Water {
    let layout = strata_level::vpr::VprLayout::of(&world.config);
    let file = dir
        .map(|d| io::vpr_path(d, &world.config))
        .filter(|p| p.exists());
    let bytes = file
        .as_ref()
        .and_then(|p| std::fs::metadata(p).ok())
        .map(|m| m.len());
    let levels = world.water_levels();
    Water {
        // Loading accepted only these two sizes.
        layout: match (&world.water, bytes) {
            (None, _) => "absent",
            (Some(_), Some(b)) if b == layout.file_size() => "game",
            (Some(_), Some(_)) => "older Strata",
            (Some(_), None) => "generated",
        },
        file: file.map(|p| p.display().to_string()),
        bytes,
        expected_bytes: layout.file_size(),
        sections: levels.len(),
        min: levels.iter().copied().min().unwrap_or(0),
        max: levels.iter().copied().max().unwrap_or(0),
    }
}

#[derive(Serialize)]
struct Info {
    world: String,
    mid_rule: MidRule,
    map_file: Option<MapFile>,
    water: Water,
    vmc_round_trip: Option<VmcRoundTrip>,
    stats_ms: f64,
    stats: LevelStats,
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn vmc_round_trip(level: &Level) -> anyhow::Result<VmcRoundTrip> {
    let path = Path::new("<in memory>.vmc");
    let t = Instant::now();
    let bytes = vmc::encode_vmc(level, path)?;
    let encode_ms = ms_since(t);
    let t = Instant::now();
    let back = vmc::decode_vmc(&bytes, level.width(), level.height(), level.mid_rule, path)?;
    let decode_ms = ms_since(t);
    if back.heights() != level.heights() || back.metas() != level.metas() {
        bail!("the in-memory .vmc round trip changed the map (encoder bug)");
    }
    Ok(VmcRoundTrip {
        bytes: bytes.len() as u64,
        encode_ms,
        decode_ms,
    })
}

/// Read and decode a world directory's map file, timed.
fn time_map(dir: &Path, world: &World, mid_rule: MidRule) -> anyhow::Result<io::MapLoad> {
    let path = io::map_path(dir, &world.config);
    let t0 = Instant::now();
    let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    let read_ms = ms_since(t0);
    let t1 = Instant::now();
    io::decode_map(&bytes, &world.config, mid_rule, &path)?;
    Ok(io::MapLoad {
        bytes: bytes.len() as u64,
        read_ms,
        decode_ms: ms_since(t1),
        path,
    })
}

/// User + system CPU time of this process so far (Linux only; `USER_HZ` 100).
fn process_cpu_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name, which is in parentheses and may hold spaces.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(11)? + ticks(12)?) * 10.0)
}

/// The map file's figures, with `repeat - 1` more timed decodes when asked.
fn map_file(
    load: io::MapLoad,
    world: &World,
    mid_rule: MidRule,
    repeat: u32,
) -> anyhow::Result<MapFile> {
    let (mut decode_min_ms, mut decode_median_ms, mut decode_cpu_ms) = (None, None, None);
    if repeat > 1 {
        let bytes = std::fs::read(&load.path)
            .with_context(|| format!("reading {}", load.path.display()))?;
        let mut times = Vec::new();
        let cpu0 = process_cpu_ms();
        for _ in 0..repeat {
            let t = Instant::now();
            let level = io::decode_map(&bytes, &world.config, mid_rule, &load.path)?;
            times.push(ms_since(t));
            drop(level);
        }
        if let (Some(a), Some(b)) = (cpu0, process_cpu_ms()) {
            decode_cpu_ms = Some((b - a) / f64::from(repeat));
        }
        times.sort_by(f64::total_cmp);
        decode_min_ms = times.first().copied();
        decode_median_ms = times.get(times.len() / 2).copied();
    }
    Ok(MapFile {
        path: load.path.display().to_string(),
        bytes: load.bytes,
        read_ms: load.read_ms,
        decode_ms: load.decode_ms,
        decode_min_ms,
        decode_median_ms,
        decode_cpu_ms,
        decodes: repeat,
    })
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(dir) = &args.world.level
        && super::store_info::is_store(dir)
    {
        return super::store_info::run(dir, args.json);
    }
    let mid_rule = args.world.mid_rule();
    let mut world_dir = args.world.level.clone();
    let (world, load) = match &args.world.level {
        Some(dir) => io::load_world_timed(dir, mid_rule)
            .map(|(world, load)| (world, Some(load)))
            .with_context(|| format!("loading the world in {}", dir.display()))?,
        None => {
            // The built-in world: from its on-disk cache when there is one,
            // whose map file is then timed; else an in-memory .vmc round trip.
            let world = args.world.load()?;
            let cached = world_arg::cache_root()
                .map(|root| world_arg::cache_dir(&root, &GenerateParams::default()))
                .filter(|dir| dir.join(io::WORLD_INI).exists());
            let load = match &cached {
                Some(dir) => Some(time_map(dir, &world, mid_rule)?),
                None => None,
            };
            world_dir = cached;
            (world, load)
        }
    };
    let is_vmc = world.config.compressed && load.is_some();
    let map_file = match load {
        Some(load) => Some(map_file(load, &world, mid_rule, args.repeat)?),
        None => None,
    };
    let vmc_round_trip = if args.reencode || !is_vmc {
        Some(vmc_round_trip(&world.level)?)
    } else {
        None
    };
    let t = Instant::now();
    let stats = LevelStats::compute(&world.level);
    let info = Info {
        world: world.name.clone(),
        mid_rule,
        map_file,
        water: water(&world, world_dir.as_deref()),
        vmc_round_trip,
        stats_ms: ms_since(t),
        stats,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print_text(&info);
    }
    Ok(())
}

fn print_text(info: &Info) {
    let s = &info.stats;
    println!("world        {} ({:?} mid rule)", info.world, info.mid_rule);
    println!("size         {} x {}", s.width, s.height);
    if let Some(m) = &info.map_file {
        println!(
            "map file     {} ({:.2} MB): read {:.0} ms, decode {:.0} ms",
            m.path,
            m.bytes as f64 / 1e6,
            m.read_ms,
            m.decode_ms
        );
        if let (Some(min), Some(median)) = (m.decode_min_ms, m.decode_median_ms) {
            let cpu = m
                .decode_cpu_ms
                .map(|c| format!(", CPU {c:.0} ms each"))
                .unwrap_or_default();
            println!(
                "             {} more decodes: fastest {min:.0} ms, median {median:.0} ms{cpu}",
                m.decodes
            );
        }
    }
    let w = &info.water;
    let file = match (&w.file, w.bytes) {
        (Some(f), Some(b)) => format!("{f} ({b} bytes, {} layout)", w.layout),
        _ => format!("{} (no .vpr file)", w.layout),
    };
    println!(
        "water        {} sections, levels {} .. {}: {file}; the game reads {} bytes",
        w.sections, w.min, w.max, w.expected_bytes
    );
    if let Some(r) = &info.vmc_round_trip {
        println!(
            "as .vmc      {:.2} MB: encode {:.0} ms, decode {:.0} ms",
            r.bytes as f64 / 1e6,
            r.encode_ms,
            r.decode_ms
        );
    }
    println!("dual         {:.2} % of texels", s.dual_percent);
    println!("heights      {} .. {}", s.height_min, s.height_max);
    let pct = |p: &[f64; 8]| {
        p.iter()
            .enumerate()
            .map(|(t, v)| format!("{t}:{v:.1}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!("floor types  {} (% of texels)", pct(&s.floor_type_percent));
    println!(
        "slab types   {} (% of dual texels)",
        pct(&s.slab_type_percent)
    );
    println!(
        "roughness    floor {:.2}, surface {:.2} (Fostral: 3.44, 6.54)",
        s.roughness_floor, s.roughness_surface
    );
    println!("pair disagreements {}", s.pair_disagreements);
    println!("stats        {:.0} ms", info.stats_ms);
}
