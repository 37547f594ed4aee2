//! `strata compare` over a world that cannot be loaded whole (a store past
//! the whole-world limit, issue 33): the paged methods
//! (`strata_render::paged::PAGED_METHODS`) draw it through pages and are
//! measured and compared as in the protocol (each view converged before its
//! warm-up and timed frames, the CPU reference traced through the store's
//! chunk cache); every other method is a refusal in the results, naming the
//! limit and the methods that can draw the world. No edit protocol and no
//! temporal path here (both need the world in memory).

use crate::methods::{describe, settings_for};
use crate::plan::{MethodChoice, file_part, source_revision};
use crate::results::*;
use crate::run::{CONVERGE_FRAMES, Measured, Options, adapter_info, row_of};
use crate::session::{GridMode, Session, color_image};
use crate::warm::{ms, warm_up};
use anyhow::Context;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use strata_camera::Camera;
use strata_level::MidRule;
use strata_level::source::ColumnSource;
use strata_reference::{ReferenceSettings, Tracer};
use strata_render::paged::{PAGED_METHODS, PageSource, PagedOptions};
use strata_render::{Gpu, Renderer, TerrainColors};

/// A world drawn only through pages.
pub struct PagedInput<'a> {
    pub name: String,
    pub size: (u32, u32),
    pub mid_rule: MidRule,
    pub colors: TerrainColors,
    pub source: Arc<dyn PageSource>,
    /// Where the CPU reference reads columns (a store's chunk cache).
    pub columns: &'a dyn ColumnSource,
    pub paging: PagedOptions,
    /// Why the other methods cannot draw it: the limit it is past.
    pub refusal: String,
}

/// Run the protocol's cells that a paged world allows; returns the results
/// file and `report.md`.
pub fn run(
    gpu: &Gpu,
    input: &PagedInput<'_>,
    opts: &Options,
) -> anyhow::Result<(PathBuf, PathBuf)> {
    let (w, h) = (opts.width, opts.height);
    let cameras = opts
        .views
        .iter()
        .map(|v| {
            strata_reference::camera_for_view(input.columns, v, w, h)
                .with_context(|| format!("view `{}`", v.name))
        })
        .collect::<anyhow::Result<Vec<Camera>>>()?;
    let settings = opts
        .methods
        .iter()
        .map(|m| settings_for(m, opts.shadows))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let results = RunResults {
        protocol_version: PROTOCOL_VERSION,
        level: LevelInfo {
            name: input.name.clone(),
            // Hashing would read the whole store.
            hash: format!("unhashed-{}x{}", input.size.0, input.size.1),
            width: input.size.0,
            height: input.size.1,
        },
        adapter: adapter_info(gpu),
        settings: Settings {
            width: w,
            height: h,
            far: cameras
                .first()
                .map_or(strata_camera::DEFAULT_FAR, |c| c.far),
            frames: opts.frames,
            shadows: opts.shadows,
            methods: opts.methods.iter().map(MethodChoice::label).collect(),
            method_settings: opts
                .methods
                .iter()
                .zip(&settings)
                .map(|(m, s)| describe(m.method, s))
                .collect(),
            views: opts.views.clone(),
            warmup_first_view: opts.min_warmup,
            warmup_frames: opts.min_warmup,
            hold_busy_ms: opts.hold_busy_ms,
            edits: false,
            mid_rule: format!("{:?}", input.mid_rule).to_lowercase(),
        },
        source_revision: source_revision(),
        complete: false,
        rows: Vec::new(),
        edit_rows: Vec::new(),
        failures: Vec::new(),
        edit_skipped: Some("the world is drawn through pages (past the whole-world limit)".into()),
        reference_images: Vec::new(),
        temporal: Vec::new(),
        edit_images: Vec::new(),
        gameplay: None,
    };
    let mut session = Session::new(&opts.out, results);
    // The references, traced through the store's chunk cache.
    let tracer = Tracer::over(input.columns).context("preparing the reference tracer")?;
    let mut references = Vec::new();
    for (v, (view, camera)) in opts.views.iter().zip(&cameras).enumerate() {
        let r = tracer
            .try_render(camera, &ReferenceSettings::default())
            .with_context(|| format!("reference of view `{}`", view.name))?;
        session.save_reference(v, &view.name, &r, camera.far)?;
        references.push(r);
    }
    for (m, choice) in opts.methods.iter().enumerate() {
        let label = choice.label();
        if !PAGED_METHODS.contains(&choice.method.name) {
            let error = format!(
                "`{}` draws whole worlds only, and {}; {} draw it through pages",
                choice.method.name,
                input.refusal,
                PAGED_METHODS.join(", ")
            );
            eprintln!("{label}: {error}");
            for view in &opts.views {
                session.results.failures.push(Failure {
                    view: view.name.clone(),
                    method: label.clone(),
                    error: error.clone(),
                });
            }
            continue;
        }
        let start = Instant::now();
        let mut renderer = Renderer::new_paged(
            gpu,
            input.source.clone(),
            &input.colors,
            choice.method,
            &settings[m],
            w,
            h,
            input.paging.clone(),
        )?;
        let setup_ms = ms(start);
        for (v, (view, camera)) in opts.views.iter().zip(&cameras).enumerate() {
            let cell = (|| -> anyhow::Result<Row> {
                let converge_frames = renderer.converge(camera, CONVERGE_FRAMES)?;
                let warm = warm_up(
                    &mut renderer,
                    camera,
                    opts.min_warmup,
                    opts.min_warmup,
                    gpu.report.timestamps,
                )?;
                let frames = (0..opts.frames)
                    .map(|_| renderer.render_frame(camera))
                    .collect::<anyhow::Result<Vec<_>>>()?;
                let s = renderer
                    .paged_terrain()
                    .map(|t| t.stats())
                    .unwrap_or_default();
                let depth = renderer.read_depth()?;
                let distance = strata_reference::distance_from_depth(camera, &depth);
                let metrics = strata_reference::metrics::try_compare(&references[v], &distance)?;
                let color = color_image(w, h, renderer.read_color()?)?;
                let file = format!("{}-{}", view.name, file_part(&label));
                let image = session.save_picture(GridMode::Pictures, (v, m + 1), &file, color)?;
                let measured = Measured {
                    metrics,
                    frames,
                    warm,
                    setup_ms,
                    retained: renderer.retained_bytes(),
                };
                let mut row = row_of(view, label.clone(), measured, image)?;
                row.paging = Some(CellPaging {
                    gpu_budget: s.gpu_budget,
                    gpu_bytes: s.gpu_bytes,
                    slots: s.slots,
                    resident_pages: s.resident_pages,
                    resident_bytes: s.resident_bytes,
                    converge_frames,
                    pending_pixels: s.pending_pixels,
                    read_errors: s.read_errors,
                });
                Ok(row)
            })();
            match cell {
                Ok(row) => session.results.rows.push(row),
                Err(e) => session.results.failures.push(Failure {
                    view: view.name.clone(),
                    method: label.clone(),
                    error: format!("{e:#}"),
                }),
            }
            session.save_json()?;
        }
    }
    session.results.complete = true;
    let json = session.save_json()?;
    let report = session.save_report()?;
    Ok((json, report))
}
