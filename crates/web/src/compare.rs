//! `?compare`: the quick protocol in the page — every method (or
//! `&methods=A,B`, as `--methods`) at the level's views (or `&views=A,B`) at 320x200, 4 timed frames, shadows on, no edit
//! protocol — scored against the CPU reference traced in the page. The
//! results file is `strata compare`'s own (`strata_bench::results`), built by
//! the same [`Plan`]; the page offers it for download, and `strata merge`
//! takes it next to a native `strata compare --quick --no-edits`.
//!
//! What differs from the native runner is only what a page must do
//! differently: it cannot block, so each frame is awaited (submit until the
//! queue reports the work done: the same CPU submit-and-wait timing the
//! native runner uses without timestamps), read-backs are polled, the mesh
//! fits a slice at a time, and it yields to the browser between steps.

use crate::progress::{progress, yield_to_browser};
use anyhow::Context;
use std::cell::RefCell;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use strata_bench::plan::{every_method, file_part, parse_methods};
use strata_bench::results::{Failure, RunResults};
use strata_bench::run::{EditMode, Measured, Options, Plan, WarmUp};
use strata_camera::Camera;
use strata_level::World;
use strata_reference::{Reference, ReferenceSettings, Tracer};
use strata_render::{FrameTimings, Gpu, Renderer, methods};
use strata_viewer::web::{Backend, now_ms, set_state};
use wasm_bindgen::JsCast;

/// The quick protocol's picture size and frame counts (`strata compare --quick`).
const SIZE: (u32, u32) = (320, 200);
const FRAMES: u32 = 4;
const MIN_WARMUP: u32 = 1;
/// Milliseconds of a sliced build (the mesh fit) between yields.
const STEP_BUDGET_MS: f64 = 100.0;

