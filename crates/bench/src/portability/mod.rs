//! The portability report (`portability.md` + `portability.json`): the same
//! protocol on several adapters, side by side. Written by
//! `strata compare --all-adapters` after its runs and by
//! `strata merge --portability` from results files of any machines.
//!
//! Runs are grouped by protocol ([`crate::merge::check_compatible`]): accuracy
//! is compared only inside a group, and the report says why each later group
//! stands apart from the first. Inside a group, every cell's accuracy fields
//! are spread over the adapters (max − min); a cell whose spread exceeds
//! merge's tolerance ([`PERCENT_TOLERANCE`], [`DEPTH_TOLERANCE`]) disagrees,
//! and disagreeing cells come first, each with a picture of the reference
//! and every adapter's image side by side. Timing rows stay apart per adapter
//! and per timing source (GPU timestamps vs CPU submit-and-wait).

use crate::grid;
use crate::merge::{DEPTH_TOLERANCE, PERCENT_TOLERANCE, fields_with_tolerance};
use crate::plan::file_part;
use crate::results::{AdapterInfo, Row, RunResults, TimingSource, slug};
use crate::stats;
use anyhow::{Context, bail};
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::path::{Component, Path, PathBuf};

/// Bumped when a field of `portability.json` changes meaning.
pub const PORTABILITY_FORMAT: u32 = 1;
/// Side-by-side pictures scale each image down to at most this width.
pub const SIDE_BY_SIDE_MAX_WIDTH: u32 = 640;
/// Folder (under the report's directory) of the side-by-side pictures.
pub const SIDE_BY_SIDE_DIR: &str = "disagreements";

/// `portability.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Portability {
    pub format_version: u32,
    pub tolerances: Tolerances,
    /// Every results file merged, in input order.
    pub runs: Vec<RunEntry>,
    /// Adapters the batch found but could not run at all (no results file).
    #[serde(default)]
    pub skipped: Vec<SkippedAdapter>,
    /// Runs grouped by protocol; accuracy is compared only inside a group.
    pub groups: Vec<ProtocolGroup>,
}

/// Beyond these spreads (max − min over adapters) a cell disagrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Percentage points (see-through, covers-sky, coherence).
    pub percent: f64,
    /// World units (depth p50, p95).
    pub depth: f64,
}

/// One merged results file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunEntry {
    /// Unique in the report: `name (backend)`, with ` #2`… for repeats.
    pub label: String,
    pub adapter: AdapterInfo,
    /// The results file, relative to the report's directory where possible.
    pub results: String,
    /// The run's own `grid.png`, when it sits beside the results file.
    pub grid: Option<String>,
    /// The protocol group's id (`A`, `B`, …).
    pub group: String,
    pub source_revision: String,
    pub complete: bool,
    pub cells: usize,
    pub expected_cells: usize,
    /// The timing sources its rows carry.
    pub timing_sources: Vec<TimingSource>,
}

/// An adapter the batch could not open or run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SkippedAdapter {
    pub adapter: String,
    pub backend: String,
    pub error: String,
}

/// What the runs of one group share.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProtocolSummary {
    pub protocol_version: u32,
    pub level: String,
    pub level_hash: String,
    pub width: u32,
    pub height: u32,
    pub far: f32,
    pub frames: u32,
    pub shadows: bool,
    pub edits: bool,
    pub mid_rule: String,
    pub methods: Vec<String>,
    pub views: Vec<String>,
}

/// Runs measured under one protocol.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProtocolGroup {
    pub id: String,
    pub protocol: ProtocolSummary,
    /// Run labels, in input order.
    pub adapters: Vec<String>,
    /// Why this group's runs were not compared with the first group's
    /// (merge's refusal); `None` for the first group.
    pub separate_because: Option<String>,
    /// Per adapter, method and pitch: the mean over the views at that pitch.
    pub pitch_means: Vec<PitchMean>,
    /// Per method and pitch: the spread of those means across adapters.
    pub pitch_spreads: Vec<PitchSpread>,
    /// Per method: the largest spread of each field over its cells.
    pub method_max_spreads: Vec<MethodSpread>,
    /// Every cell; those that disagree first.
    pub cells: Vec<CellSpread>,
    pub disagreeing_cells: usize,
    /// Methods refused or failed, per adapter (capability refusals included).
    pub failures: Vec<AdapterFailure>,
    /// The edit protocol's consistency per method across adapters.
    pub edits: Vec<EditAgreement>,
    /// Frame times, apart per adapter and timing source.
    pub timing: Vec<TimingRow>,
}

