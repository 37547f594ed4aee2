//! `strata`: render and measure editable multi-layer height fields.

mod adapter_arg;
mod cmd;
mod paged_arg;
mod world_arg;

use std::sync::LazyLock;

use clap::{Parser, Subcommand};

/// `--version`: the crate version and the revision baked in at build time
/// (the one results files carry).
static VERSION: LazyLock<String> = LazyLock::new(|| {
    format!(
        "{} (revision {})",
        env!("CARGO_PKG_VERSION"),
        strata_bench::plan::SOURCE_REVISION
    )
});

#[derive(Parser)]
#[command(
    name = "strata",
    version = VERSION.as_str(),
    about = "Render and measure editable multi-layer height fields (Vangers terrain)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write a generated Vangers-like world directory in the real file format.
    Generate(cmd::generate::Args),
    /// Convert a Vangers world to a Strata store (Zarr v3) or back.
    Convert(cmd::convert::Args),
    /// Print a world's size, dual fraction, height range, terrain types, roughness, decode time.
    Info(cmd::info::Args),
    /// CPU reference ray cast of one view (or every view of a file).
    Reference(cmd::reference::Args),
    /// Compare a rendered depth/colour pair with the CPU reference.
    Metrics(cmd::metrics::Args),
    /// Render one view with one method on the GPU.
    Render(cmd::render::Args),
    /// Fly a path over paged terrain: per-frame GPU/CPU ms, pending pixels, uploads, resident bytes.
    Fly(cmd::fly::Args),
    /// Fit the TIN mesh and report its size, causes, time and memory.
    Fit(cmd::fit::Args),
    /// Fit a grid of generated worlds (or given ones) at five qualities: table, correlations, causes, plots.
    Survey(cmd::survey::Args),
    /// Build the terrain collider: build time, memory, crater refit, ray-cast throughput.
    Collide(cmd::collide::Args),
    /// `ray-exact`'s frame on paper: a CPU replay of its traversal counting steps, texel reads and bytes per pass.
    ExactCounts(cmd::exact_counts::Args),
    /// Export the fitted mesh with terrain colours as glTF (.glb binary or .gltf JSON) or OBJ.
    Export(cmd::export::Args),
    /// The one-command comparison of every method over the level's views.
    Compare(cmd::compare::Args),
    /// Tune each method's knob on this level: sweeps, the one-point rule, tuning.md, settings.json.
    Tune(cmd::tune::Args),
    /// Merge results from several machines into one report.
    Merge(cmd::merge::Args),
    /// List every GPU adapter: backend, driver, capabilities, limits, the methods it runs.
    Adapters(cmd::adapters::Args),
    /// Fly a camera path with one method or several side by side; H.264 MP4 via ffmpeg, or PNGs.
    Video(cmd::video::Args),
    /// Open a window: fly over the level, switch methods live, dig craters.
    View(cmd::view::Args),
    /// A long scripted viewer session (digs, undos, switches, resizes, splits) sampling memory.
    Soak(cmd::soak::Args),
    /// Serve the browser build of the viewer (and a world directory) on localhost.
    Serve(cmd::serve::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Generate(args) => cmd::generate::run(args),
        Command::Convert(args) => cmd::convert::run(args),
        Command::Info(args) => cmd::info::run(args),
        Command::Reference(args) => cmd::reference::run(args),
        Command::Metrics(args) => cmd::metrics::run(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Fit(args) => cmd::fit::run(args),
        Command::Fly(args) => cmd::fly::run(args),
        Command::Collide(args) => cmd::collide::run(args),
        Command::ExactCounts(args) => cmd::exact_counts::run(args),
        Command::Export(args) => cmd::export::run(args),
        Command::Compare(args) => cmd::compare::run(args),
        Command::Survey(args) => cmd::survey::run(args),
        Command::Merge(args) => cmd::merge::run(args),
        Command::Tune(args) => cmd::tune::run(args),
        Command::View(args) => cmd::view::run(args),
        Command::Video(args) => cmd::video::run(args),
        Command::Serve(args) => cmd::serve::run(args),
        Command::Soak(args) => cmd::soak::run(args),
        Command::Adapters(args) => cmd::adapters::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