thread_local! {
    /// The finished results file, for `strataResults()`.
    static RESULTS: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// The results file of the last `?compare` run (JSON), once it is complete.
pub fn results_json() -> Option<String> {
    RESULTS.with(|r| r.borrow().clone())
}

/// Run the protocol on `world`; `views` keeps only the named views, and
/// `methods` (`compare --methods`' syntax) chooses the methods.
pub async fn run(
    world: World,
    backend: Backend,
    views: Option<Vec<String>>,
    methods: Option<&str>,
) -> anyhow::Result<()> {
    let views = match views {
        None => world.views.clone(),
        Some(names) => names
            .iter()
            .map(|n| {
                world
                    .views
                    .iter()
                    .find(|v| v.name == *n)
                    .cloned()
                    .with_context(|| {
                        format!(
                            "?views: the level has no view `{n}`; it has {}",
                            world
                                .views
                                .iter()
                                .map(|v| v.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    })
            })
            .collect::<anyhow::Result<_>>()?,
    };
    let methods = match methods {
        Some(list) => parse_methods(list, methods::METHODS).context("?methods")?,
        None => every_method(),
    };
    let options = Options {
        out: PathBuf::new(),
        methods,
        views,
        width: SIZE.0,
        height: SIZE.1,
        frames: FRAMES,
        min_warmup: MIN_WARMUP,
        // A page cannot block on the GPU; its frames are paced by the browser.
        hold_busy_ms: 0,
        shadows: true,
        edits: EditMode::Off,
        temporal: false,
        cache_dir: PathBuf::new(),
        resume: false,
        grid: Default::default(),
    };
    let plan = Plan::without_output(world, options)?;
    // The folder picker opens worlds for the viewer, which this page does not run.
    if let Some(bar) = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("strata-bar"))
    {
        let _ = bar.set_attribute("style", "display: none");
    }
    progress(Some(0.0), "opening the adapter");
    let gpu = open_gpu(backend).await?;
    let mut results = plan.results_header(&gpu);
    results.adapter.name = adapter_name(&gpu, backend);
    results.source_revision = option_env!("STRATA_SOURCE_REVISION")
        .unwrap_or("unknown")
        .to_string();
    results.edit_skipped =
        Some("the page runs the protocol without its edit pass (compare with `--no-edits`)".into());
    let start = now_ms();
    let references = references(&plan).await?;
    let reference_ms = now_ms() - start;
    web_sys::console::log_1(&format!("strata: references in {reference_ms:.0} ms").into());

    let n_methods = plan.options().methods.len();
    for m in 0..n_methods {
        // The method is its entry; the label (`ray:64`) only names the column.
        let choice = &plan.options().methods[m];
        let label = choice.label();
        if let Err(e) = choice.method.check(&gpu.caps) {
            results.failures.push(Failure {
                view: "*".into(),
                method: label,
                error: format!("refused: {e}"),
            });
            continue;
        }
        if let Err(e) = method_column(&plan, &gpu, &references, m, &mut results).await {
            results.failures.push(Failure {
                view: "*".into(),
                method: label,
                error: format!("{e:#}"),
            });
        }
    }
    results.complete = true;
    let total_ms = now_ms() - start;
    finish(&results, reference_ms, total_ms)
}

async fn open_gpu(backend: Backend) -> anyhow::Result<Gpu> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: backend.backends(),
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    Gpu::with_instance_async(instance, None, &Default::default())
        .await
        .context("no adapter for the protocol (try ?backend=webgl2)")
}

/// A name that says browser and API (a browser's adapter often has none of its own).
fn adapter_name(gpu: &Gpu, backend: Backend) -> String {
    let api = match backend {
        Backend::WebGpu => "WebGPU",
        Backend::WebGl2 => "WebGL2",
    };
    let agent = web_sys::window()
        .and_then(|w| w.navigator().user_agent().ok())
        .and_then(|ua| {
            ua.split_whitespace()
                .find(|p| {
                    p.starts_with("HeadlessChrome/")
                        || p.starts_with("Chrome/")
                        || p.starts_with("Firefox/")
                })
                .map(|p| p.replace('/', " "))
        })
        .unwrap_or_else(|| "a browser".into());
    let name = if gpu.report.name.trim().is_empty() {
        "unnamed adapter"
    } else {
        gpu.report.name.trim()
    };
    format!("{name} ({api} in {agent})")
}

/// Every view's reference, traced here (one tracer, its pyramid built once).
async fn references(plan: &Plan) -> anyhow::Result<Vec<Reference>> {
    let label = "tracing the CPU references";
    progress(Some(0.0), label);
    yield_to_browser().await;
    let tracer = Tracer::new(&plan.world().level);
    let cameras = plan.cameras();
    let mut out = Vec::with_capacity(cameras.len());
    for (v, camera) in cameras.iter().enumerate() {
        out.push(tracer.render(camera, &ReferenceSettings::default()));
        let done = (v + 1) as f64 / cameras.len() as f64;
        progress(
            Some(done),
            &format!("{label}: {} of {}", v + 1, cameras.len()),
        );
        publish("references", done, None);
        yield_to_browser().await;
    }
    Ok(out)
}

/// Every view of method `m` on one renderer.
async fn method_column(
    plan: &Plan,
    gpu: &Gpu,
    references: &[Reference],
    m: usize,
    results: &mut RunResults,
) -> anyhow::Result<()> {
    let choice = &plan.options().methods[m];
    let label = choice.label();
    let settings = plan.method_settings(m);
    let level = &plan.world().level;
    let status = |what: &str| {
        let done = m as f64 / plan.options().methods.len() as f64;
        progress(Some(done), &format!("{label}: {what}"));
        publish("measuring", done, Some(&label));
    };
    status("setup");
    yield_to_browser().await;
    // The renderer comes with `ray` (quick to build); the method is built in
    // slices (the mesh fit would hold the page for seconds) and put in it.
    let start = now_ms();
    let (w, h) = SIZE;
    let mut renderer = Renderer::new(gpu, level, plan.colors(), "ray", settings, w, h)?;
    let mut build_ms = now_ms() - start;
    let shared = renderer.shared_handle();
    let mut steps = methods::create_in_steps(choice.method, &shared.caps, settings)?;
    let method = loop {
        let step = now_ms();
        let built = steps.step(&shared, level, STEP_BUDGET_MS)?;
        build_ms += now_ms() - step;
        if let Some(method) = built {
            break method;
        }
        let fraction = shared.progress.get(choice.name()).unwrap_or(0.0);
        status(&format!("setup {:.0} %", fraction * 100.0));
        yield_to_browser().await;
    };
    renderer.insert_method(method, settings.clone());
    renderer.activate(choice.name())?;
    drop(shared);

    for (v, camera) in plan.cameras().iter().enumerate() {
        let view = &plan.options().views[v];
        status(&view.name);
        let cell = cell(plan, &mut renderer, &references[v], v, camera, build_ms).await;
        match cell.and_then(|measured| plan.row(v, m, measured, String::new())) {
            Ok(row) => {
                web_sys::console::log_1(
                    &format!(
                        "strata: {} / {label}: see-through {:.3} %, covers-sky {:.3} %, coherence {:.3} %, {:.1} ms",
                        view.name, row.see_through, row.covers_sky, row.coherence, row.cpu_ms_mean
                    )
                    .into(),
                );
                results.rows.push(row);
            }
            Err(e) => results.failures.push(Failure {
                view: view.name.clone(),
                method: label.clone(),
                error: format!("{e:#}"),
            }),
        }
        yield_to_browser().await;
    }
    Ok(())
}

/// One (view, method) cell: warm-up, timed frames, depth read-back, metrics.
async fn cell(
    plan: &Plan,
    renderer: &mut Renderer,
    reference: &Reference,
    v: usize,
    camera: &Camera,
    setup_ms: f64,
) -> anyhow::Result<Measured> {
    let warmup = plan.warmup_frames(v).max(1);
    let start = now_ms();
    let first_ms = frame(renderer, camera).await?.cpu_ms;
    for _ in 1..warmup {
        frame(renderer, camera).await?;
    }
    let warm = WarmUp {
        first_ms,
        total_ms: now_ms() - start,
        frames: warmup,
    };
    let mut frames = Vec::new();
    for _ in 0..plan.options().frames {
        frames.push(frame(renderer, camera).await?);
    }
    let read = renderer.start_read_depth();
    let device = &renderer.shared().device;
    let bytes = loop {
        if let Some(bytes) = read.try_take(device) {
            break bytes?;
        }
        yield_now().await;
    };
    let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
    let distance = strata_reference::distance_from_depth(camera, &depth);
    let metrics = strata_reference::metrics::try_compare(reference, &distance)?;
    Ok(Measured {
        metrics,
        frames,
        warm,
        setup_ms,
        retained: renderer.retained_bytes(),
    })
}

/// Render one frame and wait (yielding) until the queue has done it; its
/// CPU time is submit until done, as the native runner times frames
/// without timestamps.
async fn frame(renderer: &mut Renderer, camera: &Camera) -> anyhow::Result<FrameTimings> {
    let start = now_ms();
    let mut timings = renderer.render_frame(camera)?;
    let done = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&done);
    renderer
        .shared()
        .queue
        .on_submitted_work_done(move || flag.store(true, Ordering::Release));
    while !done.load(Ordering::Acquire) {
        let _ = renderer.shared().device.poll(wgpu::PollType::Poll);
        yield_now().await;
    }
    timings.cpu_ms = now_ms() - start;
    Ok(timings)
}

