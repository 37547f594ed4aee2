//! `report.md`: the paper's tables from one run, or from several runs on
//! different adapters (`strata merge`). Accuracy comes from the first run
//! (the baseline); the other runs are cross-checked in `merge`.

use crate::stats;
use crate::{Disagreement, EditRow, FlipScore, Row, RunResults, TimingSource};
use std::fmt::Write as _;
use strata_markdown::{Align, Table, cell_text};

/// A figure written as `<name>.png` and `<name>.svg`: relative paths
/// (`strata_bench::figures` draws them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Figure {
    pub title: String,
    pub png: String,
    pub svg: String,
}

/// What the report embeds besides the tables.
#[derive(Clone, Debug, Default)]
pub struct Pictures {
    /// Relative path of the grid picture, when one was written.
    pub grid: Option<String>,
    /// Column titles of the grid, left to right.
    pub grid_columns: Vec<String>,
    /// The plotted figures (PNG and SVG), relative paths.
    pub figures: Vec<Figure>,
    /// The edit figure and its row titles.
    pub edit_figure: Option<(String, Vec<String>)>,
}

/// Render the report. `runs` must be non-empty; the first is the baseline.
pub fn render(runs: &[RunResults], pictures: &Pictures, disagreements: &[Disagreement]) -> String {
    let mut md = String::new();
    let Some(base) = runs.first() else {
        return "# Strata comparison\n\nNo runs.\n".into();
    };
    heading(&mut md, base);
    adapters_table(&mut md, runs);
    grid(&mut md, base, pictures);
    failures(&mut md, runs);
    accuracy_tables(&mut md, base);
    flip_table(&mut md, base);
    if runs.len() > 1 {
        cross_check(&mut md, runs, disagreements);
    }
    timing_tables(&mut md, runs);
    preparation_table(&mut md, runs);
    memory_table(&mut md, base);
    edit_tables(&mut md, runs);
    crate::gameplay::section(&mut md, runs);
    temporal_table(&mut md, runs);
    figures(&mut md, pictures);
    per_view_table(&mut md, base);
    md
}

/// The title and the protocol in one paragraph.
fn heading(md: &mut String, base: &RunResults) {
    let s = &base.settings;
    let _ = writeln!(md, "# Strata comparison: {}\n", base.level.name);
    let _ = writeln!(
        md,
        "Level `{}` ({}x{}, content hash `{}`); {}x{} pixels, far {}, {} timed frames per cell{}, shadows {}, \
         {} views x {} methods. Protocol version {}.\n",
        base.level.name,
        base.level.width,
        base.level.height,
        short_hash(&base.level.hash),
        s.width,
        s.height,
        s.far,
        s.frames,
        if s.hold_busy_ms > 0 {
            format!(
                " (each after {} ms of untimed frames back to back, which keeps the GPU at its busy clock)",
                s.hold_busy_ms
            )
        } else {
            String::new()
        },
        if s.shadows { "on" } else { "off" },
        s.views.len(),
        s.methods.len(),
        base.protocol_version,
    );
}

/// One row per run: the adapter, its timing source, revision and cells.
fn adapters_table(md: &mut String, runs: &[RunResults]) {
    let mut t = Table::new().columns(
        [
            "adapter", "backend", "driver", "timing", "revision", "cells",
        ],
        Align::Left,
    );
    for run in runs {
        let expected = run.settings.views.len() * run.settings.methods.len();
        t.row([
            run.adapter.name.clone(),
            run.adapter.backend.clone(),
            run.adapter.driver.clone(),
            if run.adapter.timestamps {
                "GPU timestamps"
            } else {
                "CPU submit-and-wait*"
            }
            .to_string(),
            format!("`{}`", run.source_revision),
            format!(
                "{} / {expected}{}",
                run.rows.len(),
                if run.complete { "" } else { " (incomplete)" }
            ),
        ]);
    }
    t.write_to(md);
    md.push('\n');
}

