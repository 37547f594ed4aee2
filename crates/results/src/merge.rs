//! `strata merge`: combine runs from different adapters into one report
//! (the files and figures are written by `strata_bench::merge::merge_files`).
//! Runs must share the protocol (version, level, settings: size, views,
//! methods, frames, shadows); accuracy is expected to be device-independent,
//! so every accuracy field that differs from the baseline is flagged.

pub use crate::Disagreement;
use crate::{Row, RunResults};
use anyhow::{Context, bail};
use std::path::Path;

/// Percent fields disagree beyond this many percentage points.
pub const PERCENT_TOLERANCE: f64 = 0.5;
/// Depth fields (world units) disagree beyond this.
pub const DEPTH_TOLERANCE: f64 = 0.5;

/// Refuse runs that were not measured under the same protocol. The error
/// names the first differing field.
pub fn check_compatible(base: &RunResults, other: &RunResults) -> anyhow::Result<()> {
    let who = &other.adapter.name;
    if base.protocol_version != other.protocol_version {
        bail!(
            "{who}: protocol version {} differs from the baseline's {}",
            other.protocol_version,
            base.protocol_version
        );
    }
    if base.level.hash != other.level.hash {
        bail!(
            "{who}: level `{}` (hash {}) is not the baseline's `{}` (hash {})",
            other.level.name,
            other.level.hash,
            base.level.name,
            base.level.hash
        );
    }
    let (a, b) = (&base.settings, &other.settings);
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "{who}: size {}x{} differs from the baseline's {}x{}",
            b.width,
            b.height,
            a.width,
            a.height
        );
    }
    if a.views != b.views {
        bail!("{who}: the views differ from the baseline's");
    }
    if a.methods != b.methods {
        bail!(
            "{who}: methods {:?} differ from the baseline's {:?}",
            b.methods,
            a.methods
        );
    }
    if a != b {
        bail!(
            "{who}: settings differ from the baseline's (far {} vs {}, frames {} vs {}, shadows {} vs {}, edits {} vs {}, mid rule {} vs {})",
            b.far,
            a.far,
            b.frames,
            a.frames,
            b.shadows,
            a.shadows,
            b.edits,
            a.edits,
            b.mid_rule,
            a.mid_rule
        );
    }
    Ok(())
}

