//! `strata merge A.json B.json … [--out DIR]`: one report from runs on
//! several adapters. Refuses runs measured under different protocols; flags
//! accuracy that differs across adapters (a finding, not noise).
//!
//! `--portability` writes the portability report instead (`portability.md`,
//! `portability.json`, side-by-side pictures of the disagreeing cells): runs
//! of different protocols are grouped, not refused, and compared only within
//! their group.

use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// `results-*.json` files written by `strata compare`; the first is the baseline.
    /// With --portability also `portability.json` files of earlier batches (their runs
    /// and skipped adapters are merged).
    #[arg(required = true, num_args = 1..)]
    pub runs: Vec<PathBuf>,
    /// Directory for the merged `report.md` (or the portability report).
    #[arg(long, value_name = "DIR", default_value = "out/merge")]
    pub out: PathBuf,
    /// Write the portability report: per adapter and method the pitch means, the spread
    /// across adapters per cell, disagreeing cells first with their pictures side by side
    /// (found beside each results file), timing apart per adapter and source. Runs of
    /// different protocols form separate groups.
    #[arg(long)]
    pub portability: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.portability {
        let (report, md, json) = strata_bench::portability::merge_files(&args.runs, &args.out)?;
        println!("wrote {}", md.display());
        println!("wrote {}", json.display());
        super::compare::summarize(&report);
        return Ok(());
    }
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
