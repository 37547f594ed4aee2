//! `strata merge`: combine runs from different adapters into one report.
//! The checks and the report text need no GPU and live in
//! [`strata_results::merge`] (re-exported here); this module writes the
//! report with its figures.

use crate::report;
use anyhow::Context;
use std::path::{Path, PathBuf};
pub use strata_results::merge::*;

/// `strata merge`: read, check, write `<out>/report.md`; returns its path and the flags.
pub fn merge_files(paths: &[PathBuf], out: &Path) -> anyhow::Result<(PathBuf, Vec<Disagreement>)> {
    let runs = paths
        .iter()
        .map(|p| read_run(p))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let (_, flags) = merge(&runs)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // The figures need a directory to live in, so they come with the files.
    let pictures = crate::figures::with_figures(report::Pictures::default(), &runs, out);
    let report = report::render(&runs, &pictures, &flags);
    let path = out.join("report.md");
    std::fs::write(&path, report).with_context(|| format!("writing {}", path.display()))?;
    Ok((path, flags))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    #[test]
    fn merge_files_round_trips_json() {
        let dir = std::env::temp_dir().join(format!("strata-merge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pa = fixtures::run("gpu-a").write(&dir).unwrap();
        let pb = fixtures::run("gpu-b").write(&dir).unwrap();
        assert!(pa.ends_with("results-gpu-a.json"));
        let (report, flags) = merge_files(&[pa, pb], &dir.join("merged")).unwrap();
        assert!(flags.is_empty());
        assert!(std::fs::read_to_string(report).unwrap().contains("gpu-b"));
        let bad = dir.join("bad.json");
        std::fs::write(&bad, "{\"rows\": 3}").unwrap();
        assert!(
            merge_files(&[bad], &dir)
                .unwrap_err()
                .to_string()
                .contains("not a strata results file")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