/// An accuracy field: its name and how to read it from a row.
pub type Field = (&'static str, fn(&Row) -> f64);

pub const PERCENT_FIELDS: [Field; 3] = [
    ("see_through", |r| r.see_through),
    ("covers_sky", |r| r.covers_sky),
    ("coherence", |r| r.coherence),
];
pub const DEPTH_FIELDS: [Field; 2] = [
    ("depth_p50", |r| r.depth_p50),
    ("depth_p95", |r| r.depth_p95),
];

/// Every accuracy field with its tolerance: the percent fields, then the
/// depth fields.
pub fn fields_with_tolerance() -> impl Iterator<Item = (&'static Field, f64)> {
    PERCENT_FIELDS
        .iter()
        .map(|f| (f, PERCENT_TOLERANCE))
        .chain(DEPTH_FIELDS.iter().map(|f| (f, DEPTH_TOLERANCE)))
}

/// Every accuracy field of `other` that differs from `base` beyond tolerance,
/// plus cells present in one run and not the other (an interrupted run).
pub fn disagreements(base: &RunResults, other: &RunResults) -> Vec<Disagreement> {
    let mut out = Vec::new();
    let find = |run: &RunResults, view: &str, method: &str| {
        run.rows
            .iter()
            .find(|r| r.view == view && r.method == method)
            .cloned()
    };
    let mut keys: Vec<(String, String)> = base
        .rows
        .iter()
        .map(|r| (r.view.clone(), r.method.clone()))
        .collect();
    for r in &other.rows {
        if !keys.iter().any(|(v, m)| *v == r.view && *m == r.method) {
            keys.push((r.view.clone(), r.method.clone()));
        }
    }
    for (view, method) in keys {
        let d = |field, baseline, other_v| Disagreement {
            adapter: other.adapter.name.clone(),
            view: view.clone(),
            method: method.clone(),
            field,
            baseline,
            other: other_v,
        };
        match (find(base, &view, &method), find(other, &view, &method)) {
            (Some(a), Some(b)) => {
                for ((name, get), tol) in fields_with_tolerance() {
                    let (x, y) = (get(&a), get(&b));
                    // NaN-safe: a NaN on one side only is a disagreement.
                    let differs = (x - y).abs() > tol || (x.is_nan() != y.is_nan());
                    if differs {
                        out.push(d(name, Some(x), Some(y)));
                    }
                }
            }
            (a, b) => out.push(d("cell", a.map(|_| 1.0), b.map(|_| 1.0))),
        }
    }
    for e in &base.edit_rows {
        let o = other.edit_rows.iter().find(|o| o.method == e.method);
        if let Some(o) = o
            && o.consistent_after_frames != e.consistent_after_frames
        {
            out.push(Disagreement {
                adapter: other.adapter.name.clone(),
                view: "edit".into(),
                method: e.method.clone(),
                field: "consistent_after_frames",
                baseline: e.consistent_after_frames.map(f64::from),
                other: o.consistent_after_frames.map(f64::from),
            });
        }
    }
    out
}

/// Read runs, check them against the first, and return the report text and the flags.
pub fn merge(runs: &[RunResults]) -> anyhow::Result<(String, Vec<Disagreement>)> {
    let Some(base) = runs.first() else {
        bail!("no runs to merge")
    };
    let mut flags = Vec::new();
    for other in &runs[1..] {
        check_compatible(base, other)?;
        flags.extend(disagreements(base, other));
    }
    let report = crate::report::render(runs, &crate::report::Pictures::default(), &flags);
    Ok((report, flags))
}

pub fn read_run(path: &Path) -> anyhow::Result<RunResults> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    RunResults::from_json(&text)
        .with_context(|| format!("{} is not a strata results file", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    #[test]
    fn identical_runs_merge_without_flags() {
        let a = fixtures::run("gpu-a");
        let b = fixtures::run("gpu-b");
        let (md, flags) = merge(&[a, b]).unwrap();
        assert!(flags.is_empty(), "{flags:?}");
        assert!(md.contains("No field disagrees."));
        assert!(md.contains("| gpu-b / -90° |"));
    }

    #[test]
    fn accuracy_beyond_half_a_point_is_flagged() {
        let a = fixtures::run("gpu-a");
        let mut b = fixtures::run("gpu-b");
        b.rows[0].see_through += 0.4; // within tolerance
        b.rows[1].coherence += 0.6; // beyond
        b.rows[2].depth_p95 += 2.0; // beyond (world units)
        b.rows.pop(); // an interrupted run lacks a cell
        b.edit_rows[0].consistent_after_frames = None;
        let flags = disagreements(&a, &b);
        let fields: Vec<(&str, &str, &str)> = flags
            .iter()
            .map(|d| (d.view.as_str(), d.method.as_str(), d.field))
            .collect();
        assert_eq!(
            fields,
            vec![
                ("river", "mesh", "coherence"),
                ("spiral", "ray", "depth_p95"),
                ("spiral", "mesh", "cell"),
                ("edit", "ray", "consistent_after_frames"),
            ]
        );
        let (md, _) = merge(&[a, b]).unwrap();
        assert!(
            md.contains("| gpu-b | river | mesh | coherence | 0.100 | 0.700 |"),
            "{md}"
        );
    }

    #[test]
    fn different_protocols_are_refused() {
        let a = fixtures::run("gpu-a");
        type Change = fn(&mut RunResults);
        let cases: Vec<(Change, &str)> = vec![
            (|r| r.protocol_version += 1, "protocol version"),
            (|r| r.level.hash = "other".into(), "hash"),
            (|r| r.settings.width = 64, "size"),
            (|r| r.settings.views[0].yaw = 1.0, "views"),
            (|r| r.settings.methods.reverse(), "methods"),
            (|r| r.settings.frames = 40, "settings"),
        ];
        for (change, what) in cases {
            let mut b = fixtures::run("gpu-b");
            change(&mut b);
            let err = merge(&[a.clone(), b]).unwrap_err().to_string();
            assert!(err.contains(what), "{what}: {err}");
        }
    }
}
