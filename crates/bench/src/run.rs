//! `strata compare`: check every input, then measure every (view, method)
//! cell and the edit protocol. One renderer per method serves all views (its
//! setup is paid once and recorded on each of its rows); each view gets its
//! own warm-up before the timed frames.

use crate::edits;
use crate::methods::{describe, settings_for};
use crate::plan::{MethodChoice, check_view_names, file_part, prepare_out_dir, source_revision};
use crate::results::*;
use crate::session::{GridMode, Session, color_image};
use crate::stats::summarize;
use crate::video;
mod records;
mod references;

pub use crate::warm::{INCREMENTAL_BUDGET_TEXELS, WarmUp, build_frames, ms, warm_up};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
pub(crate) use records::adapter_info;
use records::save_edit_pictures;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use strata_camera::Camera;
use strata_level::{EditSite, ViewSpec, World};
use strata_reference::{ColorImage, Reference};
use strata_render::paged::{LevelPages, PAGED_METHODS, PageSource, PagedOptions};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

/// Most frames a paged cell draws at its view waiting for every page it
/// reads, before its warm-up and timed frames.
pub(crate) const CONVERGE_FRAMES: u32 = 600;

/// `--temporal`: the default path played in this many seconds ...
pub const TEMPORAL_SECONDS: f32 = 2.0;
/// ... at this many frames per second (21 frames; the crater dug midway).
pub const TEMPORAL_FPS: u32 = 10;

/// Whether to run the edit protocol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EditMode {
    /// Run it when the level has an edit site (the default run).
    Auto,
    /// `--edits`: the level must have one.
    Required,
    /// `--no-edits`.
    Off,
}

/// Most frames a view after the first adds to its warm-up while the method
/// still reports build passes (with timestamps only).
pub const VIEW_BUILD_FRAMES: u32 = 64;

#[derive(Clone, Debug)]
pub struct Options {
    pub out: PathBuf,
    pub methods: Vec<MethodChoice>,
    /// The views to render (the level's own unless `--views`).
    pub views: Vec<ViewSpec>,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    /// Pre-timing frames at every view (the first view adds the build budget).
    pub min_warmup: u32,
    /// Before each cell's warm-up, keep the GPU busy with the cell's frames
    /// back to back for this many ms (0: off), so every cell is timed at the
    /// clock a busy GPU runs at ([`Renderer::hold_busy`]).
    pub hold_busy_ms: u32,
    pub shadows: bool,
    pub edits: EditMode,
    /// Fly a short path with every method and measure flicker (`--temporal`).
    pub temporal: bool,
    pub cache_dir: PathBuf,
    /// `--resume`: `out` holds an interrupted run of this comparison whose
    /// finished cells are kept ([`crate::resume`]).
    pub resume: bool,
    /// What `grid.png` shows (`--grid`).
    pub grid: GridMode,
}

/// A checked comparison, ready to run: nothing here touches the GPU.
pub struct Plan {
    world: World,
    colors: TerrainColors,
    opts: Options,
    cameras: Vec<Camera>,
    settings: Vec<MethodSettings>,
    edit: Option<(EditSite, Camera)>,
    edit_skipped: Option<String>,
    warmup_first: u32,
    /// `--gpu-budget`: the paged methods draw through pages of the world
    /// ([`Plan::with_paging`]).
    paging: Option<(PagedOptions, Arc<dyn PageSource>)>,
    /// `--gameplay`: the sustained edit workload ([`Plan::with_gameplay`]).
    gameplay: Option<crate::gameplay::GameplaySpec>,
}

impl Plan {
    /// Validate everything a run needs: output directory, views, cameras,
    /// method settings, edit site. Errors name the bad input.
    pub fn new(world: World, opts: Options) -> anyhow::Result<Plan> {
        prepare_out_dir(&opts.out)?;
        Self::without_output(world, opts)
    }

