//! Draw `report.md`'s figures from results files, to look at them:
//!
//! ```text
//! cargo run -p strata-bench --example figures -- OUT_DIR RESULTS.json [MORE.json …]
//! ```
//!
//! Several files draw the merged figures (one line per method and adapter).

use std::path::PathBuf;
use strata_bench::{figures, merge, report};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (Some(out), files) = (args.next(), args.collect::<Vec<_>>()) else {
        anyhow::bail!("usage: figures OUT_DIR RESULTS.json [MORE.json …]");
    };
    let runs = files
        .iter()
        .map(|f| merge::read_run(&PathBuf::from(f)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let out = PathBuf::from(out);
    let pictures = figures::with_figures(report::Pictures::default(), &runs, &out);
    for f in &pictures.figures {
        println!("{}", out.join(&f.png).display());
    }
    if let Some((png, _)) = &pictures.edit_figure {
        println!("{}", out.join(png).display());
    }
    Ok(())
}