/// The five accuracy fields of a cell (or a mean, or a spread of them).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Accuracy {
    pub see_through: f64,
    pub covers_sky: f64,
    pub depth_p50: f64,
    pub depth_p95: f64,
    pub coherence: f64,
}

impl Accuracy {
    fn of(r: &Row) -> Self {
        Accuracy {
            see_through: r.see_through,
            covers_sky: r.covers_sky,
            depth_p50: r.depth_p50,
            depth_p95: r.depth_p95,
            coherence: r.coherence,
        }
    }

    /// The field named as in the results file (`see_through`, …).
    pub fn get(&self, field: &str) -> Option<f64> {
        Some(match field {
            "see_through" => self.see_through,
            "covers_sky" => self.covers_sky,
            "depth_p50" => self.depth_p50,
            "depth_p95" => self.depth_p95,
            "coherence" => self.coherence,
            _ => return None,
        })
    }

    /// Each field of the result is `f` of that field's values over `xs`;
    /// `None` when `f` gives none for some field.
    fn fieldwise(xs: &[Accuracy], f: impl Fn(&[f64]) -> Option<f64>) -> Option<Accuracy> {
        let field = |get: fn(&Accuracy) -> f64| f(&xs.iter().map(get).collect::<Vec<f64>>());
        Some(Accuracy {
            see_through: field(|a| a.see_through)?,
            covers_sky: field(|a| a.covers_sky)?,
            depth_p50: field(|a| a.depth_p50)?,
            depth_p95: field(|a| a.depth_p95)?,
            coherence: field(|a| a.coherence)?,
        })
    }

    /// Field-wise mean over `xs` (NaN where there are none).
    fn mean(xs: &[Accuracy]) -> Accuracy {
        let mean = |v: &[f64]| Some(stats::mean(v).unwrap_or(f64::NAN));
        Accuracy::fieldwise(xs, mean).expect("a mean for every field")
    }

    /// Field-wise max − min over `xs`; `None` for fewer than two.
    fn spread(xs: &[Accuracy]) -> Option<Accuracy> {
        if xs.len() < 2 {
            return None;
        }
        Accuracy::fieldwise(xs, |v| {
            // A NaN on some adapters only is an infinite spread; on all, none.
            Some(if v.iter().all(|x| x.is_nan()) {
                0.0
            } else if v.iter().any(|x| x.is_nan()) {
                f64::INFINITY
            } else {
                v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - v.iter().copied().fold(f64::INFINITY, f64::min)
            })
        })
    }