fn grid(md: &mut String, base: &RunResults, pictures: &Pictures) {
    let Some(grid) = &pictures.grid else {
        return;
    };
    let _ = writeln!(md, "![views down, methods across]({grid})\n");
    let _ = writeln!(
        md,
        "Views down ({}); columns: {}.\n",
        base.settings
            .views
            .iter()
            .map(|v| v.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        pictures.grid_columns.join(", ")
    );
}

fn failures(md: &mut String, runs: &[RunResults]) {
    for run in runs.iter().filter(|r| !r.failures.is_empty()) {
        let _ = writeln!(md, "**Failures on {}:**\n", cell_text(&run.adapter.name));
        for f in &run.failures {
            let _ = writeln!(md, "- {} at {}: {}", f.method, f.view, cell_text(&f.error));
        }
        md.push('\n');
    }
}

fn figures(md: &mut String, pictures: &Pictures) {
    if pictures.figures.is_empty() && pictures.edit_figure.is_none() {
        return;
    }
    md.push_str("## Figures\n\n");
    for f in &pictures.figures {
        let _ = writeln!(
            md,
            "![{}]({})\n\n{} ([SVG]({}))\n",
            f.title, f.png, f.title, f.svg
        );
    }
    if let Some((png, rows)) = &pictures.edit_figure {
        let _ = writeln!(
            md,
            "![the edit camera before the crater and on the first post-edit frame]({png})\n\n\
             The edit camera before the crater and on the first post-edit frame, one method per \
             update class: {}.\n",
            rows.join("; ")
        );
    }
}

/// `compare --temporal`: each method's flicker along the short path.
fn temporal_table(md: &mut String, runs: &[RunResults]) {
    if runs.iter().all(|r| r.temporal.is_empty()) {
        return;
    }
    md.push_str("## Temporal flicker\n\n");
    md.push_str(
        "Percent of pixels whose depth changes between consecutive frames by more than the CPU \
         reference's own change (4 % of the distance), or that switch between terrain and sky \
         when the reference does not: mean over frame pairs / worst pair, along the video's \
         default path played short (the crater dug midway).\n\n",
    );
    let mut t = Table::new()
        .left("adapter")
        .left("method")
        .right("flicker % mean / worst")
        .right("frames")
        .left("dug")
        .right("frame ms");
    for run in runs {
        for r in &run.temporal {
            t.row([
                run.adapter.name.clone(),
                r.method.clone(),
                format!("{:.2} / {:.2}", r.flicker_mean, r.flicker_max),
                format!("{} at {} fps", r.frames, r.fps),
                if r.dug { "yes" } else { "no" }.to_string(),
                format!("{:.2}", r.frame_ms_mean),
            ]);
        }
    }
    t.write_to(md);
    md.push('\n');
}

fn short_hash(h: &str) -> &str {
    h.get(..12).unwrap_or(h)
}

/// Distinct pitches in view order, highest (horizon) first.
pub fn pitches(run: &RunResults) -> Vec<f32> {
    distinct_pitches(run.settings.views.iter().map(|v| v.pitch))
}

/// The distinct values of `pitches`, highest (horizon) first.
pub fn distinct_pitches(pitches: impl IntoIterator<Item = f32>) -> Vec<f32> {
    let mut ps: Vec<f32> = Vec::new();
    for p in pitches {
        if !ps.contains(&p) {
            ps.push(p);
        }
    }
    ps.sort_by(|a, b| b.total_cmp(a));
    ps
}

/// A pitch as the tables write it (`-45°`).
pub fn pitch_label(p: f32) -> String {
    format!("{p}°")
}

fn rows_of<'a>(run: &'a RunResults, method: &'a str) -> impl Iterator<Item = &'a Row> + 'a {
    run.rows.iter().filter(move |r| r.method == method)
}

/// Mean of `f` over the rows of `method` at `pitch`.
fn pitch_mean(run: &RunResults, method: &str, pitch: f32, f: impl Fn(&Row) -> f64) -> Option<f64> {
    let xs: Vec<f64> = rows_of(run, method)
        .filter(|r| r.pitch == pitch)
        .map(f)
        .collect();
    stats::mean(&xs)
}

