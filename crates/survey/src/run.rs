//! Running a survey: each world is loaded (or generated), measured as
//! `strata info` measures it, and fitted at every quality. A world that
//! fails to load keeps its row, with the error, and the survey goes on.

use serde::Serialize;
use std::time::Instant;
use strata_level::generate::generate_with;
use strata_level::stats::LevelStats;
use strata_level::{Level, MidRule, io};
use strata_mesh::{
    CAUSES, FitOptions, LODS, MeshStats, fit_on_threads_with, tolerance_for_quality,
};

use crate::plan::{Plan, WorldSpec};

/// One fit of one world.
#[derive(Clone, Debug, Serialize)]
pub struct FitRow {
    pub quality: f64,
    pub max_error: f64,
    /// Finest-LOD planar triangles (the paper's "tris"): distinct planar
    /// footprints drawn, i.e. the floor's triangles plus, in the outline fit
    /// (whose slab has its own triangulation), the slab tops'.
    pub triangles: u64,
    /// Planar triangles per LOD (as `triangles`), finest first.
    pub lod_triangles: [u64; LODS],
    /// Everything the finest LOD draws (floor, slab top and ceiling, walls).
    pub emitted_triangles: u64,
    /// Full grid (2 per texel) over finest triangles.
    pub reduction: f64,
    /// Share of finest planar triangles (as `triangles`) that carry a slab
    /// (top and ceiling), percent: where the fit's budget went.
    pub slab_share: f64,
    /// Insertions: floor, slab interior, single/double boundary, chunk border.
    pub causes: [u64; CAUSES],
    pub gpu_bytes: u64,
    pub fit_seconds: f64,
}

/// One world: its statistics and its fits, or why it has none.
#[derive(Clone, Debug, Serialize)]
pub struct WorldRow {
    pub label: String,
    /// The directory, or the generator's knobs.
    pub source: String,
    /// Why the world has no figures (it failed to load), else `None`.
    pub error: Option<String>,
    pub texels: u64,
    /// Percent of texels in dual pairs.
    pub dual_percent: f64,
    /// `rough(floor)` and `rough(surface)` as `strata info` prints them.
    pub r_f: f64,
    pub r_s: f64,
    pub load_seconds: f64,
    pub fits: Vec<FitRow>,
}

impl WorldRow {
    /// The fit at `quality`, if the world has one.
    pub fn fit_at(&self, quality: f64) -> Option<&FitRow> {
        self.fits.iter().find(|f| f.quality == quality)
    }
}

/// A finished survey.
#[derive(Clone, Debug, Serialize)]
pub struct Survey {
    pub qualities: Vec<f64>,
    pub table_quality: f64,
    pub outline: bool,
    pub threads: usize,
    pub wall_seconds: f64,
    pub worlds: Vec<WorldRow>,
}

/// What the survey is doing, for a progress bar.
pub trait Progress {
    /// Starting `world` (its label).
    fn world(&self, label: &str);
    /// One more fit done.
    fn fit_done(&self);
}

impl Progress for () {
    fn world(&self, _: &str) {}
    fn fit_done(&self) {}
}

/// Run `plan` with fits on `threads` workers (0: one per core).
pub fn run(plan: &Plan, threads: usize, progress: &dyn Progress) -> Survey {
    let start = Instant::now();
    let mut used_threads = 0;
    let worlds = plan
        .worlds
        .iter()
        .map(|spec| {
            let label = spec.label();
            progress.world(&label);
            let t = Instant::now();
            let loaded = load(spec);
            let load_seconds = t.elapsed().as_secs_f64();
            let mut row = WorldRow {
                label,
                source: source(spec),
                error: None,
                texels: 0,
                dual_percent: 0.0,
                r_f: 0.0,
                r_s: 0.0,
                load_seconds,
                fits: Vec::new(),
            };
            let level = match loaded {
                Ok(level) => level,
                Err(e) => {
                    row.error = Some(e);
                    for _ in &plan.qualities {
                        progress.fit_done();
                    }
                    return row;
                }
            };
            let stats = LevelStats::compute(&level);
            row.texels = u64::from(level.width()) * u64::from(level.height());
            row.dual_percent = stats.dual_percent;
            row.r_f = stats.roughness_floor;
            row.r_s = stats.roughness_surface;
            for &q in &plan.qualities {
                match fit(&level, q, threads, plan.outline) {
                    Ok((fit, n)) => {
                        used_threads = n;
                        row.fits.push(fit);
                    }
                    Err(e) => {
                        row.error.get_or_insert(e);
                    }
                }
                progress.fit_done();
            }
            row
        })
        .collect();
    Survey {
        qualities: plan.qualities.clone(),
        table_quality: plan.table_quality,
        outline: plan.outline,
        threads: used_threads,
        wall_seconds: start.elapsed().as_secs_f64(),
        worlds,
    }
}

fn source(spec: &WorldSpec) -> String {
    match spec {
        WorldSpec::Generated { params, knobs } => format!(
            "generated seed {} {}x{} --dual-fraction {} --floor-roughness {}",
            params.seed,
            params.width,
            params.height,
            knobs.dual_fraction.unwrap_or(0.0),
            knobs.floor_roughness.unwrap_or(1.0)
        ),
        WorldSpec::Dir(dir) => dir.display().to_string(),
    }
}

/// The level of `spec`, or an error that names the world.
fn load(spec: &WorldSpec) -> Result<Level, String> {
    match spec {
        WorldSpec::Generated { params, knobs } => generate_with(params, knobs)
            .map(|w| w.level)
            .map_err(|e| format!("generating {}: {e}", spec.label())),
        WorldSpec::Dir(dir) => io::load_world(dir, MidRule::Original)
            .map(|w| w.level)
            .map_err(|e| format!("loading the world in {}: {e}", dir.display())),
    }
}

fn fit(level: &Level, q: f64, threads: usize, outline: bool) -> Result<(FitRow, usize), String> {
    let tol = tolerance_for_quality(q).ok_or_else(|| format!("quality {q} is outside [0, 1]"))?;
    let (mesh, timing) = fit_on_threads_with(level, tol, threads, FitOptions { outline })
        .map_err(|e| format!("worker threads: {e}"))?;
    let s = mesh.stats();
    let full = 2 * u64::from(level.width()) * u64::from(level.height());
    Ok((
        row_of(q, &s, full, timing.wall_seconds, outline),
        timing.threads,
    ))
}

fn row_of(quality: f64, s: &MeshStats, full: u64, fit_seconds: f64, outline: bool) -> FitRow {
    // The outline fit draws its slab tops on triangles of their own.
    let footprints =
        |l: &strata_mesh::level_mesh::LodTotals| l.planar + if outline { l.slab / 2 } else { 0 };
    let tris = footprints(&s.lods[0]);
    FitRow {
        quality,
        max_error: s.tolerance,
        triangles: tris,
        lod_triangles: s.lods.each_ref().map(footprints),
        emitted_triangles: s.lods[0].emitted,
        reduction: full as f64 / tris.max(1) as f64,
        // Each planar triangle with a slab emits two slab triangles.
        slab_share: 100.0 * (s.lods[0].slab / 2) as f64 / tris.max(1) as f64,
        causes: s.causes,
        gpu_bytes: s.gpu_bytes,
        fit_seconds,
    }
}