    /// Field-wise maximum over `xs`; `None` for none.
    fn max(xs: &[Accuracy]) -> Option<Accuracy> {
        Accuracy::fieldwise(xs, |v| v.iter().copied().reduce(f64::max))
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PitchMean {
    pub adapter: String,
    pub method: String,
    pub pitch: f32,
    /// Views averaged (cells present at this pitch).
    pub views: usize,
    pub mean: Accuracy,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PitchSpread {
    pub method: String,
    pub pitch: f32,
    pub spread: Accuracy,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodSpread {
    pub method: String,
    /// Field-wise maximum of the cells' spreads.
    pub max: Accuracy,
}

/// One adapter's value of a cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellValue {
    pub adapter: String,
    pub accuracy: Accuracy,
    /// The cell picture, relative to the report's directory; `None` when the
    /// file is not where the results file says.
    pub picture: Option<String>,
}

/// An adapter without a value for a cell, and why.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CellAbsence {
    pub adapter: String,
    /// The recorded failure or refusal; `None` when the run simply lacks the
    /// cell (interrupted), which counts as a disagreement.
    pub failure: Option<String>,
}

/// One (view, method) cell across the adapters of a group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellSpread {
    pub view: String,
    pub pitch: f32,
    pub method: String,
    pub values: Vec<CellValue>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub absent: Vec<CellAbsence>,
    /// Max − min of each field over `values`; `None` with fewer than two.
    pub spread: Option<Accuracy>,
    /// Fields whose spread exceeds the tolerance, and `cell` when some
    /// adapter lacks the cell without a recorded failure. Empty: agrees.
    pub disagrees: Vec<String>,
    /// The reference picture of the view, relative to the report's directory.
    pub reference_picture: Option<String>,
    /// The reference and every adapter's picture side by side (disagreeing
    /// cells only), relative to the report's directory.
    pub side_by_side: Option<String>,
}

impl CellSpread {
    /// How far beyond tolerance the worst field is (spread / tolerance).
    fn excess(&self) -> f64 {
        let Some(s) = &self.spread else {
            return 0.0;
        };
        fields_with_tolerance()
            .map(|((n, _), tol)| s.get(n).unwrap_or(0.0) / tol)
            .fold(0.0, f64::max)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AdapterFailure {
    pub adapter: String,
    /// A view name, `*` (every view: the method was refused or failed to
    /// build) or `edit`.
    pub view: String,
    pub method: String,
    pub error: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EditAgreement {
    pub method: String,
    /// Per adapter with an edit row: post-edit frames until consistent
    /// (`None`: not within 16).
    pub consistent_after_frames: Vec<(String, Option<u32>)>,
    pub agrees: bool,
}

/// Mean frame time of one adapter and method from one timing source, over
/// the views at one pitch (`pitch` None: over every view).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimingRow {
    pub adapter: String,
    pub source: TimingSource,
    pub method: String,
    pub pitch: Option<f32>,
    pub views: usize,
    pub mean_ms: f64,
}

/// A results file and where it was read from (its directory is where the
/// row pictures are).
#[derive(Clone, Debug)]
pub struct Input {
    pub path: PathBuf,
    pub run: RunResults,
}

/// Read results files for [`build`].
pub fn read_inputs(paths: &[PathBuf]) -> anyhow::Result<Vec<Input>> {
    paths
        .iter()
        .map(|p| {
            Ok(Input {
                path: p.clone(),
                run: crate::merge::read_run(p)?,
            })
        })
        .collect()
}

/// Group runs by protocol: each run joins the first group whose first run
/// it is compatible with. Returns, per group, the input indices and (for
/// later groups) why its first run was not compatible with the first group.
pub fn group_by_protocol(runs: &[&RunResults]) -> Vec<(Vec<usize>, Option<String>)> {
    let mut groups: Vec<(Vec<usize>, Option<String>)> = Vec::new();
    for (i, run) in runs.iter().enumerate() {
        let home = groups
            .iter_mut()
            .find(|(members, _)| crate::merge::check_compatible(runs[members[0]], run).is_ok());
        match home {
            Some((members, _)) => members.push(i),
            None => {
                let why = groups.first().and_then(|(members, _)| {
                    crate::merge::check_compatible(runs[members[0]], run)
                        .err()
                        .map(|e| format!("{e:#}"))
                });
                groups.push((vec![i], why));
            }
        }
    }
    groups
}

fn group_id(i: usize) -> String {
    let letters = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ";
    if i < letters.len() {
        (letters[i] as char).to_string()
    } else {
        format!("G{}", i + 1)
    }
}

/// Unique labels: `name (backend)`, repeats numbered.
fn labels(inputs: &[Input]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for input in inputs {
        let a = &input.run.adapter;
        let base = format!("{} ({})", a.name, a.backend);
        let mut label = base.clone();
        let mut n = 2;
        while out.contains(&label) {
            label = format!("{base} #{n}");
            n += 1;
        }
        out.push(label);
    }
    out
}

/// `path` relative to `base` when both resolve (`..` where needed), else
/// `path` as given.
pub fn relative_to(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| -> Option<PathBuf> {
        let p = if p.is_absolute() {
            p.to_path_buf()
        } else {
            std::env::current_dir().ok()?.join(p)
        };
        // Normalise lexically (the file may not exist yet).
        let mut out = PathBuf::new();
        for c in p.components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::CurDir => {}
                other => out.push(other),
            }
        }
        Some(out)
    };
    let (Some(p), Some(b)) = (abs(path), abs(base)) else {
        return path.display().to_string();
    };
    let pc: Vec<_> = p.components().collect();
    let bc: Vec<_> = b.components().collect();
    let common = pc.iter().zip(&bc).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..bc.len() {
        rel.push("..");
    }
    for c in &pc[common..] {
        rel.push(c);
    }
    // Markdown links want forward slashes.
    rel.to_string_lossy().replace('\\', "/")
}

/// Build the report from results files. `out` is the report's directory
/// (picture paths are made relative to it); nothing is written here.
pub fn build(inputs: &[Input], skipped: Vec<SkippedAdapter>, out: &Path) -> Portability {
    let labels = labels(inputs);
    let runs: Vec<&RunResults> = inputs.iter().map(|i| &i.run).collect();
    let grouped = group_by_protocol(&runs);
    let mut group_of = vec![String::new(); inputs.len()];
    for (g, (members, _)) in grouped.iter().enumerate() {
        for &i in members {
            group_of[i] = group_id(g);
        }
    }
    let dir_of = |i: usize| -> PathBuf {
        inputs[i]
            .path
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    };
    let entries = inputs
        .iter()
        .enumerate()
        .map(|(i, input)| {
            let run = &input.run;
            let mut sources: Vec<TimingSource> = Vec::new();
            for r in &run.rows {
                if !sources.contains(&r.timing_source) {
                    sources.push(r.timing_source);
                }
            }
            let grid = dir_of(i).join("grid.png");
            RunEntry {
                label: labels[i].clone(),
                adapter: run.adapter.clone(),
                results: relative_to(&input.path, out),
                grid: grid.is_file().then(|| relative_to(&grid, out)),
                group: group_of[i].clone(),
                source_revision: run.source_revision.clone(),
                complete: run.complete,
                cells: run.rows.len(),
                expected_cells: run.settings.views.len() * run.settings.methods.len(),
                timing_sources: sources,
            }
        })
        .collect();
    let groups = grouped
        .iter()
        .enumerate()
        .map(|(g, (members, why))| {
            let members: Vec<Member> = members
                .iter()
                .map(|&i| Member {
                    label: &labels[i],
                    run: &inputs[i].run,
                    dir: dir_of(i),
                })
                .collect();
            build_group(group_id(g), &members, why.clone(), out)
        })
        .collect();
    Portability {
        format_version: PORTABILITY_FORMAT,
        tolerances: Tolerances {
            percent: PERCENT_TOLERANCE,
            depth: DEPTH_TOLERANCE,
        },
        runs: entries,
        skipped,
        groups,
    }
}

struct Member<'a> {
    label: &'a str,
    run: &'a RunResults,
    /// The results file's directory.
    dir: PathBuf,
}