/// A table of one row title column, then one number column per method.
fn per_method(first: &str, methods: &[String]) -> Table {
    Table::new().left(first).columns(methods, Align::Right)
}

/// A value or the dash of a missing one.
fn or_dash(v: Option<String>) -> String {
    v.unwrap_or_else(|| "—".into())
}

/// One row per pitch, one column per method: `cell` formats the method's
/// rows at that pitch.
fn pitch_table(md: &mut String, run: &RunResults, cell: impl Fn(&str, f32) -> Option<String>) {
    let methods = &run.settings.methods;
    let mut t = per_method("pitch", methods);
    for p in pitches(run) {
        let cells = methods.iter().map(|m| or_dash(cell(m, p)));
        t.row(std::iter::once(pitch_label(p)).chain(cells));
    }
    t.write_to(md);
}

fn accuracy_tables(md: &mut String, run: &RunResults) {
    md.push_str("## Accuracy by pitch\n\n");
    let _ = writeln!(
        md,
        "see-through / coherence error (% of pixels), arithmetic mean over the views at each pitch ({}).\n",
        cell_text(&run.adapter.name)
    );
    pitch_table(md, run, |m, p| {
        let see = pitch_mean(run, m, p, |r| r.see_through)?;
        let coh = pitch_mean(run, m, p, |r| r.coherence)?;
        Some(format!("{see:.1} / {coh:.1}"))
    });
    md.push_str("\ncovers-sky (%) / depth error p50 / p95 (world units), same means.\n\n");
    pitch_table(md, run, |m, p| {
        let sky = pitch_mean(run, m, p, |r| r.covers_sky)?;
        let p50 = pitch_mean(run, m, p, |r| r.depth_p50)?;
        let p95 = pitch_mean(run, m, p, |r| r.depth_p95)?;
        Some(format!("{sky:.1} / {p50:.2} / {p95:.2}"))
    });
    md.push('\n');
}

/// Mean ꟻLIP per pitch, where the run measured it (older runs and the
/// browser's did not: then no table).
fn flip_table(md: &mut String, run: &RunResults) {
    if !run.rows.iter().any(|r| r.flip.is_some()) {
        return;
    }
    md.push_str("## Colour error by pitch (ꟻLIP)\n\n");
    let _ = writeln!(
        md,
        "ꟻLIP of each picture against the CPU colour reference (the shared shading at the exact hits, \
         shadows from the CPU twin of the shadow map): mean ꟻLIP / % of pixels above 0.5, arithmetic \
         mean over the views at each pitch ({}). Error maps: `cells/*-flip.png`.\n",
        cell_text(&run.adapter.name)
    );
    pitch_table(md, run, |m, p| {
        let flip = |f: fn(&FlipScore) -> f64| {
            let xs: Vec<f64> = rows_of(run, m)
                .filter(|r| r.pitch == p)
                .filter_map(|r| r.flip.as_ref().map(f))
                .collect();
            stats::mean(&xs)
        };
        Some(format!(
            "{:.3} / {:.1}",
            flip(|f| f.mean)?,
            flip(|f| f.over_half)?
        ))
    });
    md.push('\n');
}

fn cross_check(md: &mut String, runs: &[RunResults], disagreements: &[Disagreement]) {
    md.push_str("## Cross-device accuracy check\n\n");
    let _ = writeln!(
        md,
        "Every accuracy field of {} other run(s) compared with the baseline ({}); percent fields are flagged \
         beyond 0.5 percentage points, depth fields beyond 0.5 world units.\n",
        runs.len() - 1,
        cell_text(&runs[0].adapter.name)
    );
    if disagreements.is_empty() {
        md.push_str("No field disagrees.\n\n");
        return;
    }
    let mut t = Table::new()
        .columns(["adapter", "view", "method", "field"], Align::Left)
        .right("baseline")
        .right("this adapter");
    let fmt = |v: Option<f64>| v.map_or("missing".to_string(), |v| format!("{v:.3}"));
    for d in disagreements {
        t.row([
            d.adapter.clone(),
            d.view.clone(),
            d.method.clone(),
            d.field.to_string(),
            fmt(d.baseline),
            fmt(d.other),
        ]);
    }
    t.write_to(md);
    md.push('\n');
}

