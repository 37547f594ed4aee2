//! `portability.md`: the report as Markdown tables, disagreeing cells first.

use super::*;
use crate::report::{distinct_pitches, pitch_label};
use std::fmt::Write as _;
use strata_markdown::{Align, Table, cell_text};

fn field_title(f: &str) -> &str {
    match f {
        "see_through" => "see-through",
        "covers_sky" => "covers-sky",
        "depth_p50" => "depth p50",
        "depth_p95" => "depth p95",
        "coherence" => "coherence",
        "cell" => "cell missing",
        other => other,
    }
}

fn source_title(s: TimingSource) -> &'static str {
    match s {
        TimingSource::GpuTimestamps => "GPU timestamps",
        TimingSource::CpuSubmitWait => "CPU submit-and-wait",
    }
}

fn num(v: f64, digits: usize) -> String {
    if v.is_nan() {
        "NaN".into()
    } else if v.is_infinite() {
        "∞".into()
    } else {
        format!("{v:.digits$}")
    }
}

/// A value or the dash of a missing one.
fn or_dash(v: Option<String>) -> String {
    v.unwrap_or_else(|| "—".into())
}

/// The five accuracy fields, three decimals each.
fn accuracy_cells(a: &Accuracy) -> [String; 5] {
    [
        num(a.see_through, 3),
        num(a.covers_sky, 3),
        num(a.depth_p50, 3),
        num(a.depth_p95, 3),
        num(a.coherence, 3),
    ]
}

/// The accuracy fields' columns, units in the titles.
const ACCURACY_TITLES: [&str; 5] = ["see-through %", "covers-sky %", "p50", "p95", "coherence %"];

/// `portability.md`.
pub fn render_markdown(r: &Portability) -> String {
    let mut md = String::new();
    let level = r
        .groups
        .first()
        .map_or("(no runs)".to_string(), |g| g.protocol.level.clone());
    let _ = writeln!(md, "# Strata portability: {}\n", cell_text(&level));
    let _ = writeln!(
        md,
        "{} run(s) on {} protocol group(s). Accuracy is compared only between runs of one protocol \
         (version, level, size, views, methods, frames, shadows, edits, mid rule). A cell disagrees when \
         the spread of a field across adapters (max − min) exceeds {} percentage points (see-through, \
         covers-sky, coherence) or {} world units (depth p50, p95) — `strata merge`'s tolerances.\n",
        r.runs.len(),
        r.groups.len(),
        r.tolerances.percent,
        r.tolerances.depth
    );
    runs_table(&mut md, &r.runs);
    skipped(&mut md, &r.skipped);
    if r.groups.len() > 1 {
        protocol_groups(&mut md, &r.groups);
    }
    for g in &r.groups {
        group_markdown(&mut md, g);
    }
    md
}

fn runs_table(md: &mut String, runs: &[RunEntry]) {
    let mut t = Table::new().columns(
        [
            "adapter", "backend", "driver", "timing", "group", "revision", "cells", "results",
            "grid",
        ],
        Align::Left,
    );
    for e in runs {
        let timing = if e.adapter.timestamps {
            "GPU timestamps"
        } else {
            "CPU submit-and-wait"
        };
        t.row([
            e.label.clone(),
            e.adapter.backend.clone(),
            e.adapter.driver.clone(),
            timing.to_string(),
            e.group.clone(),
            format!("`{}`", e.source_revision),
            format!(
                "{} / {}{}",
                e.cells,
                e.expected_cells,
                if e.complete { "" } else { " (incomplete)" }
            ),
            format!("[json]({})", e.results),
            or_dash(e.grid.as_ref().map(|g| format!("[grid]({g})"))),
        ]);
    }
    t.write_to(md);
    md.push('\n');
}

