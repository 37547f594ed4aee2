//! `strata compare --resume DIR`: the finished cells of an interrupted run
//! (its results file is rewritten after every cell) are kept, and only the
//! rest are measured. A run is resumed only when it is the same comparison:
//! same protocol version, level (by content hash), adapter and settings;
//! anything else is refused with what differs named. Failed cells are not
//! kept: a resumed run tries them again.

use crate::results::{RunResults, slug};
use anyhow::{Context, bail};
use std::path::{Path, PathBuf};

/// The results file of the interrupted run in `dir` for this run's adapter.
/// A directory holding only another adapter's results is refused by name.
fn results_path(dir: &Path, header: &RunResults) -> anyhow::Result<PathBuf> {
    let path = dir.join(header.file_name());
    if path.is_file() {
        return Ok(path);
    }
    let others: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("--resume: cannot read {}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("results-") && n.ends_with(".json"))
        .collect();
    if others.is_empty() {
        bail!(
            "--resume: {} holds no results file to resume (expected {})",
            dir.display(),
            header.file_name()
        );
    }
    bail!(
        "--resume: {} holds {} from another adapter, not {} of adapter `{}`",
        dir.display(),
        others.join(", "),
        header.file_name(),
        header.adapter.name
    )
}

/// Each setting that differs, as `name (there X, here Y)`.
fn settings_differences(there: &RunResults, here: &RunResults) -> Vec<String> {
    let (Ok(a), Ok(b)) = (
        serde_json::to_value(&there.settings),
        serde_json::to_value(&here.settings),
    ) else {
        return vec!["settings (not comparable)".into()];
    };
    let (Some(a), Some(b)) = (a.as_object(), b.as_object()) else {
        return vec!["settings (not comparable)".into()];
    };
    let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
    keys.sort();
    keys.dedup();
    keys.into_iter()
        .filter(|k| a.get(*k) != b.get(*k))
        .map(|k| {
            let show = |v: Option<&serde_json::Value>| {
                let text = v.map_or("absent".to_string(), |v| v.to_string());
                // A long list (the views) is named, not printed whole.
                if text.len() > 80 {
                    format!("{}…", &text[..text.floor_char_boundary(77)])
                } else {
                    text
                }
            };
            format!("{k} (there {}, here {})", show(a.get(k)), show(b.get(k)))
        })
        .collect()
}

/// Refuse to resume `there` as the run `here` unless they are the same
/// comparison; the error names every difference.
pub fn check_same_run(there: &RunResults, here: &RunResults) -> anyhow::Result<()> {
    let mut differ = Vec::new();
    if there.protocol_version != here.protocol_version {
        differ.push(format!(
            "protocol version (there {}, here {})",
            there.protocol_version, here.protocol_version
        ));
    }
    if there.level.hash != here.level.hash {
        differ.push(format!(
            "level (there `{}` hash {}, here `{}` hash {})",
            there.level.name, there.level.hash, here.level.name, here.level.hash
        ));
    }
    if slug(&there.adapter.name) != slug(&here.adapter.name)
        || there.adapter.backend != here.adapter.backend
    {
        differ.push(format!(
            "adapter (there {} on {}, here {} on {})",
            there.adapter.name, there.adapter.backend, here.adapter.name, here.adapter.backend
        ));
    }
    differ.extend(settings_differences(there, here));
    if !differ.is_empty() {
        bail!(
            "the interrupted run differs from this one in: {}",
            differ.join("; ")
        );
    }
    Ok(())
}

/// Read and check the interrupted run in `dir` against this run's header.
pub fn load(dir: &Path, header: &RunResults) -> anyhow::Result<RunResults> {
    let path = results_path(dir, header)?;
    let there = crate::merge::read_run(&path)?;
    check_same_run(&there, header)
        .with_context(|| format!("--resume: cannot resume {}", path.display()))?;
    Ok(there)
}

/// Move the finished work of `there` into the new run's results: the
/// measured cells, edit rows (with their pictures) and temporal rows.
/// Failures and reference pictures are not carried: failed cells run again,
/// and the references are looked up (in the cache) again.
pub fn carry_over(there: RunResults, here: &mut RunResults) {
    here.rows = there.rows;
    here.edit_rows = there.edit_rows;
    here.edit_images = there.edit_images;
    here.temporal = there.temporal;
    here.gameplay = there.gameplay;
}

/// Is cell (`view`, `method`) among the finished rows?
pub fn has_row(results: &RunResults, view: &str, method: &str) -> bool {
    results
        .rows
        .iter()
        .any(|r| r.view == view && r.method == method)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::run;

    #[test]
    fn same_run_is_accepted_and_differences_are_named() {
        let here = run("llvmpipe");
        check_same_run(&run("llvmpipe"), &here).unwrap();
        let mut there = run("llvmpipe");
        there.settings.frames = 9;
        there.level.hash = "0000".into();
        let err = check_same_run(&there, &here).unwrap_err().to_string();
        assert!(
            err.contains("level (there `test` hash 0000, here `test` hash abcdef0123456789)")
                && err.contains("frames (there 9, here 4)"),
            "{err}"
        );
        let err = check_same_run(&run("NVIDIA H100"), &here)
            .unwrap_err()
            .to_string();
        assert!(err.contains("adapter (there NVIDIA H100"), "{err}");
        let mut there = run("llvmpipe");
        there.protocol_version += 1;
        let err = check_same_run(&there, &here).unwrap_err().to_string();
        assert!(err.contains("protocol version (there 2, here 1)"), "{err}");
    }

    #[test]
    fn a_directory_without_this_adapters_results_is_refused() {
        let dir = std::env::temp_dir().join(format!("strata-resume-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let here = run("llvmpipe");
        let err = load(&dir, &here).unwrap_err().to_string();
        assert!(err.contains("no results file"), "{err}");
        run("NVIDIA H100").write(&dir).unwrap();
        let err = load(&dir, &here).unwrap_err().to_string();
        assert!(
            err.contains("results-nvidia-h100.json from another adapter"),
            "{err}"
        );
        here.write(&dir).unwrap();
        assert_eq!(load(&dir, &here).unwrap(), here);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
