//! `strata tune`: the paper's tuning protocol on any level. Each method's
//! knob is swept over a horizon fixture (three 0° views) at 400x260, plus a
//! 1280x800 pass for the mesh as in the paper; the combined error is
//! see-through + covers-sky + coherence (percent of pixels, mean over the
//! views), the cost the mean frame time, and the one-point rule
//! ([`rule::choose`]) picks each method's setting. Outputs: `tuning.md`,
//! `tuning.json`, a cost-versus-error plot per method and `settings.json`
//! for `strata compare --settings`.

pub mod output;
pub mod plot;
pub mod rule;

use crate::methods::{describe, settings_for};
use crate::plan::MethodChoice;
use crate::run::warm_up;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::time::Instant;
use strata_camera::Camera;
use strata_level::{ViewSpec, World};
use strata_reference::{Reference, ReferenceCache, Tracer};
use strata_render::methods::{METHODS, Sweep as MethodSweep};
use strata_render::{Gpu, MethodEntry, Renderer, TerrainColors};

/// What to sweep and how.
#[derive(Clone, Debug)]
pub struct TuneOptions {
    pub out: PathBuf,
    /// The fixture: three 0° views unless `--views`.
    pub views: Vec<ViewSpec>,
    /// Sweep size (400x260; 200x130 with `--quick`).
    pub size: (u32, u32),
    /// The mesh's extra pass at the paper's size (1280x800); none with `--quick`.
    pub mesh_size: Option<(u32, u32)>,
    /// Fewer points per sweep.
    pub quick: bool,
    /// Timed frames per point and view.
    pub frames: u32,
    pub min_warmup: u32,
    /// Ms of untimed frames back to back before each point's timed frames
    /// at each view (0: off), as `compare --hold-busy`: a mostly idle GPU
    /// lowers its clock, which would charge later points more.
    pub hold_busy_ms: u32,
    pub shadows: bool,
    pub cache_dir: PathBuf,
    /// Only these methods (default: every swept method).
    pub methods: Option<Vec<String>>,
}

/// One method's sweep: its knob's settings in `methods::settings_for` syntax.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    pub method: &'static MethodEntry,
    /// What the knob is, for the table.
    pub knob: &'static str,
    pub settings: Vec<Option<String>>,
    /// The paper's (= the built-in default) setting, in the same syntax.
    pub paper: Option<&'static str>,
    pub size: (u32, u32),
}

/// The methods `strata tune` sweeps (their entries' [`MethodSweep`]), in
/// the report's order.
fn tuned() -> Vec<&'static MethodEntry> {
    let mut tuned: Vec<&'static MethodEntry> =
        METHODS.iter().filter(|m| m.tune.is_some()).collect();
    tuned.sort_by_key(|m| m.tune.map(|t| t.order));
    tuned
}

/// The sweeps of the protocol (issue 16's ranges, each method's entry's
/// [`MethodSweep`]), fewer points with `quick` (always the ends and the
/// paper's setting, so ours can be set beside it).
pub fn sweeps(quick: bool, size: (u32, u32), mesh_size: Option<(u32, u32)>) -> Vec<Sweep> {
    let sweep = |method: &'static MethodEntry, t: &MethodSweep, size| Sweep {
        method,
        knob: t.knob,
        settings: if t.full.is_empty() {
            vec![None]
        } else {
            let list = if quick { t.quick } else { t.full };
            list.iter().map(|s| Some((*s).to_string())).collect()
        },
        paper: method.knobs.default,
        size,
    };
    let tuned = tuned();
    let mut out: Vec<Sweep> = tuned
        .iter()
        .filter_map(|m| m.tune.map(|t| sweep(m, t, size)))
        .collect();
    if let Some(big) = mesh_size {
        out.extend(
            tuned
                .iter()
                .filter_map(|m| m.tune.filter(|t| t.at_paper_size).map(|t| sweep(m, t, big))),
        );
    }
    out
}