impl Member<'_> {
    /// A picture path from the results file, relative to the report's
    /// directory, when the file exists.
    fn picture(&self, rel: &str, out: &Path) -> Option<String> {
        if rel.is_empty() {
            return None;
        }
        let path = self.dir.join(rel);
        path.is_file().then(|| relative_to(&path, out))
    }

    fn failure_for(&self, view: &str, method: &str) -> Option<&crate::results::Failure> {
        self.run
            .failures
            .iter()
            .find(|f| f.method == method && (f.view == view || f.view == "*"))
    }
}

/// Compose the side-by-side picture of every disagreeing cell into
/// `<out>/disagreements/` and record its path. Cells whose pictures are
/// all missing get none.
pub fn write_side_by_side(report: &mut Portability, out: &Path) -> anyhow::Result<()> {
    let dir = out.join(SIDE_BY_SIDE_DIR);
    for group in &mut report.groups {
        for cell in group.cells.iter_mut().filter(|c| !c.disagrees.is_empty()) {
            let load = |rel: &Option<String>| -> Option<RgbaImage> {
                let rel = rel.as_ref()?;
                let img = image::open(out.join(rel)).ok()?.to_rgba8();
                Some(grid::thumbnail_to(&img, SIDE_BY_SIDE_MAX_WIDTH))
            };
            let mut columns = vec!["reference".to_string()];
            let mut pictures = vec![load(&cell.reference_picture)];
            for v in &cell.values {
                columns.push(v.adapter.clone());
                pictures.push(load(&v.picture));
            }
            for a in &cell.absent {
                columns.push(format!("{} (none)", a.adapter));
                pictures.push(None);
            }
            if pictures.iter().skip(1).all(Option::is_none) {
                continue;
            }
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            let name = format!(
                "{}-{}-{}.png",
                group.id.to_lowercase(),
                file_part(&cell.view),
                file_part(&cell.method)
            );
            let row = format!("{} {}", cell.view, cell.method);
            let img = grid::compose(&[row], &columns, &[pictures]);
            let path = dir.join(&name);
            img.save(&path)
                .with_context(|| format!("writing {}", path.display()))?;
            cell.side_by_side = Some(format!("{SIDE_BY_SIDE_DIR}/{name}"));
        }
    }
    Ok(())
}

