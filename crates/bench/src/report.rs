//! `report.md`: the paper's tables from one run, or from several runs on
//! different adapters (`strata merge`). Accuracy comes from the first run
//! (the baseline); the other runs are cross-checked in `merge`.

use crate::merge::Disagreement;
use crate::results::{EditRow, FlipScore, Row, RunResults, TimingSource};
use crate::stats;
use std::fmt::Write as _;

/// What the report embeds besides the tables.
#[derive(Clone, Debug, Default)]
pub struct Pictures {
    /// Relative path of the grid picture, when one was written.
    pub grid: Option<String>,
    /// Column titles of the grid, left to right.
    pub grid_columns: Vec<String>,
    /// The plotted figures (PNG and SVG), relative paths.
    pub figures: Vec<crate::figures::Figure>,
    /// The edit figure and its row titles.
    pub edit_figure: Option<(String, Vec<String>)>,
}

impl Pictures {
    /// Draw the figures of `runs` into `dir` (a failure costs the figures,
    /// with a warning, never the report).
    pub fn with_figures(mut self, runs: &[RunResults], dir: &std::path::Path) -> Self {
        match crate::figures::write_all(runs, dir) {
            Ok(f) => self.figures = f,
            Err(e) => eprintln!("warning: figures not drawn: {e:#}"),
        }
        if let Some(base) = runs.first() {
            match crate::figures::edit_figure(base, dir) {
                Ok(f) => self.edit_figure = f,
                Err(e) => eprintln!("warning: edit figure not drawn: {e:#}"),
            }
        }
        self
    }
}

/// Render the report. `runs` must be non-empty; the first is the baseline.
pub fn render(runs: &[RunResults], pictures: &Pictures, disagreements: &[Disagreement]) -> String {
    let mut md = String::new();
    let Some(base) = runs.first() else {
        return "# Strata comparison\n\nNo runs.\n".into();
    };
    let methods = &base.settings.methods;
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
        methods.len(),
        base.protocol_version,
    );
    md.push_str(
        "| adapter | backend | driver | timing | revision | cells |\n|---|---|---|---|---|---|\n",
    );
    for run in runs {
        let expected = run.settings.views.len() * run.settings.methods.len();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | `{}` | {} / {}{} |",
            cell_text(&run.adapter.name),
            cell_text(&run.adapter.backend),
            cell_text(&run.adapter.driver),
            if run.adapter.timestamps {
                "GPU timestamps"
            } else {
                "CPU submit-and-wait*"
            },
            cell_text(&run.source_revision),
            run.rows.len(),
            expected,
            if run.complete { "" } else { " (incomplete)" },
        );
    }
    md.push('\n');

    if let Some(grid) = &pictures.grid {
        let _ = writeln!(md, "![views down, methods across]({grid})\n");
        let _ = writeln!(
            md,
            "Views down ({}); columns: {}.\n",
            s.views
                .iter()
                .map(|v| v.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            pictures.grid_columns.join(", ")
        );
    }

    for run in runs {
        if !run.failures.is_empty() {
            let _ = writeln!(md, "**Failures on {}:**\n", cell_text(&run.adapter.name));
            for f in &run.failures {
                let _ = writeln!(md, "- {} at {}: {}", f.method, f.view, cell_text(&f.error));
            }
            md.push('\n');
        }
    }

    accuracy_tables(&mut md, base);
    flip_table(&mut md, base);
    if runs.len() > 1 {
        cross_check(&mut md, runs, disagreements);
    }
    timing_tables(&mut md, runs);
    preparation_table(&mut md, runs);
    memory_table(&mut md, base);
    edit_tables(&mut md, runs);
    temporal_table(&mut md, runs);
    figures(&mut md, pictures);
    per_view_table(&mut md, base);
    md
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
    md.push_str("| adapter | method | flicker % mean / worst | frames | dug | frame ms |\n|---|---|---:|---:|---|---:|\n");
    for run in runs {
        for t in &run.temporal {
            let _ = writeln!(
                md,
                "| {} | {} | {:.2} / {:.2} | {} at {} fps | {} | {:.2} |",
                cell_text(&run.adapter.name),
                t.method,
                t.flicker_mean,
                t.flicker_max,
                t.frames,
                t.fps,
                if t.dug { "yes" } else { "no" },
                t.frame_ms_mean
            );
        }
    }
    md.push('\n');
}

fn short_hash(h: &str) -> &str {
    h.get(..12).unwrap_or(h)
}