/// One measured setting.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TunePoint {
    /// `None` for a method without a knob.
    pub setting: Option<String>,
    /// The effective knob (`ray steps=64`).
    pub label: String,
    pub see_through: f64,
    pub covers_sky: f64,
    pub coherence: f64,
    /// see-through + covers-sky + coherence, percent of pixels.
    pub combined: f64,
    /// Mean frame ms over the views (GPU timestamps, else CPU submit-and-wait).
    pub cost_ms: f64,
    /// Why the point could not be measured (then cost and error are NaN).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// One method's sweep, measured, with the rule's choice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodTuning {
    pub method: String,
    pub knob: String,
    pub size: [u32; 2],
    pub points: Vec<TunePoint>,
    /// The rule's choice and the lowest error (indices into `points`).
    pub chosen: Option<usize>,
    pub best: Option<usize>,
    pub paper_setting: Option<String>,
}

impl MethodTuning {
    /// The chosen point's setting.
    pub fn chosen_setting(&self) -> Option<&str> {
        self.chosen.and_then(|i| self.points[i].setting.as_deref())
    }
}

/// Everything `strata tune` measured: `tuning.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tuning {
    pub level: String,
    pub level_hash: String,
    pub adapter: String,
    pub backend: String,
    /// `gpu-timestamps` or `cpu-submit-and-wait`.
    pub timing_source: String,
    pub views: Vec<ViewSpec>,
    pub quick: bool,
    pub frames: u32,
    pub shadows: bool,
    pub tolerance_points: f64,
    pub methods: Vec<MethodTuning>,
    pub seconds: f64,
}

/// One sweep size's cameras and CPU references, one per view.
type Fixture = ((u32, u32), Vec<Camera>, Vec<Reference>);

/// The horizon fixture: the level's first three 0° views.
pub fn horizon_fixture(world: &World) -> Vec<ViewSpec> {
    world
        .views
        .iter()
        .filter(|v| v.pitch == 0.0)
        .take(3)
        .cloned()
        .collect()
}

