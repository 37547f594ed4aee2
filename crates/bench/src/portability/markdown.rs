//! `portability.md`: the report as Markdown tables, disagreeing cells first.

use super::*;

fn cell_text(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

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

fn pitch_label(p: f32) -> String {
    format!("{p}°")
}

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
    md.push_str(
        "| adapter | backend | driver | timing | group | revision | cells | results | grid |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for e in &r.runs {
        let timing = if e.adapter.timestamps {
            "GPU timestamps"
        } else {
            "CPU submit-and-wait"
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | `{}` | {} / {}{} | [json]({}) | {} |",
            cell_text(&e.label),
            cell_text(&e.adapter.backend),
            cell_text(&e.adapter.driver),
            timing,
            e.group,
            cell_text(&e.source_revision),
            e.cells,
            e.expected_cells,
            if e.complete { "" } else { " (incomplete)" },
            e.results,
            e.grid
                .as_ref()
                .map_or("—".to_string(), |g| format!("[grid]({g})")),
        );
    }
    md.push('\n');
    if !r.skipped.is_empty() {
        md.push_str("**Adapters that could not run at all:**\n\n");
        for s in &r.skipped {
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
    if r.groups.len() > 1 {
        md.push_str("## Protocol groups\n\n");
        md.push_str(
            "These runs were not all measured under one protocol, so merge refuses to compare accuracy \
             across groups; each group is reported on its own below.\n\n",
        );
        for g in &r.groups {
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
    for g in &r.groups {
        group_markdown(&mut md, g);
    }
    md
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
    }

    // Disagreements first.
    if g.adapters.len() > 1 {
        let _ = writeln!(
            md,
            "### Cells that disagree across adapters ({} of {})\n",
            g.disagreeing_cells,
            g.cells.len()
        );
        if g.disagreeing_cells == 0 {
            md.push_str("Every cell agrees within tolerance.\n\n");
        } else {
            for c in g.cells.iter().filter(|c| !c.disagrees.is_empty()) {
                let fields: Vec<&str> = c.disagrees.iter().map(|f| field_title(f)).collect();
                let _ = writeln!(
                    md,
                    "**{} / {}** ({}): {}\n",
                    cell_text(&c.view),
                    cell_text(&c.method),
                    pitch_label(c.pitch),
                    fields.join(", ")
                );
                md.push_str(
                    "| adapter | see-through % | covers-sky % | p50 | p95 | coherence % | picture |\n\
                     |---|---:|---:|---:|---:|---:|---|\n",
                );
                for v in &c.values {
                    let a = &v.accuracy;
                    let _ = writeln!(
                        md,
                        "| {} | {} | {} | {} | {} | {} | {} |",
                        cell_text(&v.adapter),
                        num(a.see_through, 3),
                        num(a.covers_sky, 3),
                        num(a.depth_p50, 3),
                        num(a.depth_p95, 3),
                        num(a.coherence, 3),
                        v.picture
                            .as_ref()
                            .map_or("—".to_string(), |p| format!("[png]({p})"))
                    );
                }
                for a in &c.absent {
                    let _ = writeln!(
                        md,
                        "| {} | — | — | — | — | — | {} |",
                        cell_text(&a.adapter),
                        a.failure.as_ref().map_or(
                            "missing (run incomplete)".to_string(),
                            |f| format!("refused: {}", cell_text(f))
                        )
                    );
                }
                if let Some(s) = &c.spread {
                    let _ = writeln!(
                        md,
                        "| **spread** | {} | {} | {} | {} | {} | |",
                        num(s.see_through, 3),
                        num(s.covers_sky, 3),
                        num(s.depth_p50, 3),
                        num(s.depth_p95, 3),
                        num(s.coherence, 3)
                    );
                }
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
        }
    }

    // Refusals and failures.
    let _ = writeln!(md, "### Refused or failed ({})\n", g.failures.len());
    if g.failures.is_empty() {
        md.push_str("Every method ran on every adapter of this group.\n\n");
    } else {
        md.push_str("| adapter | method | view | error |\n|---|---|---|---|\n");
        for f in &g.failures {
            let view = if f.view == "*" {
                "every view"
            } else {
                f.view.as_str()
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} |",
                cell_text(&f.adapter),
                cell_text(&f.method),
                cell_text(view),
                cell_text(&f.error)
            );
        }
        md.push('\n');
    }

    // Pitch means: methods and pitches down, adapters across, spread last.
    let pitches = {
        let mut ps: Vec<f32> = Vec::new();
        for c in &g.cells {
            if !ps.contains(&c.pitch) {
                ps.push(c.pitch);
            }
        }
        ps.sort_by(|a, b| b.total_cmp(a));
        ps
    };
    let spread_col = g.adapters.len() > 1;
    let accuracy_table = |md: &mut String, title: &str, fmt: &dyn Fn(&Accuracy) -> String| {
        md.push_str(title);
        md.push_str("\n\n| method / pitch |");
        for a in &g.adapters {
            let _ = write!(md, " {} |", cell_text(a));
        }
        if spread_col {
            md.push_str(" spread |");
        }
        md.push_str("\n|---|");
        for _ in &g.adapters {
            md.push_str("---:|");
        }
        if spread_col {
            md.push_str("---:|");
        }
        md.push('\n');
        for m in &g.protocol.methods {
            for &p in &pitches {
                let _ = write!(md, "| {} / {} |", cell_text(m), pitch_label(p));
                for a in &g.adapters {
                    match g
                        .pitch_means
                        .iter()
                        .find(|x| x.adapter == *a && x.method == *m && x.pitch == p)
                    {
                        Some(x) => {
                            let _ = write!(md, " {} |", fmt(&x.mean));
                        }
                        None => md.push_str(" — |"),
                    }
                }
                if spread_col {
                    match g
                        .pitch_spreads
                        .iter()
                        .find(|x| x.method == *m && x.pitch == p)
                    {
                        Some(x) => {
                            let _ = write!(md, " {} |", fmt(&x.spread));
                        }
                        None => md.push_str(" — |"),
                    }
                }
                md.push('\n');
            }
        }
        md.push('\n');
    };
    md.push_str("### Accuracy by pitch\n\n");
    accuracy_table(
        md,
        "see-through / coherence error (% of pixels), mean over the views at each pitch; spread = max − min \
         of the adapters' means.",
        &|a| format!("{} / {}", num(a.see_through, 2), num(a.coherence, 2)),
    );
    accuracy_table(
        md,
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

    if !g.method_max_spreads.is_empty() {
        md.push_str("### Largest spread per method\n\n");
        md.push_str(
            "The largest max − min across adapters over the method's cells, each field on its own.\n\n\
             | method | see-through % | covers-sky % | p50 | p95 | coherence % |\n\
             |---|---:|---:|---:|---:|---:|\n",
        );
        for m in &g.method_max_spreads {
            let a = &m.max;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} |",
                cell_text(&m.method),
                num(a.see_through, 3),
                num(a.covers_sky, 3),
                num(a.depth_p50, 3),
                num(a.depth_p95, 3),
                num(a.coherence, 3)
            );
        }
        md.push('\n');
    }

    // Every cell's spread.
    if g.adapters.len() > 1 {
        md.push_str("### Spread per cell\n\n");
        md.push_str(
            "max − min across the adapters that have the cell; disagreeing cells first (**bold** fields \
             beyond tolerance).\n\n\
             | view | pitch | method | see-through | covers-sky | p50 | p95 | coherence | adapters |\n\
             |---|---:|---|---:|---:|---:|---:|---:|---:|\n",
        );
        for c in &g.cells {
            let _ = write!(
                md,
                "| {} | {} | {} |",
                cell_text(&c.view),
                c.pitch,
                cell_text(&c.method)
            );
            for f in [
                "see_through",
                "covers_sky",
                "depth_p50",
                "depth_p95",
                "coherence",
            ] {
                match c.spread.as_ref().and_then(|s| s.get(f)) {
                    Some(v) if c.disagrees.iter().any(|d| d == f) => {
                        let _ = write!(md, " **{}** |", num(v, 3));
                    }
                    Some(v) => {
                        let _ = write!(md, " {} |", num(v, 3));
                    }
                    None => md.push_str(" — |"),
                }
            }
            let _ = writeln!(md, " {} / {} |", c.values.len(), g.adapters.len());
        }
        md.push('\n');
    }

    // Edits.
    if !g.edits.is_empty() {
        md.push_str("### Edit consistency\n\n");
        md.push_str(
            "Post-edit frames until the edited renderer matches a fresh build, per adapter.\n\n",
        );
        md.push_str("| method |");
        for a in &g.adapters {
            let _ = write!(md, " {} |", cell_text(a));
        }
        md.push_str(" agrees |\n|---|");
        for _ in &g.adapters {
            md.push_str("---:|");
        }
        md.push_str("---|\n");
        for e in &g.edits {
            let _ = write!(md, "| {} |", cell_text(&e.method));
            for a in &g.adapters {
                match e.consistent_after_frames.iter().find(|(x, _)| x == a) {
                    Some((_, Some(n))) => {
                        let _ = write!(md, " {n} |");
                    }
                    Some((_, None)) => md.push_str(" not by 16 |"),
                    None => md.push_str(" — |"),
                }
            }
            let _ = writeln!(md, " {} |", if e.agrees { "yes" } else { "**no**" });
        }
        md.push('\n');
    }

    // Timing, apart per adapter and source.
    md.push_str("### Frame time (ms)\n\n");
    md.push_str(
        "Mean over the views of each view's frame mean, one row per adapter, timing source and pitch. GPU \
         timestamps sum per-pass GPU time; CPU submit-and-wait times a frame from submit to the end of the \
         GPU's work (what the paper reports where an adapter has no timestamps). Rows of different sources \
         are not comparable with each other.\n\n",
    );
    md.push_str("| adapter | source | pitch |");
    for m in &g.protocol.methods {
        let _ = write!(md, " {} |", cell_text(m));
    }
    md.push_str("\n|---|---|---|");
    for _ in &g.protocol.methods {
        md.push_str("---:|");
    }
    md.push('\n');
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
                let _ = write!(
                    md,
                    "| {} | {} | {} |",
                    cell_text(a),
                    source_title(source),
                    p.map_or("all views".to_string(), pitch_label)
                );
                for m in &g.protocol.methods {
                    match g.timing.iter().find(|t| {
                        t.adapter == *a && t.source == source && t.method == *m && t.pitch == p
                    }) {
                        Some(t) => {
                            let _ = write!(md, " {} |", num(t.mean_ms, 3));
                        }
                        None => md.push_str(" — |"),
                    }
                }
                md.push('\n');
            }
        }
    }
    md.push('\n');
}
