//! `strata survey`: fit a set of worlds at q = 0, 0.25, 0.5, 0.75, 1 and
//! write the paper's table, correlations, insertion causes and plots
//! (issue 17). By default a generated grid that turns one knob at a time.

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use strata_level::generate::{GenerateParams, check_size, parse_size};
use strata_survey::{Plan, plots, report};

#[derive(clap::Args)]
pub struct Args {
    /// Survey these world directories instead of the generated grid (e.g. the game's ten).
    #[arg(long, value_name = "DIR", num_args = 1..)]
    level: Vec<PathBuf>,
    /// Directory for survey.md, survey.json and the plots (created if needed).
    #[arg(long, value_name = "DIR", default_value = "survey")]
    out: PathBuf,
    /// The generated grid at 1024x2048 instead of 2048x4096 (a couple of minutes on 2 cores).
    #[arg(long, conflicts_with = "size")]
    quick: bool,
    /// Size of each generated world, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "2048x4096")]
    size: String,
    /// Seed of the generated worlds.
    #[arg(long, default_value_t = GenerateParams::default().seed)]
    seed: u64,
    /// Fit worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Use the outline-constrained fit.
    #[arg(long)]
    outline: bool,
}

/// Progress on the terminal: one bar over every fit.
struct Bar(ProgressBar);

impl strata_survey::run::Progress for Bar {
    fn world(&self, label: &str) {
        self.0.set_message(label.to_string());
    }
    fn fit_done(&self) {
        self.0.inc(1);
    }
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let plan = if args.level.is_empty() {
        let (w, h) = if args.quick {
            (1024, 2048)
        } else {
            parse_size(&args.size)?
        };
        check_size(w, h)?;
        Plan::grid(args.seed, w, h)
    } else {
        Plan::dirs(args.level.clone())
    };
    let plan = Plan {
        outline: args.outline,
        ..plan
    };
    if plan.worlds.is_empty() {
        bail!("nothing to survey");
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let bar = ProgressBar::new(plan.steps() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} fits  {msg}  [{elapsed_precise}, {eta_precise} left]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let survey = strata_survey::run(&plan, args.threads.unwrap_or(0), &Bar(bar.clone()));
    bar.finish_and_clear();
    let command: String = std::env::args()
        .map(|a| a.rsplit('/').next().unwrap_or(&a).to_string())
        .take(1)
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    let figures = plots::write_all(&args.out, &survey)?;
    report::write(&args.out, &command, &survey, &figures)?;
    let failed = survey.worlds.iter().filter(|w| w.error.is_some()).count();
    println!(
        "surveyed {} worlds ({} failed) in {:.0} s: {}",
        survey.worlds.len(),
        failed,
        survey.wall_seconds,
        args.out.join("survey.md").display()
    );
    for c in report::correlations(&survey) {
        if c.quality == survey.table_quality {
            let f = |r: Option<f64>| r.map_or("n/a".to_string(), |r| format!("{r:+.2}"));
            println!(
                "log reduction at q={} correlates {} with r_f, {} with dual %, {} with r_s, {} with slab share",
                c.quality,
                f(c.r_f),
                f(c.dual),
                f(c.r_s),
                f(c.slab_share)
            );
        }
    }
    for w in survey.worlds.iter().filter(|w| w.error.is_some()) {
        eprintln!(
            "warning: {}: {}",
            w.label,
            w.error.as_deref().unwrap_or_default()
        );
    }
    Ok(())
}