fn uses_cpu_time(run: &RunResults) -> bool {
    run.rows
        .iter()
        .any(|r| r.timing_source == TimingSource::CpuSubmitWait)
}

/// A run's adapter name, starred when some of its times are CPU submit-and-wait.
fn starred_name(run: &RunResults) -> String {
    let star = if uses_cpu_time(run) { "*" } else { "" };
    format!("{}{star}", run.adapter.name)
}

fn timing_tables(md: &mut String, runs: &[RunResults]) {
    let methods = &runs[0].settings.methods;
    md.push_str("## Frame time by pitch (ms)\n\n");
    md.push_str(
        "Mean over the views at each pitch of each view's frame mean. GPU rows sum per-pass timestamps; \
         rows marked * are CPU submit-and-wait (no timestamps), comparable among methods on that adapter only.\n\n",
    );
    let mut t = per_method("adapter / pitch", methods);
    for run in runs {
        for p in pitches(run) {
            let means: Vec<Option<f64>> = methods
                .iter()
                .map(|m| pitch_mean(run, m, p, Row::frame_ms))
                .collect();
            let best = means
                .iter()
                .flatten()
                .copied()
                .fold(f64::INFINITY, f64::min);
            let cells = means.into_iter().map(|v| match v {
                Some(v) if v == best => format!("**{v:.3}**"),
                Some(v) => format!("{v:.3}"),
                None => "—".into(),
            });
            let title = format!("{} / {}", starred_name(run), pitch_label(p));
            t.row(std::iter::once(title).chain(cells));
        }
    }
    t.write_to(md);
    md.push_str("\nCPU submit-and-wait (ms), same means, every adapter.\n\n");
    let mut t = per_method("adapter / pitch", methods);
    for run in runs {
        for p in pitches(run) {
            let cells = methods.iter().map(|m| {
                or_dash(pitch_mean(run, m, p, |r| r.cpu_ms_mean).map(|v| format!("{v:.3}")))
            });
            let title = format!("{} / {}", run.adapter.name, pitch_label(p));
            t.row(std::iter::once(title).chain(cells));
        }
    }
    t.write_to(md);
    md.push_str(
        "\n95 % intervals of the mean over all views of each view's frame mean, from the frame samples \
         (mean ± 1.96·sqrt(Σ s²/n)/V).\n\n",
    );
    let mut t = per_method("adapter", methods);
    for run in runs {
        let cells = methods.iter().map(|m| {
            let samples: Vec<&[f64]> = rows_of(run, m).map(Row::frame_samples).collect();
            or_dash(
                stats::mean_of_means_interval(&samples)
                    .map(|(mean, half)| format!("{mean:.3} ± {half:.3}")),
            )
        });
        t.row(std::iter::once(starred_name(run)).chain(cells));
    }
    t.write_to(md);
    md.push('\n');
}

fn max_of(run: &RunResults, method: &str, f: impl Fn(&Row) -> f64) -> Option<f64> {
    rows_of(run, method).map(f).reduce(f64::max)
}

fn preparation_table(md: &mut String, runs: &[RunResults]) {
    md.push_str("## Preparation (ms, maximum over views)\n\n");
    md.push_str(
        "setup builds pipelines and uploads; first frame adds whatever the method builds lazily; \
         warm-up covers every pre-timing frame.\n\n",
    );
    let mut t = Table::new()
        .left("adapter")
        .left("method")
        .columns(["setup", "first frame", "warm-up"], Align::Right);
    for run in runs {
        for m in &run.settings.methods {
            let (Some(a), Some(b), Some(c)) = (
                max_of(run, m, |r| r.prep_setup_ms),
                max_of(run, m, |r| r.prep_first_frame_ms),
                max_of(run, m, |r| r.prep_warmup_ms),
            ) else {
                continue;
            };
            t.row([
                run.adapter.name.clone(),
                m.clone(),
                format!("{a:.0}"),
                format!("{b:.0}"),
                format!("{c:.0}"),
            ]);
        }
    }
    t.write_to(md);
    md.push('\n');
}

