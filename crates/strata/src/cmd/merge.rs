//! `strata merge A.json B.json … [--out DIR]`: one report from runs on
//! several adapters. Refuses runs measured under different protocols; flags
//! accuracy that differs across adapters (a finding, not noise).

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// `results-*.json` files written by `strata compare`; the first is the baseline.
    #[arg(required = true, num_args = 1..)]
    pub runs: Vec<PathBuf>,
    /// Directory for the merged `report.md`.
    #[arg(long, value_name = "DIR", default_value = "out/merge")]
    pub out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let (report, flags) = strata_bench::merge::merge_files(&args.runs, &args.out)?;
    println!("wrote {}", report.display());
    if flags.is_empty() {
        println!("accuracy agrees across all {} run(s)", args.runs.len());
    } else {
        println!(
            "{} accuracy field(s) disagree across adapters:",
            flags.len()
        );
        for d in &flags {
            let fmt = |v: Option<f64>| v.map_or("missing".to_string(), |v| format!("{v:.3}"));
            println!(
                "  {} {} {}: baseline {}, {} {}",
                d.view,
                d.method,
                d.field,
                fmt(d.baseline),
                d.adapter,
                fmt(d.other)
            );
        }
    }
    Ok(())
}