    /// [`Plan::new`] for a runner that writes no files (the browser page's,
    /// which offers the results file for download): `opts.out` and
    /// `opts.cache_dir` are not touched.
    pub fn without_output(world: World, opts: Options) -> anyhow::Result<Plan> {
        check_view_names(&opts.views)?;
        if opts.frames == 0 {
            anyhow::bail!("--frames must be at least 1");
        }
        let cameras = opts
            .views
            .iter()
            .map(|v| {
                Camera::from_view(&world.level, v, opts.width, opts.height)
                    .with_context(|| format!("view `{}`", v.name))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let settings = opts
            .methods
            .iter()
            .map(|m| settings_for(m, opts.shadows))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let (edit, edit_skipped) = match (&world.edit, opts.edits) {
            (_, EditMode::Off) => (None, Some("--no-edits".to_string())),
            (None, EditMode::Required) => anyhow::bail!(
                "--edits: level `{}` has no edit site (edit.txt)",
                world.name
            ),
            (None, EditMode::Auto) => (
                None,
                Some(format!("level `{}` has no edit site", world.name)),
            ),
            (Some(site), _) => {
                let cam = Camera::from_view(&world.level, &site.camera, opts.width, opts.height)
                    .context("the edit camera")?;
                (Some((site.clone(), cam)), None)
            }
        };
        let warmup_first = opts.min_warmup.saturating_add(build_frames(&world.level));
        let colors = TerrainColors::from_world(&world);
        Ok(Plan {
            world,
            colors,
            opts,
            cameras,
            settings,
            edit,
            edit_skipped,
            warmup_first,
            paging: None,
            gameplay: None,
        })
    }

    /// Draw the paged methods (`strata_render::paged::PAGED_METHODS`)
    /// through pages of the world within `options.gpu_budget`: each view
    /// converges (nothing pending) before it is timed and compared, and its
    /// row carries the paging numbers. The other methods keep the
    /// whole-world path. `None`: every method draws the world whole.
    pub fn with_paging(mut self, options: Option<PagedOptions>) -> anyhow::Result<Self> {
        self.paging = match options {
            Some(o) => {
                let level = Arc::new(self.world.level.clone());
                Some((o, Arc::new(LevelPages::new(level)?) as Arc<dyn PageSource>))
            }
            None => None,
        };
        Ok(self)
    }

    /// Also run the sustained edit workload ([`crate::gameplay`]) with
    /// every method the adapter runs, after the edit protocol. Checked
    /// here: a spec that makes no workload, or a world whose camera path
    /// does not resolve, is an error before any GPU work.
    pub fn with_gameplay(
        mut self,
        spec: Option<crate::gameplay::GameplaySpec>,
    ) -> anyhow::Result<Self> {
        if let Some(spec) = spec {
            crate::gameplay::Workload::new(&self.world, spec, self.opts.width, self.opts.height)?;
        }
        self.gameplay = spec;
        Ok(self)
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn options(&self) -> &Options {
        &self.opts
    }

    /// Each view's camera, in view order.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// Method `m`'s settings (the order of `options().methods`).
    pub fn method_settings(&self, m: usize) -> &MethodSettings {
        &self.settings[m]
    }

    pub fn colors(&self) -> &TerrainColors {
        &self.colors
    }

    /// Pre-timing frames at view `v`: the first view adds enough for a
    /// whole-level incremental build.
    pub fn warmup_frames(&self, v: usize) -> u32 {
        if v == 0 {
            self.warmup_first
        } else {
            self.opts.min_warmup
        }
    }

    /// The results file before any cell: protocol, level, adapter, settings.
    pub fn results_header(&self, gpu: &Gpu) -> RunResults {
        let level = &self.world.level;
        RunResults {
            protocol_version: PROTOCOL_VERSION,
            level: LevelInfo {
                name: self.world.name.clone(),
                hash: level.content_hash(),
                width: level.width(),
                height: level.height(),
            },
            adapter: adapter_info(gpu),
            settings: Settings {
                width: self.opts.width,
                height: self.opts.height,
                far: self
                    .cameras
                    .first()
                    .map_or(strata_camera::DEFAULT_FAR, |c| c.far),
                frames: self.opts.frames,
                shadows: self.opts.shadows,
                methods: self.opts.methods.iter().map(MethodChoice::label).collect(),
                method_settings: self
                    .opts
                    .methods
                    .iter()
                    .zip(&self.settings)
                    .map(|(m, s)| describe(m.method, s))
                    .collect(),
                views: self.opts.views.clone(),
                warmup_first_view: self.warmup_first,
                warmup_frames: self.opts.min_warmup,
                hold_busy_ms: self.opts.hold_busy_ms,
                edits: self.edit.is_some(),
                mid_rule: format!("{:?}", level.mid_rule).to_lowercase(),
            },
            source_revision: source_revision(),
            complete: false,
            rows: Vec::new(),
            edit_rows: Vec::new(),
            failures: Vec::new(),
            edit_skipped: self.edit_skipped.clone(),
            reference_images: Vec::new(),
            temporal: Vec::new(),
            edit_images: Vec::new(),
            gameplay: None,
        }
    }

    /// Run the protocol on `gpu`, writing into the output directory as it goes.
    /// Returns the results file and the report.
    pub fn run(self, gpu: &Gpu) -> anyhow::Result<(PathBuf, PathBuf)> {
        self.run_until(gpu, None)
    }

    /// [`Plan::run`], stopped with an error once `stop_after_cells` view x
    /// method cells have been measured in this call, as an interruption
    /// would stop it (for testing `--resume`).
    pub fn run_until(
        self,
        gpu: &Gpu,
        stop_after_cells: Option<usize>,
    ) -> anyhow::Result<(PathBuf, PathBuf)> {
        let mut header = self.results_header(gpu);
        if self.opts.resume {
            let there = crate::resume::load(&self.opts.out, &header)?;
            crate::resume::carry_over(there, &mut header);
        }
        let mut session = Session::new(&self.opts.out, header);
        session.restore_thumbnails();
        session.grid = self.opts.grid;
        let json = session.save_json()?;
        let references = self.references(&mut session)?;
        let colors = self.color_references(&mut session)?;

        // A method the adapter cannot run is refused here, before any GPU
        // work, with the missing capability named: one failure for every view
        // and no edit row.
        let refused: Vec<Option<String>> = self
            .opts
            .methods
            .iter()
            .map(|m| {
                strata_render::methods::check_support(m.method, &gpu.caps)
                    .err()
                    .map(|e| format!("refused: {e:#}"))
            })
            .collect();
        let n_methods = refused.iter().filter(|r| r.is_none()).count();
        let total = self.cameras.len() * n_methods
            + if self.edit.is_some() { n_methods } else { 0 }
            + if self.gameplay.is_some() {
                n_methods
            } else {
                0
            };
        let kept = session.results.rows.len() + session.results.edit_rows.len();
        let bar = ProgressBar::new(total.saturating_sub(kept) as u64);
        let mut count = CellCount {
            measured: 0,
            stop_after: stop_after_cells,
        };
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:30} {pos}/{len} cells  {msg}  [{elapsed_precise}, {eta_precise} left]",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        for (m, choice) in self.opts.methods.iter().enumerate() {
            if let Some(why) = &refused[m] {
                bar.println(why.clone());
                session.results.failures.push(Failure {
                    view: "*".into(),
                    method: choice.label(),
                    error: why.clone(),
                });
                session.save_json()?;
                continue;
            }
            let column =
                self.method_column(gpu, &mut session, &references, &colors, m, &bar, &mut count);
            if let Err(e) = column {
                if e.is::<Stopped>() {
                    return Err(e);
                }
                bar.println(format!("{}: {e:#}", choice.label()));
                session.results.failures.push(Failure {
                    view: "*".into(),
                    method: choice.label(),
                    error: format!("{e:#}"),
                });
                session.save_json()?;
            }
            session.save_report()?;
        }
        if let Some((site, camera)) = &self.edit {
            let mut edited = self.world.level.clone();
            let rects = strata_level::edit::crater(&mut edited, site);
            let runnable = self
                .opts
                .methods
                .iter()
                .zip(&self.settings)
                .zip(&refused)
                .filter(|(_, why)| why.is_none())
                .map(|(pair, _)| pair);
            for (choice, settings) in runnable {
                let label = choice.label();
                if session.results.edit_rows.iter().any(|r| r.method == label) {
                    continue;
                }
                bar.set_message(format!("edit / {}", choice.label()));
                let input = edits::EditInput {
                    gpu,
                    original: &self.world.level,
                    edited: &edited,
                    rects: &rects,
                    colors: &self.colors,
                    camera,
                    warmup_cap: self.warmup_first,
                    hold_busy_ms: self.opts.hold_busy_ms,
                    timestamps: gpu.report.timestamps,
                    steady_frames: self.opts.frames.min(10),
                };
                match edits::edit_row(&input, choice.name(), settings) {
                    Ok((mut row, pictures)) => {
                        row.method = choice.label();
                        session.results.edit_rows.push(row);
                        if let Err(e) =
                            save_edit_pictures(&mut session, camera, &choice.label(), pictures)
                        {
                            bar.println(format!("edit / {}: pictures: {e:#}", choice.label()));
                        }
                    }
                    Err(e) => {
                        bar.println(format!("edit / {}: {e:#}", choice.label()));
                        session.results.failures.push(Failure {
                            view: "edit".into(),
                            method: choice.label(),
                            error: format!("{e:#}"),
                        });
                    }
                }
                session.save_json()?;
                bar.inc(1);
            }
        }
        if let Some(spec) = self.gameplay {
            self.gameplay(gpu, &mut session, &refused, spec, &bar)?;
        }
        // A resumed run keeps the temporal rows of one that got that far.
        if self.opts.temporal && session.results.temporal.is_empty() {
            self.temporal(gpu, &mut session, &refused, &bar)?;
        }
        bar.finish_and_clear();
        session.results.complete = true;
        session.save_json()?;
        let report = session.save_report()?;
        Ok((json, report))
    }

    /// `--gameplay`: every runnable method through the sustained edit
    /// workload; a method that fails is a failure row and the rest go on.
    fn gameplay(
        &self,
        gpu: &Gpu,
        session: &mut Session,
        refused: &[Option<String>],
        spec: crate::gameplay::GameplaySpec,
        bar: &ProgressBar,
    ) -> anyhow::Result<()> {
        use crate::gameplay::{GameplayInput, Workload, follow_collider};
        use crate::results::gameplay::{ColliderFollow, GameplayResults, Spread};
        let workload = Workload::new(&self.world, spec, self.opts.width, self.opts.height)?;
        // A resumed run keeps the rows of the same workload only.
        let same = |g: &GameplayResults| {
            (g.edits_per_frame, g.frames, g.check_every, g.seed)
                == (
                    spec.edits_per_frame,
                    spec.frames,
                    spec.check_every,
                    spec.seed,
                )
        };
        if !session.results.gameplay.as_ref().is_some_and(same) {
            bar.set_message("gameplay: level edits and collider");
            let cpu = follow_collider(&self.world, &workload);
            session.results.gameplay = Some(GameplayResults {
                edits_per_frame: spec.edits_per_frame,
                frames: spec.frames,
                check_every: spec.check_every,
                seed: spec.seed,
                edits_total: cpu.edits,
                dirty_texels_per_frame: cpu.dirty_texels as f64 / f64::from(spec.frames),
                level_edit_ms: Spread::of(&cpu.level_edit_ms).context("no frames")?,
                collider: cpu.collider.and_then(|(refit, consistent)| {
                    Some(ColliderFollow {
                        refit_ms: Spread::of(&refit)?,
                        consistent,
                    })
                }),
                rows: Vec::new(),
            });
            session.save_json()?;
        }
        let input = GameplayInput {
            world: &self.world,
            fresh: edits::FreshBuild {
                gpu,
                colors: &self.colors,
                camera: &self.cameras[0],
                warmup_cap: self.warmup_first,
                hold_busy_ms: self.opts.hold_busy_ms,
                timestamps: gpu.report.timestamps,
            },
            width: self.opts.width,
            height: self.opts.height,
        };
        for (m, choice) in self.opts.methods.iter().enumerate() {
            let label = choice.label();
            let done = session
                .results
                .gameplay
                .as_ref()
                .is_some_and(|g| g.rows.iter().any(|r| r.method == label));
            if refused[m].is_some() || done {
                continue;
            }
            bar.set_message(format!("gameplay / {label}"));
            match crate::gameplay::method_row(
                &input,
                &workload,
                &label,
                choice.name(),
                &self.settings[m],
            ) {
                Ok(row) => {
                    if let Some(g) = session.results.gameplay.as_mut() {
                        g.rows.push(row);
                    }
                }
                Err(e) => {
                    bar.println(format!("gameplay / {label}: {e:#}"));
                    session.results.failures.push(Failure {
                        view: "gameplay".into(),
                        method: label,
                        error: format!("{e:#}"),
                    });
                }
            }
            session.save_json()?;
            bar.inc(1);
        }
        Ok(())
    }

    /// `--temporal`: every runnable method along the video's default path,
    /// played in [`TEMPORAL_SECONDS`] at [`TEMPORAL_FPS`] at the run's size.
    fn temporal(
        &self,
        gpu: &Gpu,
        session: &mut Session,
        refused: &[Option<String>],
        bar: &ProgressBar,
    ) -> anyhow::Result<()> {
        let methods: Vec<MethodChoice> = self
            .opts
            .methods
            .iter()
            .zip(refused)
            .filter(|(_, why)| why.is_none())
            .map(|(m, _)| m.clone())
            .collect();
        let path = video::path::default_path(&self.world).retimed(TEMPORAL_SECONDS);
        let opts = video::VideoOptions {
            methods,
            tile: (self.opts.width, self.opts.height),
            frame: None,
            fps: TEMPORAL_FPS,
            shadows: self.opts.shadows,
            temporal: true,
            overlap: None,
            paging: None,
        };
        let (pos, len) = (bar.position(), bar.length());
        let recording = video::record(gpu, &self.world, &path, &opts, None, bar);
        bar.set_length(len.unwrap_or(0));
        bar.set_position(pos);
        match recording {
            Ok(r) => {
                let dug = r.dig_frame.is_some();
                for m in r.methods {
                    match (m.error, m.flicker) {
                        (None, Some(f)) => session.results.temporal.push(TemporalRow {
                            method: m.method,
                            flicker_mean: f.mean_percent,
                            flicker_max: f.max_percent,
                            frames: r.frames,
                            fps: r.fps,
                            dug,
                            frame_ms_mean: m.frame_ms_mean,
                        }),
                        (error, _) => session.results.failures.push(Failure {
                            view: "temporal".into(),
                            method: m.method,
                            error: error.unwrap_or_else(|| "no flicker measured".into()),
                        }),
                    }
                }
            }
            Err(e) => {
                bar.println(format!("temporal: {e:#}"));
                session.results.failures.push(Failure {
                    view: "temporal".into(),
                    method: "*".into(),
                    error: format!("{e:#}"),
                });
            }
        }
        session.save_json()?;
        Ok(())
    }

    /// Every view of method `m`, one renderer.
    #[allow(clippy::too_many_arguments)]
    fn method_column(
        &self,
        gpu: &Gpu,
        session: &mut Session,
        references: &[Reference],
        colors: &[Option<ColorImage>],
        m: usize,
        bar: &ProgressBar,
        count: &mut CellCount,
    ) -> anyhow::Result<()> {
        let choice = &self.opts.methods[m];
        let label = choice.label();
        // The views a resumed run has not measured yet.
        let todo: Vec<usize> = (0..self.cameras.len())
            .filter(|&v| {
                !crate::resume::has_row(&session.results, &self.opts.views[v].name, &label)
            })
            .collect();
        if todo.is_empty() {
            return Ok(());
        }
        bar.set_message(format!("{label}: setup"));
        let start = Instant::now();
        let paged = self
            .paging
            .as_ref()
            .filter(|_| PAGED_METHODS.contains(&choice.method.name));
        let built = match paged {
            Some((options, source)) => Renderer::new_paged(
                gpu,
                source.clone(),
                &self.colors,
                choice.method,
                &self.settings[m],
                self.opts.width,
                self.opts.height,
                options.clone(),
            ),
            None => Renderer::new(
                gpu,
                &self.world.level,
                &self.colors,
                choice.method,
                &self.settings[m],
                self.opts.width,
                self.opts.height,
            ),
        };
        let mut renderer = match built {
            Ok(r) => r,
            // With paging on, a whole-world method that cannot hold this
            // world is a refusal in the results, not the end of the run.
            Err(e) if self.paging.is_some() => {
                let error = format!(
                    "{e:#} (with --gpu-budget, {} draw through pages)",
                    PAGED_METHODS.join(", ")
                );
                bar.println(format!("{label}: {error}"));
                for &v in &todo {
                    session.results.failures.push(Failure {
                        view: self.opts.views[v].name.clone(),
                        method: label.clone(),
                        error: error.clone(),
                    });
                    bar.inc(1);
                    count.measured += 1;
                }
                session.save_json()?;
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        let setup_ms = ms(start);
        for (i, &v) in todo.iter().enumerate() {
            if count.stop_after.is_some_and(|n| count.measured >= n) {
                return Err(Stopped(count.measured).into());
            }
            let (view, camera) = (&self.opts.views[v], &self.cameras[v]);
            bar.set_message(format!("{} / {label}", view.name));
            // The renderer's first view covers its incremental build (view 0
            // in a fresh run; the first view left in a resumed one).
            // Later views keep warming up while the method still builds
            // (`ray-exact` casts a still view's shadow cover over its first
            // frames there), up to `VIEW_BUILD_FRAMES` more; without
            // timestamps the builds are not seen and every frame up to the
            // cap would run, so there the cap stays.
            let warmup = if i == 0 {
                self.warmup_first
            } else if session.results.adapter.timestamps {
                self.opts.min_warmup.saturating_add(VIEW_BUILD_FRAMES)
            } else {
                self.opts.min_warmup
            };
            match self.cell(
                session,
                &mut renderer,
                (&references[v], colors[v].as_ref()),
                v,
                m,
                camera,
                warmup,
                setup_ms,
            ) {
                Ok(row) => session.results.rows.push(row),
                Err(e) => {
                    bar.println(format!("{} / {label}: {e:#}", view.name));
                    session.results.failures.push(Failure {
                        view: view.name.clone(),
                        method: label.clone(),
                        error: format!("{e:#}"),
                    });
                }
            }
            session.save_json()?;
            bar.inc(1);
            count.measured += 1;
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn cell(
        &self,
        session: &mut Session,
        renderer: &mut Renderer,
        (reference, color_reference): (&Reference, Option<&ColorImage>),
        v: usize,
        m: usize,
        camera: &Camera,
        warmup: u32,
        setup_ms: f64,
    ) -> anyhow::Result<Row> {
        let view = &self.opts.views[v];
        let label = self.opts.methods[m].label();
        // Paged terrain: every page the view reads resident before timing.
        let converge_frames = renderer
            .converge(camera, CONVERGE_FRAMES)
            .context("paged terrain")?;
        if self.opts.hold_busy_ms > 0 {
            // A renderer's first view follows its setup, seconds of CPU work
            // in which the GPU idles down to its lowest clock (345 MHz on the
            // H100), and the clock then took longer than one hold to come back:
            // ray-exact's first 9 timed frames at its first view read 2.6x
            // slow. So that view holds four times as long.
            let scale = if v == 0 { 4 } else { 1 };
            renderer.hold_busy(
                camera,
                std::time::Duration::from_millis(u64::from(self.opts.hold_busy_ms) * scale),
            )?;
        }
        let warm = warm_up(
            renderer,
            camera,
            self.opts.min_warmup,
            warmup,
            session.results.adapter.timestamps,
        )?;
        let frames = (0..self.opts.frames)
            .map(|_| renderer.render_frame(camera))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let paging = renderer.paged_terrain().map(|t| {
            let s = t.stats();
            CellPaging {
                gpu_budget: s.gpu_budget,
                gpu_bytes: s.gpu_bytes,
                slots: s.slots,
                resident_pages: s.resident_pages,
                resident_bytes: s.resident_bytes,
                converge_frames,
                pending_pixels: s.pending_pixels,
                read_errors: s.read_errors,
            }
        });
        let depth = renderer.read_depth()?;
        let distance = strata_reference::distance_from_depth(camera, &depth);
        let metrics = strata_reference::metrics::try_compare(reference, &distance)?;
        let color = color_image(camera.width, camera.height, renderer.read_color()?)?;
        let file = format!("{}-{}", view.name, file_part(&label));
        #[cfg(not(target_arch = "wasm32"))]
        let flip = match color_reference {
            Some(c) => {
                let map = crate::flip::FlipMap::compare(c, &color)?;
                let flip_file = format!("{file}-flip");
                let image =
                    session.save_picture(GridMode::Flip, (v, m + 1), &flip_file, map.picture())?;
                Some(FlipScore {
                    mean: map.mean(),
                    over_half: map.percent_over_half(),
                    image,
                })
            }
            None => None,
        };
        #[cfg(target_arch = "wasm32")]
        let flip = color_reference.and(None);
        let image = session.save_picture(GridMode::Pictures, (v, m + 1), &file, color)?;
        let measured = Measured {
            metrics,
            frames,
            warm,
            setup_ms,
            retained: renderer.retained_bytes(),
        };
        let mut row = self.row(v, m, measured, image)?;
        row.flip = flip;
        row.paging = paging;
        Ok(row)
    }

    /// The row of cell (view `v`, method `m`) from what was measured there
    /// (the native runner's and the browser page's). `image` is the cell
    /// picture relative to the results file ("" without one).
    pub fn row(
        &self,
        v: usize,
        m: usize,
        measured: Measured,
        image: String,
    ) -> anyhow::Result<Row> {
        row_of(
            &self.opts.views[v],
            self.opts.methods[m].label(),
            measured,
            image,
        )
    }
}

/// The row of one cell from what was measured there ([`Plan::row`], and
/// the runs over paged stores that have no [`Plan`]).
pub fn row_of(
    view: &ViewSpec,
    method: String,
    measured: Measured,
    image: String,
) -> anyhow::Result<Row> {
    let Measured {
        metrics,
        frames,
        warm,
        setup_ms,
        retained,
    } = measured;
    let n = frames.len() as f64;
    let mut passes: Vec<PassTime> = Vec::new();
    for t in &frames {
        for (label, ms) in &t.passes {
            match passes.iter_mut().find(|p| p.label == *label) {
                Some(p) => p.mean_ms += ms / n,
                None => passes.push(PassTime {
                    label: label.clone(),
                    mean_ms: ms / n,
                }),
            }
        }
    }
    let cpu: Vec<f64> = frames.iter().map(|t| t.cpu_ms).collect();
    let gpu: Vec<f64> = frames.iter().filter_map(|t| t.gpu_ms).collect();
    // Timestamps on some frames only would mix sources: keep GPU only when every frame has it.
    let gpu_t = if gpu.len() == cpu.len() {
        summarize(&gpu)
    } else {
        None
    };
    let cpu_t = summarize(&cpu).context("no timed frames")?;
    Ok(Row {
        view: view.name.clone(),
        pitch: view.pitch,
        method,
        see_through: metrics.see_through,
        covers_sky: metrics.covers_sky,
        depth_p50: f64::from(metrics.depth_p50),
        depth_p95: f64::from(metrics.depth_p95),
        coherence: metrics.coherence,
        gpu_ms_mean: gpu_t.as_ref().map(|t| t.mean),
        cpu_ms_mean: cpu_t.mean,
        timing_source: TimingSource::of(gpu_t.as_ref()),
        gpu_ms: gpu_t,
        cpu_ms: cpu_t,
        prep_setup_ms: setup_ms,
        prep_first_frame_ms: warm.first_ms,
        prep_warmup_ms: warm.total_ms,
        gpu_bytes: retained.gpu,
        cpu_bytes: retained.cpu,
        passes,
        image,
        flip: None,
        paging: None,
    })
}

/// Cells measured so far in this call, and where [`Plan::run_until`] stops.
struct CellCount {
    measured: usize,
    stop_after: Option<usize>,
}

/// [`Plan::run_until`] stopped on purpose after this many cells.
#[derive(Debug)]
pub struct Stopped(pub usize);

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "stopped after {} cells, as asked", self.0)
    }
}

impl std::error::Error for Stopped {}

/// What one cell measured, before it becomes a [`Row`].
pub struct Measured {
    pub metrics: strata_reference::Metrics,
    /// The timed frames.
    pub frames: Vec<strata_render::FrameTimings>,
    pub warm: WarmUp,
    /// The renderer's setup (paid once per method, recorded on each row).
    pub setup_ms: f64,
    pub retained: strata_render::RetainedBytes,
}