/// MiB with two decimals; "<0.01" for a small non-zero size.
pub fn mib(bytes: u64) -> String {
    let v = bytes as f64 / (1024.0 * 1024.0);
    if bytes > 0 && v < 0.005 {
        "<0.01".into()
    } else {
        format!("{v:.2}")
    }
}

fn memory_table(md: &mut String, run: &RunResults) {
    md.push_str("## Retained method data (MiB)\n\n");
    md.push_str(
        "Persistent method-specific allocations only: shared terrain, palette, colour/depth and shadow \
         textures, pipelines and staging are excluded. Maximum over views.\n\n",
    );
    let mut t = Table::new()
        .left("method")
        .columns(["GPU data", "CPU data"], Align::Right);
    for m in &run.settings.methods {
        let gpu = rows_of(run, m).map(|r| r.gpu_bytes).max();
        let cpu = rows_of(run, m).map(|r| r.cpu_bytes).max();
        if let (Some(g), Some(c)) = (gpu, cpu) {
            t.row([m.clone(), mib(g), mib(c)]);
        }
    }
    t.write_to(md);
    md.push('\n');
}

fn fmt_opt(v: Option<f64>) -> String {
    or_dash(v.map(|v| format!("{v:.2}")))
}

fn fmt_delta(a: Option<f64>, b: Option<f64>) -> String {
    match (a, b) {
        (Some(a), Some(b)) => format!("{:+.2}", b - a),
        _ => "—".into(),
    }
}

fn match_label(e: &EditRow) -> String {
    match e.consistent_after_frames {
        Some(1) => "1 frame".into(),
        Some(n) => format!("{n} frames"),
        None => "not by 16".into(),
    }
}

fn edit_tables(md: &mut String, runs: &[RunResults]) {
    if runs
        .iter()
        .all(|r| r.edit_rows.is_empty() && r.edit_skipped.is_none())
    {
        return;
    }
    md.push_str("## Edit\n\n");
    md.push_str(
        "Crater edit seen from the edit camera. CPU/GPU₀: median frame of a renderer built fresh from the \
         edited level; CPU/GPU₁: median of 5 independent first post-edit frames (CPU is submit-and-wait: \
         upload + any rebuild + GPU work + round trip). match: post-edit frames until the edited renderer \
         agrees with the fresh build (≤ 0.01 % hit/miss, p95 depth ≤ 0.1); the last column is the \
         disagreement at that check (at 16 when never consistent).\n\n",
    );
    for run in runs {
        let _ = writeln!(md, "{}:\n", cell_text(&run.adapter.name));
        if let Some(why) = &run.edit_skipped {
            let _ = writeln!(md, "Not run: {}\n", cell_text(why));
            continue;
        }
        edit_table(md, &run.edit_rows);
        md.push('\n');
    }
}

fn edit_table(md: &mut String, rows: &[EditRow]) {
    let mut t = Table::new()
        .left("method")
        .columns(["CPU₀", "CPU₁", "ΔC", "GPU₀", "GPU₁", "ΔG"], Align::Right)
        .left("match")
        .left("last check: hit/miss % / p95");
    for e in rows {
        let last = e.checks.last().map_or("—".into(), |c| {
            format!("{:.4} / {:.2}", c.class_mismatch, c.depth_p95)
        });
        t.row([
            e.method.clone(),
            format!("{:.2}", e.steady_cpu_ms),
            format!("{:.2}", e.first_frame_cpu_ms),
            fmt_delta(Some(e.steady_cpu_ms), Some(e.first_frame_cpu_ms)),
            fmt_opt(e.steady_gpu_ms),
            fmt_opt(e.first_frame_gpu_ms),
            fmt_delta(e.steady_gpu_ms, e.first_frame_gpu_ms),
            match_label(e),
            last,
        ]);
    }
    t.write_to(md);
}