fn skipped(md: &mut String, skipped: &[SkippedAdapter]) {
    if skipped.is_empty() {
        return;
    }
    md.push_str("**Adapters that could not run at all:**\n\n");
    for s in skipped {
        let _ = writeln!(
            md,
            "- {} ({}): {}",
            cell_text(&s.adapter),
            cell_text(&s.backend),
            cell_text(&s.error)
        );
    }
    md.push('\n');
}

fn protocol_groups(md: &mut String, groups: &[ProtocolGroup]) {
    md.push_str("## Protocol groups\n\n");
    md.push_str(
        "These runs were not all measured under one protocol, so merge refuses to compare accuracy \
         across groups; each group is reported on its own below.\n\n",
    );
    for g in groups {
        let _ = write!(
            md,
            "- **{}** ({}): {}",
            g.id,
            protocol_line(&g.protocol),
            g.adapters
                .iter()
                .map(|a| cell_text(a))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if let Some(why) = &g.separate_because {
            let _ = write!(md, ". Not compared with group A: {}", cell_text(why));
        }
        md.push('\n');
    }
    md.push('\n');
}

fn protocol_line(p: &ProtocolSummary) -> String {
    format!(
        "{}x{}, {} frames, {} views x {} methods, shadows {}, edits {}, protocol v{}",
        p.width,
        p.height,
        p.frames,
        p.views.len(),
        p.methods.len(),
        if p.shadows { "on" } else { "off" },
        if p.edits { "on" } else { "off" },
        p.protocol_version
    )
}

/// One protocol group: disagreements first, then refusals, accuracy by
/// pitch, spreads, edits and timing.
fn group_markdown(md: &mut String, g: &ProtocolGroup) {
    let _ = writeln!(
        md,
        "## Group {}: {} on {} adapter(s)\n",
        g.id,
        protocol_line(&g.protocol),
        g.adapters.len()
    );
    if g.adapters.len() < 2 {
        md.push_str("One adapter under this protocol: no spread to measure.\n\n");
    } else {
        disagreements(md, g);
    }
    refusals(md, g);
    let pitches = distinct_pitches(g.cells.iter().map(|c| c.pitch));
    accuracy_by_pitch(md, g, &pitches);
    largest_spreads(md, g);
    if g.adapters.len() > 1 {
        cell_spreads(md, g);
    }
    edit_consistency(md, g);
    frame_times(md, g, &pitches);
}

fn disagreements(md: &mut String, g: &ProtocolGroup) {
    let _ = writeln!(
        md,
        "### Cells that disagree across adapters ({} of {})\n",
        g.disagreeing_cells,
        g.cells.len()
    );
    if g.disagreeing_cells == 0 {
        md.push_str("Every cell agrees within tolerance.\n\n");
        return;
    }
    for c in g.cells.iter().filter(|c| !c.disagrees.is_empty()) {
        disagreeing_cell(md, c);
    }
}

/// One disagreeing cell: its fields, every adapter's value, the spread and
/// the pictures side by side.
fn disagreeing_cell(md: &mut String, c: &CellSpread) {
    let fields: Vec<&str> = c.disagrees.iter().map(|f| field_title(f)).collect();
    let _ = writeln!(
        md,
        "**{} / {}** ({}): {}\n",
        cell_text(&c.view),
        cell_text(&c.method),
        pitch_label(c.pitch),
        fields.join(", ")
    );
    let mut t = Table::new()
        .left("adapter")
        .columns(ACCURACY_TITLES, Align::Right)
        .left("picture");
    for v in &c.values {
        let picture = or_dash(v.picture.as_ref().map(|p| format!("[png]({p})")));
        t.row(
            std::iter::once(v.adapter.clone())
                .chain(accuracy_cells(&v.accuracy))
                .chain([picture]),
        );
    }
    for a in &c.absent {
        let why = a
            .failure
            .as_ref()
            .map_or("missing (run incomplete)".to_string(), |f| {
                format!("refused: {f}")
            });
        t.row(
            std::iter::once(a.adapter.clone())
                .chain(std::iter::repeat_n("—".to_string(), 5))
                .chain([why]),
        );
    }
    if let Some(s) = &c.spread {
        t.row(
            std::iter::once("**spread**".to_string())
                .chain(accuracy_cells(s))
                .chain([String::new()]),
        );
    }
    t.write_to(md);
    md.push('\n');
    match &c.side_by_side {
        Some(p) => {
            let _ = writeln!(
                md,
                "![{} {}: reference, then each adapter]({p})\n",
                cell_text(&c.view),
                cell_text(&c.method)
            );
        }
        None => md.push_str("(no cell pictures found beside the results files)\n\n"),
    }
}

fn refusals(md: &mut String, g: &ProtocolGroup) {
    let _ = writeln!(md, "### Refused or failed ({})\n", g.failures.len());
    if g.failures.is_empty() {
        md.push_str("Every method ran on every adapter of this group.\n\n");
        return;
    }
    let mut t = Table::new().columns(["adapter", "method", "view", "error"], Align::Left);
    for f in &g.failures {
        let view = if f.view == "*" {
            "every view"
        } else {
            f.view.as_str()
        };
        t.row([
            f.adapter.as_str(),
            f.method.as_str(),
            view,
            f.error.as_str(),
        ]);
    }
    t.write_to(md);
    md.push('\n');
}

/// Pitch means: methods and pitches down, adapters across, spread last.
fn accuracy_by_pitch(md: &mut String, g: &ProtocolGroup, pitches: &[f32]) {
    md.push_str("### Accuracy by pitch\n\n");
    pitch_mean_table(
        md,
        g,
        pitches,
        "see-through / coherence error (% of pixels), mean over the views at each pitch; spread = max − min \
         of the adapters' means.",
        &|a| format!("{} / {}", num(a.see_through, 2), num(a.coherence, 2)),
    );
    pitch_mean_table(
        md,
        g,
        pitches,
        "covers-sky (%) / depth error p50 / p95 (world units), same means.",
        &|a| {
            format!(
                "{} / {} / {}",
                num(a.covers_sky, 2),
                num(a.depth_p50, 2),
                num(a.depth_p95, 2)
            )
        },
    );
}

fn pitch_mean_table(
    md: &mut String,
    g: &ProtocolGroup,
    pitches: &[f32],
    title: &str,
    fmt: &dyn Fn(&Accuracy) -> String,
) {
    let spread_col = g.adapters.len() > 1;
    md.push_str(title);
    md.push_str("\n\n");
    let mut t = Table::new()
        .left("method / pitch")
        .columns(&g.adapters, Align::Right);
    if spread_col {
        t = t.right("spread");
    }
    for m in &g.protocol.methods {
        for &p in pitches {
            let mut row = vec![format!("{m} / {}", pitch_label(p))];
            for a in &g.adapters {
                let mean = g
                    .pitch_means
                    .iter()
                    .find(|x| x.adapter == *a && x.method == *m && x.pitch == p);
                row.push(or_dash(mean.map(|x| fmt(&x.mean))));
            }
            if spread_col {
                let spread = g
                    .pitch_spreads
                    .iter()
                    .find(|x| x.method == *m && x.pitch == p);
                row.push(or_dash(spread.map(|x| fmt(&x.spread))));
            }
            t.row(row);
        }
    }
    t.write_to(md);
    md.push('\n');
}

fn largest_spreads(md: &mut String, g: &ProtocolGroup) {
    if g.method_max_spreads.is_empty() {
        return;
    }
    md.push_str("### Largest spread per method\n\n");
    md.push_str(
        "The largest max − min across adapters over the method's cells, each field on its own.\n\n",
    );
    let mut t = Table::new()
        .left("method")
        .columns(ACCURACY_TITLES, Align::Right);
    for m in &g.method_max_spreads {
        t.row(std::iter::once(m.method.clone()).chain(accuracy_cells(&m.max)));
    }
    t.write_to(md);
    md.push('\n');
}

/// Every cell's spread.
fn cell_spreads(md: &mut String, g: &ProtocolGroup) {
    md.push_str("### Spread per cell\n\n");
    md.push_str(
        "max − min across the adapters that have the cell; disagreeing cells first (**bold** fields \
         beyond tolerance).\n\n",
    );
    let mut t = Table::new()
        .left("view")
        .right("pitch")
        .left("method")
        .columns(
            [
                "see-through",
                "covers-sky",
                "p50",
                "p95",
                "coherence",
                "adapters",
            ],
            Align::Right,
        );
    for c in &g.cells {
        let mut row = vec![c.view.clone(), c.pitch.to_string(), c.method.clone()];
        for f in [
            "see_through",
            "covers_sky",
            "depth_p50",
            "depth_p95",
            "coherence",
        ] {
            row.push(match c.spread.as_ref().and_then(|s| s.get(f)) {
                Some(v) if c.disagrees.iter().any(|d| d == f) => format!("**{}**", num(v, 3)),
                Some(v) => num(v, 3),
                None => "—".into(),
            });
        }
        row.push(format!("{} / {}", c.values.len(), g.adapters.len()));
        t.row(row);
    }
    t.write_to(md);
    md.push('\n');
}

fn edit_consistency(md: &mut String, g: &ProtocolGroup) {
    if g.edits.is_empty() {
        return;
    }
    md.push_str("### Edit consistency\n\n");
    md.push_str(
        "Post-edit frames until the edited renderer matches a fresh build, per adapter.\n\n",
    );
    let mut t = Table::new()
        .left("method")
        .columns(&g.adapters, Align::Right)
        .left("agrees");
    for e in &g.edits {
        let mut row = vec![e.method.clone()];
        for a in &g.adapters {
            row.push(
                match e.consistent_after_frames.iter().find(|(x, _)| x == a) {
                    Some((_, Some(n))) => n.to_string(),
                    Some((_, None)) => "not by 16".into(),
                    None => "—".into(),
                },
            );
        }
        row.push(if e.agrees { "yes" } else { "**no**" }.to_string());
        t.row(row);
    }
    t.write_to(md);
    md.push('\n');
}

/// Timing, apart per adapter and source.
fn frame_times(md: &mut String, g: &ProtocolGroup, pitches: &[f32]) {
    md.push_str("### Frame time (ms)\n\n");
    md.push_str(
        "Mean over the views of each view's frame mean, one row per adapter, timing source and pitch. GPU \
         timestamps sum per-pass GPU time; CPU submit-and-wait times a frame from submit to the end of the \
         GPU's work (what the paper reports where an adapter has no timestamps). Rows of different sources \
         are not comparable with each other.\n\n",
    );
    let mut t = Table::new()
        .columns(["adapter", "source", "pitch"], Align::Left)
        .columns(&g.protocol.methods, Align::Right);
    for a in &g.adapters {
        for source in [TimingSource::GpuTimestamps, TimingSource::CpuSubmitWait] {
            if !g
                .timing
                .iter()
                .any(|t| t.adapter == *a && t.source == source)
            {
                continue;
            }
            let pitch_rows = pitches.iter().map(|&p| Some(p)).chain([None]);
            for p in pitch_rows {
                let mut row = vec![
                    a.clone(),
                    source_title(source).to_string(),
                    p.map_or("all views".to_string(), pitch_label),
                ];
                for m in &g.protocol.methods {
                    let time = g.timing.iter().find(|t| {
                        t.adapter == *a && t.source == source && t.method == *m && t.pitch == p
                    });
                    row.push(or_dash(time.map(|t| num(t.mean_ms, 3))));
                }
                t.row(row);
            }
        }
    }
    t.write_to(md);
    md.push('\n');
}