/// Keep user text from breaking a table row.
fn cell_text(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

/// Distinct pitches in view order, highest (horizon) first.
pub fn pitches(run: &RunResults) -> Vec<f32> {
    let mut ps: Vec<f32> = Vec::new();
    for v in &run.settings.views {
        if !ps.contains(&v.pitch) {
            ps.push(v.pitch);
        }
    }
    ps.sort_by(|a, b| b.total_cmp(a));
    ps
}

fn pitch_label(p: f32) -> String {
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

fn header(md: &mut String, first: &str, methods: &[String]) {
    let _ = write!(md, "| {first} |");
    for m in methods {
        let _ = write!(md, " {m} |");
    }
    md.push_str("\n|---|");
    for _ in methods {
        md.push_str("---:|");
    }
    md.push('\n');
}

fn accuracy_tables(md: &mut String, run: &RunResults) {
    let methods = &run.settings.methods;
    md.push_str("## Accuracy by pitch\n\n");
    let _ = writeln!(
        md,
        "see-through / coherence error (% of pixels), arithmetic mean over the views at each pitch ({}).\n",
        cell_text(&run.adapter.name)
    );
    header(md, "pitch", methods);
    for p in pitches(run) {
        let _ = write!(md, "| {} |", pitch_label(p));
        for m in methods {
            let see = pitch_mean(run, m, p, |r| r.see_through);
            let coh = pitch_mean(run, m, p, |r| r.coherence);
            match (see, coh) {
                (Some(a), Some(b)) => {
                    let _ = write!(md, " {a:.1} / {b:.1} |");
                }
                _ => md.push_str(" — |"),
            }
        }
        md.push('\n');
    }
    md.push_str("\ncovers-sky (%) / depth error p50 / p95 (world units), same means.\n\n");
    header(md, "pitch", methods);
    for p in pitches(run) {
        let _ = write!(md, "| {} |", pitch_label(p));
        for m in methods {
            let sky = pitch_mean(run, m, p, |r| r.covers_sky);
            let p50 = pitch_mean(run, m, p, |r| r.depth_p50);
            let p95 = pitch_mean(run, m, p, |r| r.depth_p95);
            match (sky, p50, p95) {
                (Some(a), Some(b), Some(c)) => {
                    let _ = write!(md, " {a:.1} / {b:.2} / {c:.2} |");
                }
                _ => md.push_str(" — |"),
            }
        }
        md.push('\n');
    }
    md.push('\n');
}

/// Mean ꟻLIP per pitch, where the run measured it (older runs and the
/// browser's did not: then no table).
fn flip_table(md: &mut String, run: &RunResults) {
    if !run.rows.iter().any(|r| r.flip.is_some()) {
        return;
    }
    let methods = &run.settings.methods;
    md.push_str("## Colour error by pitch (ꟻLIP)\n\n");
    let _ = writeln!(
        md,
        "ꟻLIP of each picture against the CPU colour reference (the shared shading at the exact hits, \
         shadows from the CPU twin of the shadow map): mean ꟻLIP / % of pixels above 0.5, arithmetic \
         mean over the views at each pitch ({}). Error maps: `cells/*-flip.png`.\n",
        cell_text(&run.adapter.name)
    );
    header(md, "pitch", methods);
    for p in pitches(run) {
        let _ = write!(md, "| {} |", pitch_label(p));
        for m in methods {
            let flip = |f: fn(&FlipScore) -> f64| {
                let xs: Vec<f64> = rows_of(run, m)
                    .filter(|r| r.pitch == p)
                    .filter_map(|r| r.flip.as_ref().map(f))
                    .collect();
                stats::mean(&xs)
            };
            match (flip(|f| f.mean), flip(|f| f.over_half)) {
                (Some(a), Some(b)) => {
                    let _ = write!(md, " {a:.3} / {b:.1} |");
                }
                _ => md.push_str(" — |"),
            }
        }
        md.push('\n');
    }
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
    md.push_str("| adapter | view | method | field | baseline | this adapter |\n|---|---|---|---|---:|---:|\n");
    for d in disagreements {
        let fmt = |v: Option<f64>| v.map_or("missing".to_string(), |v| format!("{v:.3}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} |",
            cell_text(&d.adapter),
            cell_text(&d.view),
            cell_text(&d.method),
            d.field,
            fmt(d.baseline),
            fmt(d.other)
        );
    }
    md.push('\n');
}

fn uses_cpu_time(run: &RunResults) -> bool {
    run.rows
        .iter()
        .any(|r| r.timing_source == TimingSource::CpuSubmitWait)
}

fn timing_tables(md: &mut String, runs: &[RunResults]) {
    let methods = &runs[0].settings.methods;
    md.push_str("## Frame time by pitch (ms)\n\n");
    md.push_str(
        "Mean over the views at each pitch of each view's frame mean. GPU rows sum per-pass timestamps; \
         rows marked * are CPU submit-and-wait (no timestamps), comparable among methods on that adapter only.\n\n",
    );
    header(md, "adapter / pitch", methods);
    for run in runs {
        let star = if uses_cpu_time(run) { "*" } else { "" };
        for p in pitches(run) {
            let _ = write!(
                md,
                "| {}{star} / {} |",
                cell_text(&run.adapter.name),
                pitch_label(p)
            );
            let means: Vec<Option<f64>> = methods
                .iter()
                .map(|m| pitch_mean(run, m, p, Row::frame_ms))
                .collect();
            let best = means
                .iter()
                .flatten()
                .copied()
                .fold(f64::INFINITY, f64::min);
            for v in means {
                match v {
                    Some(v) if v == best => {
                        let _ = write!(md, " **{v:.3}** |");
                    }
                    Some(v) => {
                        let _ = write!(md, " {v:.3} |");
                    }
                    None => md.push_str(" — |"),
                }
            }
            md.push('\n');
        }
    }
    md.push_str("\nCPU submit-and-wait (ms), same means, every adapter.\n\n");
    header(md, "adapter / pitch", methods);
    for run in runs {
        for p in pitches(run) {
            let _ = write!(
                md,
                "| {} / {} |",
                cell_text(&run.adapter.name),
                pitch_label(p)
            );
            for m in methods {
                match pitch_mean(run, m, p, |r| r.cpu_ms_mean) {
                    Some(v) => {
                        let _ = write!(md, " {v:.3} |");
                    }
                    None => md.push_str(" — |"),
                }
            }
            md.push('\n');
        }
    }
    md.push_str(
        "\n95 % intervals of the mean over all views of each view's frame mean, from the frame samples \
         (mean ± 1.96·sqrt(Σ s²/n)/V).\n\n",
    );
    header(md, "adapter", methods);
    for run in runs {
        let star = if uses_cpu_time(run) { "*" } else { "" };
        let _ = write!(md, "| {}{star} |", cell_text(&run.adapter.name));
        for m in methods {
            let samples: Vec<&[f64]> = rows_of(run, m).map(Row::frame_samples).collect();
            match stats::mean_of_means_interval(&samples) {
                Some((mean, half)) => {
                    let _ = write!(md, " {mean:.3} ± {half:.3} |");
                }
                None => md.push_str(" — |"),
            }
        }
        md.push('\n');
    }
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
    md.push_str("| adapter | method | setup | first frame | warm-up |\n|---|---|---:|---:|---:|\n");
    for run in runs {
        for m in &run.settings.methods {
            let (Some(a), Some(b), Some(c)) = (
                max_of(run, m, |r| r.prep_setup_ms),
                max_of(run, m, |r| r.prep_first_frame_ms),
                max_of(run, m, |r| r.prep_warmup_ms),
            ) else {
                continue;
            };
            let _ = writeln!(
                md,
                "| {} | {m} | {a:.0} | {b:.0} | {c:.0} |",
                cell_text(&run.adapter.name)
            );
        }
    }
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
    md.push_str("| method | GPU data | CPU data |\n|---|---:|---:|\n");
    for m in &run.settings.methods {
        let gpu = rows_of(run, m).map(|r| r.gpu_bytes).max();
        let cpu = rows_of(run, m).map(|r| r.cpu_bytes).max();
        if let (Some(g), Some(c)) = (gpu, cpu) {
            let _ = writeln!(md, "| {m} | {} | {} |", mib(g), mib(c));
        }
    }
    md.push('\n');
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".into(), |v| format!("{v:.2}"))
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
        md.push_str(
            "| method | CPU₀ | CPU₁ | ΔC | GPU₀ | GPU₁ | ΔG | match | last check: hit/miss % / p95 |\n\
             |---|---:|---:|---:|---:|---:|---:|---|---|\n",
        );
        for e in &run.edit_rows {
            let last = e.checks.last().map_or("—".into(), |c| {
                format!("{:.4} / {:.2}", c.class_mismatch, c.depth_p95)
            });
            let _ = writeln!(
                md,
                "| {} | {:.2} | {:.2} | {} | {} | {} | {} | {} | {} |",
                e.method,
                e.steady_cpu_ms,
                e.first_frame_cpu_ms,
                fmt_delta(Some(e.steady_cpu_ms), Some(e.first_frame_cpu_ms)),
                fmt_opt(e.steady_gpu_ms),
                fmt_opt(e.first_frame_gpu_ms),
                fmt_delta(e.steady_gpu_ms, e.first_frame_gpu_ms),
                match_label(e),
                last
            );
        }
        md.push('\n');
    }
}

fn per_view_table(md: &mut String, run: &RunResults) {
    md.push_str("## Every cell\n\n");
    let _ = writeln!(md, "{}.\n", cell_text(&run.adapter.name));
    md.push_str(
        "| view | pitch | method | see-through % | covers-sky % | p50 | p95 | coherence % | GPU ms | CPU ms | picture |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in &run.rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {:.3} | [png]({}) |",
            cell_text(&r.view),
            r.pitch,
            r.method,
            r.see_through,
            r.covers_sky,
            r.depth_p50,
            r.depth_p95,
            r.coherence,
            r.gpu_ms_mean.map_or("—".into(), |v| format!("{v:.3}")),
            r.cpu_ms_mean,
            r.image
        );
    }
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