/// Yield to the browser's event loop through a message (a timeout would
/// be clamped to 4 ms once nested, which would show in frame times).
async fn yield_now() {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        let Ok(channel) = web_sys::MessageChannel::new() else {
            let _ = resolve.call0(&wasm_bindgen::JsValue::NULL);
            return;
        };
        channel.port1().set_onmessage(Some(resolve.unchecked_ref()));
        let _ = channel.port2().post_message(&wasm_bindgen::JsValue::NULL);
    });
    let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
}

fn publish(phase: &str, progress: f64, method: Option<&str>) {
    set_state(serde_json::json!({
        "phase": phase,
        "progress": progress,
        "method": method,
    }));
}

/// Keep the results for `strataResults()`, show a summary and the download.
fn finish(results: &RunResults, reference_ms: f64, total_ms: f64) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(results).context("writing the results file")?;
    let name = format!("results-{}.json", file_part(&results.adapter.name));
    RESULTS.with(|r| *r.borrow_mut() = Some(json.clone()));
    progress(None, "");
    let summary = summary(results);
    show(&name, &json, &summary)?;
    set_state(serde_json::json!({
        "phase": "compared",
        "results_name": name,
        "rows": results.rows.len(),
        "failures": results.failures.len(),
        "reference_ms": reference_ms,
        "total_ms": total_ms,
    }));
    Ok(())
}