/// Build and write `portability.json`, `portability.md` and the
/// side-by-side pictures into `out`. Returns the report and the paths of
/// the Markdown and JSON files.
pub fn write(
    inputs: &[Input],
    skipped: Vec<SkippedAdapter>,
    out: &Path,
) -> anyhow::Result<(Portability, PathBuf, PathBuf)> {
    if inputs.is_empty() && skipped.is_empty() {
        bail!("no runs to merge");
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut report = build(inputs, skipped, out);
    write_side_by_side(&mut report, out)?;
    let json_path = out.join("portability.json");
    let json = serde_json::to_string_pretty(&report).context("serialising portability.json")?;
    std::fs::write(&json_path, json).with_context(|| format!("writing {}", json_path.display()))?;
    let md_path = out.join("portability.md");
    std::fs::write(&md_path, render_markdown(&report))
        .with_context(|| format!("writing {}", md_path.display()))?;
    Ok((report, md_path, json_path))
}

/// `strata merge --portability`: read the inputs and write the report. An
/// input is a results file, or an earlier `portability.json` (a batch made
/// on another machine), which stands for its runs (their results files
/// found relative to it) and its skipped adapters.
pub fn merge_files(
    paths: &[PathBuf],
    out: &Path,
) -> anyhow::Result<(Portability, PathBuf, PathBuf)> {
    if paths.is_empty() {
        bail!("no results files to merge");
    }
    let mut inputs = Vec::new();
    let mut skipped = Vec::new();
    for path in paths {
        match read_batch(path)? {
            Some(batch) => {
                let dir = path.parent().unwrap_or(Path::new("."));
                for run in &batch.runs {
                    let results = dir.join(&run.results);
                    let read = crate::merge::read_run(&results)
                        .with_context(|| format!("a run of the batch {}", path.display()))?;
                    inputs.push(Input {
                        path: results,
                        run: read,
                    });
                }
                skipped.extend(batch.skipped);
            }
            None => inputs.push(Input {
                path: path.clone(),
                run: crate::merge::read_run(path)?,
            }),
        }
    }
    write(&inputs, skipped, out)
}

/// `Some` when `path` holds a portability report rather than a results file.
fn read_batch(path: &Path) -> anyhow::Result<Option<Portability>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let value: serde_json::Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        // Not JSON at all: let the results reader name the problem.
        Err(_) => return Ok(None),
    };
    if value.get("groups").is_none() || value.get("format_version").is_none() {
        return Ok(None);
    }
    let batch: Portability = serde_json::from_value(value)
        .with_context(|| format!("{} is not a strata portability report", path.display()))?;
    if batch.format_version != PORTABILITY_FORMAT {
        bail!(
            "{}: portability format {} (this strata reads {PORTABILITY_FORMAT})",
            path.display(),
            batch.format_version
        );
    }
    Ok(Some(batch))
}

/// The subfolder of an adapter's run in a batch: name and backend, so one
/// GPU's Vulkan and GL adapters get different folders.
pub fn adapter_dir_name(name: &str, backend: &str) -> String {
    slug(&format!("{name} {backend}"))
}

mod build;
mod markdown;
use build::build_group;
pub use markdown::render_markdown;

#[cfg(test)]
mod tests;