/// Run every sweep on `gpu`.
pub fn run(world: &World, gpu: &Gpu, opts: &TuneOptions) -> anyhow::Result<Tuning> {
    let start = Instant::now();
    if opts.views.is_empty() {
        anyhow::bail!("tune: no views (the level has no 0° views; give --views FILE)");
    }
    let mut sweeps = sweeps(opts.quick, opts.size, opts.mesh_size);
    if let Some(only) = &opts.methods {
        for m in only {
            if !sweeps.iter().any(|s| s.method.name == m) {
                let swept: Vec<&str> = tuned().iter().map(|m| m.name).collect();
                anyhow::bail!(
                    "tune: method `{m}` has no sweep; swept: {}",
                    swept.join(", ")
                );
            }
        }
        sweeps.retain(|s| only.iter().any(|m| m == s.method.name));
    }
    // Check every setting before GPU work.
    for s in &sweeps {
        for setting in &s.settings {
            settings_for(&choice(s.method, setting), opts.shadows)?;
        }
    }
    let colors = TerrainColors::from_world(world);
    let level = &world.level;
    let hash = level.content_hash();
    let cache = ReferenceCache::new(&opts.cache_dir);
    let mut tracer: Option<Tracer> = None;
    // Cameras and references per size.
    let mut fixtures: Vec<Fixture> = Vec::new();
    for size in sweeps.iter().map(|s| s.size) {
        if fixtures.iter().any(|f| f.0 == size) {
            continue;
        }
        let mut cams = Vec::new();
        let mut refs = Vec::new();
        for v in &opts.views {
            let cam = Camera::from_view(level, v, size.0, size.1)
                .with_context(|| format!("view `{}`", v.name))?;
            let r = match cache.get(&hash, &cam) {
                Some(r) => r,
                None => {
                    let t = tracer.get_or_insert_with(|| Tracer::new(level));
                    cache
                        .get_or_compute_traced(t, &hash, &cam)
                        .with_context(|| format!("reference of view `{}`", v.name))?
                        .0
                }
            };
            cams.push(cam);
            refs.push(r);
        }
        fixtures.push((size, cams, refs));
    }
    drop(tracer);
    let total: usize = sweeps.iter().map(|s| s.settings.len()).sum();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} points  {msg}  [{elapsed_precise}, {eta_precise} left]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let timestamps = gpu.report.timestamps;
    let mut methods = Vec::new();
    for s in &sweeps {
        let (_, cams, refs) = fixtures
            .iter()
            .find(|f| f.0 == s.size)
            .expect("fixture per size");
        let mut points = Vec::new();
        for setting in &s.settings {
            let c = choice(s.method, setting);
            bar.set_message(format!("{} @{}x{}", c.label(), s.size.0, s.size.1));
            let settings = settings_for(&c, opts.shadows)?;
            let label = describe(s.method, &settings);
            let measured = (|| -> anyhow::Result<(f64, f64, f64, f64)> {
                let mut r =
                    Renderer::new(gpu, level, &colors, s.method, &settings, s.size.0, s.size.1)?;
                let (mut see, mut sky, mut coh, mut cost) = (0.0, 0.0, 0.0, 0.0);
                for (v, (cam, reference)) in cams.iter().zip(refs).enumerate() {
                    // The first view may wait out an incremental build.
                    let cap = if v == 0 { 64 } else { opts.min_warmup };
                    warm_up(&mut r, cam, opts.min_warmup, cap, timestamps)?;
                    if opts.hold_busy_ms > 0 {
                        // The first view follows the renderer's setup, when
                        // the GPU idled down (see `compare`'s first view).
                        let scale = if v == 0 { 4 } else { 1 };
                        r.hold_busy(
                            cam,
                            std::time::Duration::from_millis(u64::from(opts.hold_busy_ms) * scale),
                        )?;
                    }
                    let mut ms = 0.0;
                    for _ in 0..opts.frames {
                        let t = r.render_frame(cam)?;
                        ms += t.gpu_ms.unwrap_or(t.cpu_ms);
                    }
                    let depth = r.read_depth()?;
                    let distance = strata_reference::distance_from_depth(cam, &depth);
                    let m = strata_reference::metrics::try_compare(reference, &distance)?;
                    see += m.see_through;
                    sky += m.covers_sky;
                    coh += m.coherence;
                    cost += ms / f64::from(opts.frames.max(1));
                }
                let n = cams.len() as f64;
                Ok((see / n, sky / n, coh / n, cost / n))
            })();
            points.push(match measured {
                Ok((see, sky, coh, cost)) => TunePoint {
                    setting: setting.clone(),
                    label,
                    see_through: see,
                    covers_sky: sky,
                    coherence: coh,
                    combined: see + sky + coh,
                    cost_ms: cost,
                    error: None,
                },
                Err(e) => {
                    bar.println(format!("{}: {e:#}", c.label()));
                    TunePoint {
                        setting: setting.clone(),
                        label,
                        see_through: f64::NAN,
                        covers_sky: f64::NAN,
                        coherence: f64::NAN,
                        combined: f64::NAN,
                        cost_ms: f64::NAN,
                        error: Some(format!("{e:#}")),
                    }
                }
            });
            bar.inc(1);
        }
        let pairs: Vec<(f64, f64)> = points.iter().map(|p| (p.cost_ms, p.combined)).collect();
        methods.push(MethodTuning {
            method: s.method.name.to_string(),
            knob: s.knob.to_string(),
            size: [s.size.0, s.size.1],
            chosen: rule::choose(&pairs, rule::TOLERANCE_POINTS),
            best: rule::best(&pairs),
            points,
            paper_setting: s.paper.map(str::to_string),
        });
    }
    bar.finish_and_clear();
    Ok(Tuning {
        level: world.name.clone(),
        level_hash: hash,
        adapter: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        timing_source: if timestamps {
            "gpu-timestamps".into()
        } else {
            "cpu-submit-and-wait".into()
        },
        views: opts.views.clone(),
        quick: opts.quick,
        frames: opts.frames,
        shadows: opts.shadows,
        tolerance_points: rule::TOLERANCE_POINTS,
        methods,
        seconds: start.elapsed().as_secs_f64(),
    })
}

fn choice(method: &'static MethodEntry, setting: &Option<String>) -> MethodChoice {
    MethodChoice {
        method,
        setting: setting.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sweep_holds_the_papers_setting_and_parses() {
        for quick in [false, true] {
            for s in sweeps(quick, (400, 260), Some((1280, 800))) {
                if let Some(p) = s.paper {
                    assert!(
                        s.settings.iter().any(|x| x.as_deref() == Some(p)),
                        "{} (quick {quick}) lacks the paper's {p}",
                        s.method.name
                    );
                }
                for setting in &s.settings {
                    settings_for(&choice(s.method, setting), true).unwrap();
                }
            }
        }
        // The mesh's 1280x800 pass is there without --quick only.
        let full = sweeps(false, (400, 260), Some((1280, 800)));
        assert!(
            full.iter()
                .any(|s| s.method.name == "mesh" && s.size == (1280, 800))
        );
    }
}