/// Per method: cells, worst see-through / covers-sky / coherence, mean frame ms.
fn summary(results: &RunResults) -> String {
    let mut text = format!(
        "{} on {} ({}x{}, {} views, {} frames per cell)\n\n{:<14} {:>5} {:>12} {:>12} {:>12} {:>10}\n",
        results.level.name,
        results.adapter.name,
        results.settings.width,
        results.settings.height,
        results.settings.views.len(),
        results.settings.frames,
        "method",
        "cells",
        "see-through",
        "covers-sky",
        "coherence",
        "frame ms"
    );
    for method in &results.settings.methods {
        let rows: Vec<_> = results
            .rows
            .iter()
            .filter(|r| &r.method == method)
            .collect();
        if rows.is_empty() {
            let why = results
                .failures
                .iter()
                .find(|f| &f.method == method)
                .map_or("no cells", |f| f.error.as_str());
            text.push_str(&format!("{method:<14} {why}\n"));
            continue;
        }
        let worst = |get: fn(&strata_bench::results::Row) -> f64| {
            rows.iter().map(|r| get(r)).fold(0.0, f64::max)
        };
        let mean_ms = rows.iter().map(|r| r.frame_ms()).sum::<f64>() / rows.len() as f64;
        text.push_str(&format!(
            "{method:<14} {:>5} {:>11.3}% {:>11.3}% {:>11.3}% {:>10.1}\n",
            rows.len(),
            worst(|r| r.see_through),
            worst(|r| r.covers_sky),
            worst(|r| r.coherence),
            mean_ms
        ));
    }
    text
}

/// The summary and a download link for the results file, in the page.
fn show(name: &str, json: &str, summary: &str) -> anyhow::Result<()> {
    let fail = |what: &str| anyhow::anyhow!("showing the results: {what}");
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| fail("no document"))?;
    let body = document.body().ok_or_else(|| fail("no body"))?;
    let pre = document
        .create_element("pre")
        .map_err(|_| fail("no <pre>"))?;
    pre.set_id("strata-results");
    pre.set_text_content(Some(summary));
    let parts = js_sys::Array::of1(&json.into());
    let blob = web_sys::Blob::new_with_str_sequence(&parts).map_err(|_| fail("no Blob"))?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(|_| fail("no URL"))?;
    let link: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(|_| fail("no <a>"))?
        .dyn_into()
        .map_err(|_| fail("not an <a>"))?;
    link.set_id("strata-download");
    link.set_href(&url);
    link.set_download(name);
    link.set_text_content(Some(&format!(
        "Download {name} (then: strata merge {name} <native results-*.json> --out DIR)"
    )));
    body.append_child(&link).map_err(|_| fail("appending"))?;
    body.append_child(&pre).map_err(|_| fail("appending"))?;
    Ok(())
}