fn per_view_table(md: &mut String, run: &RunResults) {
    md.push_str("## Every cell\n\n");
    let _ = writeln!(md, "{}.\n", cell_text(&run.adapter.name));
    let mut t = Table::new()
        .left("view")
        .right("pitch")
        .left("method")
        .columns(
            [
                "see-through %",
                "covers-sky %",
                "p50",
                "p95",
                "coherence %",
                "GPU ms",
                "CPU ms",
            ],
            Align::Right,
        )
        .left("picture");
    for r in &run.rows {
        t.row([
            r.view.clone(),
            r.pitch.to_string(),
            r.method.clone(),
            format!("{:.2}", r.see_through),
            format!("{:.2}", r.covers_sky),
            format!("{:.2}", r.depth_p50),
            format!("{:.2}", r.depth_p95),
            format!("{:.2}", r.coherence),
            or_dash(r.gpu_ms_mean.map(|v| format!("{v:.3}"))),
            format!("{:.3}", r.cpu_ms_mean),
            format!("[png]({})", r.image),
        ]);
    }
    t.write_to(md);
    md.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    fn line_starting<'a>(md: &'a str, prefix: &str) -> &'a str {
        md.lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no line `{prefix}` in\n{md}"))
    }

    #[test]
    fn accuracy_and_timing_tables_hold_the_pitch_means() {
        let md = render(&[fixtures::run("gpu-a")], &Pictures::default(), &[]);
        // Accuracy: first table's 0° row; ray 0.6/0.4, mesh 0.3/0.1.
        assert_eq!(
            line_starting(&md, "| 0° |"),
            "| 0° | 0.6 / 0.4 | 0.3 / 0.1 |"
        );
        assert!(md.contains("| -90° | 0.1 / 0.5 | 0.0 / 0.1 |"), "{md}");
        // Frame time: ray mean 5, mesh 2 (fastest, bold).
        assert!(md.contains("| gpu-a / 0° | 5.000 | **2.000** |"), "{md}");
        // Interval: ray over views: means 5 and 7 -> 6; sd 1, n 3 each -> 1.96 sqrt(2/3)/2.
        let half = 1.96 * (2.0f64 / 3.0).sqrt() / 2.0;
        assert!(
            md.contains(&format!("| gpu-a | 6.000 ± {half:.3} | 2.500 ± 0.000 |")),
            "{md}"
        );
        // Preparation, memory, edit.
        assert!(md.contains("| gpu-a | ray | 10 | 20 | 30 |"));
        assert!(md.contains("| mesh | 3.00 | 0.00 |"));
        assert!(
            md.contains("| ray | 6.51 | 8.70 | +2.19 | 5.59 | 7.45 | +1.86 | 1 frame |"),
            "{md}"
        );
        assert!(!md.contains("Cross-device"));
    }

    #[test]
    fn cpu_only_runs_are_starred_and_missing_cells_dashed() {
        let mut run = fixtures::run("cpu-b");
        run.adapter.timestamps = false;
        run.complete = false;
        run.rows = vec![fixtures::row("river", 0.0, "ray", 1.0, 1.0, &[])];
        let md = render(
            &[run],
            &Pictures {
                grid: Some("grid.png".into()),
                grid_columns: vec!["reference".into()],
                ..Pictures::default()
            },
            &[],
        );
        assert!(md.contains("![views down, methods across](grid.png)"));
        // Without timestamps the frame time is the CPU mean (5 ms), starred.
        assert!(md.contains("| cpu-b* / 0° | **5.000** | — |"), "{md}");
        assert!(md.contains("| -90° | — | — |"), "{md}");
        assert!(md.contains("1 / 4 (incomplete)"), "{md}");
    }

    #[test]
    fn small_memory_is_marked() {
        assert_eq!(mib(0), "0.00");
        assert_eq!(mib(100), "<0.01");
        assert_eq!(mib(3 * 1024 * 1024 / 2), "1.50");
    }
}
