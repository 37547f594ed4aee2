//! A Strata store streamed over HTTP (issue 34): only the metadata up front
//! (the root `zarr.json` with the world's attributes, the planes' and the
//! summary's `zarr.json`, the summary's chunks for the coarse level), then
//! chunk objects fetched as the paged terrain asks for them.
//!
//! The seam to the renderer is [`RemoteChunks`]: the streamer tells it each
//! frame what it wants; the pump here, run by a timer (no threads in the
//! page), starts reads up to the cap ([`MOST_IN_FLIGHT`] pages, two
//! requests each), aborts those the camera no longer wants, gives up on a
//! request after the chunk timeout ([`TIMEOUT_MS`], `?chunk-timeout-ms=`),
//! and hands the decoded planes or the error back. The paged terrain
//! retries a failed chunk `read_tries` times, then reports it; resident
//! pages keep drawing.
//!
//! Where the browser allows, a read (the `fetch`es, the crc32c check and
//! the gzip inflate: `strata_store::http`) runs in one of [`WORKERS`]
//! dedicated Web Workers (`www/decode-worker.js`): each instantiates this
//! same wasm module (compiled once, posted to it) and calls
//! [`worker_read`]; the planes come back as transferred `ArrayBuffer`s, and
//! an abort (cancel or timeout) is forwarded to the worker. The workers
//! start once the first frame is drawn; until a worker says it is ready, when Workers are unavailable, for a picked folder's
//! files, or with `?decode=main`, reads run on the page's thread; the page
//! state's `stream_decoder` says where and why, with the page thread's
//! milliseconds spent on chunk bytes.

mod workers;

use crate::page::fetch;
use anyhow::Context;
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::sync::Arc;
use strata_level::{MidRule, World};
use strata_render::paged::{PAGE, PageRef, PageSource, RemoteChunks};
use strata_store::format::{HEIGHTS, METAS, SUMMARY};
use strata_store::http;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;
use workers::{decoder_info, next_worker, start_workers, worker_failed};

/// Pages fetched at a time (two requests each: Chromium opens six
/// connections per host over HTTP/1.1).
pub const MOST_IN_FLIGHT: usize = 3;
/// A request not answered in this time is aborted and counts as failed
/// (default of `?chunk-timeout-ms=`).
pub const TIMEOUT_MS: u32 = 10_000;
/// Decoding workers (each fetches and decodes whole pages).
pub const WORKERS: usize = 2;

/// How the pump reads: `?chunk-timeout-ms=MS`, `?decode=worker|main`.
#[derive(Clone, Copy, Debug)]
pub struct PumpOptions {
    /// A request not answered in this time is aborted and counts as failed.
    pub timeout_ms: u32,
    /// Decode in Web Workers where the browser allows (else on the page's thread).
    pub workers: bool,
}

impl Default for PumpOptions {
    fn default() -> Self {
        PumpOptions {
            timeout_ms: TIMEOUT_MS,
            workers: true,
        }
    }
}

impl PumpOptions {
    /// From the URL's `chunk-timeout-ms` and `decode` values.
    pub fn parse(timeout: Option<String>, decode: Option<String>) -> anyhow::Result<Self> {
        let mut options = PumpOptions::default();
        if let Some(text) = timeout {
            options.timeout_ms = text
                .parse::<u32>()
                .ok()
                .filter(|ms| (100..=600_000).contains(ms))
                .ok_or_else(|| {
                    anyhow::anyhow!("?chunk-timeout-ms={text}: milliseconds, 100..=600000")
                })?;
        }
        match decode.as_deref() {
            None | Some("worker") => {}
            Some("main") => options.workers = false,
            Some(other) => anyhow::bail!("?decode={other}: use worker (default) or main"),
        }
        Ok(options)
    }
}
/// Decoded chunks kept on the CPU (128 KiB each): the column under a view,
/// a dig's chunks.
const CACHE_PAGES: usize = 64;

/// Where a store's objects come from: a URL (fetched, cancellable), or a
/// folder the person picked (its files by path under the folder).
#[derive(Clone)]
pub enum Origin {
    /// The store's URL, ending in `/`.
    Http(String),
    /// A picked folder: its name and its files by path under it.
    Picked {
        name: String,
        files: Rc<HashMap<String, web_sys::File>>,
    },
}

impl Origin {
    /// How messages name the store.
    pub fn label(&self) -> String {
        match self {
            Origin::Http(base) => base.clone(),
            Origin::Picked { name, .. } => format!("the picked folder `{name}`"),
        }
    }

    /// Object `key` (`heights/c/3/1`), `None` when there is none (still
    /// in JS memory: the caller copies it in).
    async fn get(
        &self,
        key: &str,
        signal: Option<(&web_sys::AbortSignal, u32)>,
    ) -> Result<Option<js_sys::Uint8Array>, String> {
        match self {
            Origin::Http(base) => {
                let url = format!("{base}{key}");
                match signal {
                    Some((signal, timeout_ms)) => fetch_with(&url, signal, timeout_ms).await,
                    None => fetch(&url)
                        .await
                        .map(|b| b.map(|b| js_sys::Uint8Array::from(&b[..])))
                        .map_err(|e| format!("{e:#}")),
                }
            }
            Origin::Picked { files, .. } => {
                let Some(file) = files.get(key) else {
                    return Ok(None);
                };
                let buffer = JsFuture::from(file.array_buffer())
                    .await
                    .map_err(|e| format!("reading {key}: {}", describe(&e)))?;
                Ok(Some(js_sys::Uint8Array::new(&buffer)))
            }
        }
    }

    /// Object `key`, which the store must have.
    async fn required(
        &self,
        key: &str,
        signal: Option<(&web_sys::AbortSignal, u32)>,
    ) -> Result<js_sys::Uint8Array, String> {
        self.get(key, signal).await?.ok_or_else(|| match self {
            Origin::Http(base) => format!("GET {base}{key}: 404 Not Found (a store needs it)"),
            Origin::Picked { name, .. } => {
                format!("the picked folder `{name}` has no {key} (a store needs it)")
            }
        })
    }
}

/// A streamed store, opened: the world without its map, its pages.
pub struct Streamed {
    pub world: World,
    pub remote: Arc<RemoteChunks>,
    pub origin: Origin,
}

/// Open the store at `origin`: `None` when it has no `zarr.json` (not a
/// store: maybe a Vangers world directory).
pub async fn open(origin: Origin) -> anyhow::Result<Option<Streamed>> {
    let Some(root) = origin
        .get("zarr.json", None)
        .await
        .map_err(anyhow::Error::msg)?
    else {
        return Ok(None);
    };
    let root = root.to_vec();
    let label = origin.label();
    let what = label.trim_end_matches('/');
    let attrs = http::world_attrs(what, &root)?;
    let (w, h) = (attrs.width, attrs.height);
    if attrs.chunk != [PAGE, PAGE] {
        anyhow::bail!(
            "{what}: chunks of {}x{}; the page streams {PAGE}x{PAGE} chunks (rewrite it with `strata convert`)",
            attrs.chunk[1],
            attrs.chunk[0]
        );
    }
    let (gy, gx) = (u64::from(h / PAGE), u64::from(w / PAGE));
    let required = |name: String| {
        let origin = origin.clone();
        async move {
            origin
                .required(&name, None)
                .await
                .map(|b| b.to_vec())
                .map_err(anyhow::Error::msg)
        }
    };
    // Started together, awaited in turn.
    let plane_meta = [HEIGHTS, METAS].map(|a| required(format!("{a}/zarr.json")));
    let summary_meta = required(format!("{SUMMARY}/zarr.json"));
    for (meta, name) in plane_meta.into_iter().zip([HEIGHTS, METAS]) {
        let json = meta.await?;
        let shape = [u64::from(h), u64::from(w)];
        http::check_array(name, &json, "uint8", &shape, &[PAGE.into(), PAGE.into()])
            .with_context(|| what.to_string())?;
    }
    let (sshape, schunk) = http::summary_shape(gy, gx);
    http::check_array(SUMMARY, &summary_meta.await?, "uint32", &sshape, &schunk)
        .with_context(|| what.to_string())?;
    let mut objects = Vec::new();
    for cell in http::summary_cells(gy, gx) {
        objects.push(required(http::chunk_key(SUMMARY, &cell)).await?);
    }
    let tops = http::chunk_tops(gy, gx, &objects).with_context(|| what.to_string())?;
    let world = http::world_shell(what, &attrs)?;
    // No level of detail yet: the paper's far plane never reaches it.
    let remote = Arc::new(RemoteChunks::new(
        (w, h),
        MidRule::Original,
        tops,
        0,
        MOST_IN_FLIGHT,
        CACHE_PAGES,
    )?);
    Ok(Some(Streamed {
        world,
        remote,
        origin,
    }))
}

/// A page read: its planes or why not, the bytes fetched, and the
/// milliseconds of the reading thread spent on them (copies, checksums,
/// inflating; not the waits).
struct Read {
    planes: Result<strata_render::paged::Planes, String>,
    bytes: u64,
    ms: f64,
}

/// The chunk objects of page `page`, fetched and decoded.
async fn read_page(
    origin: &Origin,
    page: PageRef,
    signal: &web_sys::AbortSignal,
    timeout_ms: u32,
) -> Read {
    let cell = [u64::from(page.cy), u64::from(page.cx)];
    let prefix = if page.level == 0 {
        String::new()
    } else {
        format!("lod/{}/", page.level)
    };
    let mut bytes = 0u64;
    let mut ms = 0.0;
    // Both requests go out before either is awaited.
    let requests = [HEIGHTS, METAS].map(|name| {
        let key = format!("{prefix}{}", http::chunk_key(name, &cell));
        let request = {
            let (origin, key) = (origin.clone(), key.clone());
            async move { origin.required(&key, Some((signal, timeout_ms))).await }
        };
        (name, format!("{}{key}", origin.label()), request)
    });
    let mut planes = Vec::new();
    for (name, url, request) in requests {
        let raw = match request.await {
            Ok(raw) => raw,
            Err(e) => {
                return Read {
                    planes: Err(e),
                    bytes,
                    ms,
                };
            }
        };
        let start = clock_ms();
        let raw = raw.to_vec();
        bytes += raw.len() as u64;
        let array = format!("{prefix}{name}");
        let decoded = http::decode_chunk(&array, &cell, &raw, (PAGE * PAGE) as usize);
        ms += clock_ms() - start;
        match decoded {
            Ok(plane) => planes.push(plane),
            Err(e) => {
                return Read {
                    planes: Err(format!("{url}: {e}")),
                    bytes,
                    ms,
                };
            }
        }
    }
    let metas = planes.pop().unwrap_or_default();
    let heights = planes.pop().unwrap_or_default();
    Read {
        planes: Ok((heights, metas)),
        bytes,
        ms,
    }
}

/// GET `url` with `signal`: its bytes, `None` on 404, or why not.
/// (The page's or a worker's global `fetch`; `timeout_ms` names the
/// timeout in the message when `signal` fired.)
async fn fetch_with(
    url: &str,
    signal: &web_sys::AbortSignal,
    timeout_ms: u32,
) -> Result<Option<js_sys::Uint8Array>, String> {
    let init = web_sys::RequestInit::new();
    init.set_signal(Some(signal));
    let global = js_sys::global();
    let request = if let Some(window) = global.dyn_ref::<web_sys::Window>() {
        window.fetch_with_str_and_init(url, &init)
    } else if let Some(worker) = global.dyn_ref::<web_sys::WorkerGlobalScope>() {
        worker.fetch_with_str_and_init(url, &init)
    } else {
        return Err(format!("GET {url}: no window or worker to fetch from"));
    };
    let secs = f64::from(timeout_ms) / 1000.0;
    let response = JsFuture::from(request).await.map_err(|e| {
        if signal.aborted() {
            format!("GET {url}: no answer in {secs} s (aborted)")
        } else {
            format!("GET {url}: request failed: {}", describe(&e))
        }
    })?;
    let response: web_sys::Response = response.dyn_into().map_err(|_| "not a response")?;
    if response.status() == 404 {
        return Ok(None);
    }
    if !response.ok() {
        return Err(format!(
            "GET {url}: HTTP {} {}",
            response.status(),
            response.status_text()
        ));
    }
    let buffer = response
        .array_buffer()
        .map_err(|e| format!("GET {url}: no body: {}", describe(&e)))?;
    let buffer = JsFuture::from(buffer).await.map_err(|e| {
        if signal.aborted() {
            format!("GET {url}: body cut off: no answer in {secs} s")
        } else {
            format!("GET {url}: reading the body failed: {}", describe(&e))
        }
    })?;
    Ok(Some(js_sys::Uint8Array::new(&buffer)))
}

/// `performance.now()` of the page or the worker (0 without one).
fn clock_ms() -> f64 {
    let global = js_sys::global();
    let performance = if let Some(window) = global.dyn_ref::<web_sys::Window>() {
        window.performance()
    } else if let Some(worker) = global.dyn_ref::<web_sys::WorkerGlobalScope>() {
        worker.performance()
    } else {
        None
    };
    performance.map_or(0.0, |p| p.now())
}

fn describe(e: &JsValue) -> String {
    e.as_string()
        .or_else(|| {
            js_sys::Reflect::get(e, &"message".into())
                .ok()
                .and_then(|m| m.as_string())
        })
        .unwrap_or_else(|| format!("{e:?}"))
}

thread_local! {
    /// The reads in flight, by page id.
    static FLIGHTS: RefCell<HashMap<u32, Flight>> = RefCell::new(HashMap::new());
    /// Reads handed to a worker, by number: what its answer is for.
    static SENT: RefCell<HashMap<u64, Sent>> = RefCell::new(HashMap::new());
    /// The pump's interval timer.
    static PUMP: std::cell::Cell<Option<i32>> = const { std::cell::Cell::new(None) };
    /// Numbers the reads, so a cancelled one's late answer is told apart.
    static SEQ: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    /// The page thread's work on the pump's reads.
    static PAGE_THREAD: std::cell::Cell<PageThread> = const { std::cell::Cell::new(PageThread { ms: 0.0, pages: 0, in_workers: 0, workers_ms: 0.0 }) };
}

/// The page thread's work on the pump's reads (delivered ones), in the
/// page state as `stream_page_thread`.
#[derive(Clone, Copy)]
struct PageThread {
    /// Milliseconds spent on chunk bytes: copied in, and (read here) checked
    /// and inflated.
    ms: f64,
    /// Reads delivered.
    pages: u64,
    /// Of those, read and decoded in a worker.
    in_workers: u64,
    /// Of `ms`, what the reads in workers cost (their planes copied in).
    workers_ms: f64,
}

/// A read in flight.
struct Flight {
    seq: u64,
    abort: Abort,
    timer: Option<i32>,
}

/// How a read in flight is stopped (the camera moved on, or the timeout).
#[derive(Clone)]
enum Abort {
    /// A `fetch` on the page's thread.
    Here(web_sys::AbortController),
    /// Read `seq` in a worker: the abort is forwarded to it.
    Worker(web_sys::Worker, u64),
}

impl Abort {
    fn abort(&self) {
        match self {
            Abort::Here(controller) => controller.abort(),
            Abort::Worker(worker, seq) => {
                let message = js_sys::Object::new();
                set(&message, "kind", &"abort".into());
                set(&message, "id", &(*seq as f64).into());
                let _ = worker.post_message(&message);
            }
        }
    }
}

/// A read handed to worker `worker`.
struct Sent {
    remote: Arc<RemoteChunks>,
    origin: Origin,
    options: PumpOptions,
    page: PageRef,
}

impl Sent {
    /// The worker's answer `read` to read `seq`.
    fn finish(self, seq: u64, read: Read) {
        finish(
            &self.remote,
            &self.origin,
            self.options,
            self.page,
            seq,
            read,
            true,
        );
    }
}

fn set(object: &js_sys::Object, key: &str, value: &JsValue) {
    let _ = js_sys::Reflect::set(object, &key.into(), value);
}

fn get(object: &JsValue, key: &str) -> JsValue {
    js_sys::Reflect::get(object, &key.into()).unwrap_or(JsValue::UNDEFINED)
}

/// Fetch the chunk under map point (`x`, `y`) now and keep it (the viewer
/// places a view's camera on the column there), on the page's thread;
/// aborted after `timeout_ms`.
pub async fn prefetch_at(
    origin: &Origin,
    remote: &RemoteChunks,
    x: f32,
    y: f32,
    timeout_ms: u32,
) -> anyhow::Result<()> {
    let (w, h) = remote.size();
    let cx = (x.floor() as i64).rem_euclid(i64::from(w)) as u32 / PAGE;
    let cy = (y.floor() as i64).rem_euclid(i64::from(h)) as u32 / PAGE;
    if remote.cached(0, cx, cy).is_some() {
        return Ok(());
    }
    let page = PageRef {
        id: cy * (w / PAGE) + cx,
        level: 0,
        cx,
        cy,
    };
    let controller =
        web_sys::AbortController::new().map_err(|_| anyhow::anyhow!("no AbortController"))?;
    let timer = abort_after(Abort::Here(controller.clone()), timeout_ms);
    let read = read_page(origin, page, &controller.signal(), timeout_ms).await;
    clear_timer(timer);
    let planes = read
        .planes
        .map_err(|e| anyhow::anyhow!("the chunk under a view: {e}"))?;
    remote.pin(0, cx, cy, planes);
    Ok(())
}

/// Run the pump for `remote` (every few milliseconds, until another store
/// is opened).
pub fn start_pump(remote: Arc<RemoteChunks>, origin: Origin, options: PumpOptions) {
    match (&origin, options.workers) {
        // After the first frame: the workers' start (a module instance
        // each) competes with it for a machine of few cores (seen once at
        // 4.0 s against 0.9 s without them, though in one browser session
        // where later pages came later either way; bench/web-stream/README.md).
        (Origin::Http(_), true) => {
            if !workers::started() {
                decoder_info(
                    "main thread",
                    Some("the workers start after the first frame".into()),
                );
            }
        }
        (Origin::Http(_), false) => decoder_info("main thread", Some("?decode=main".into())),
        (Origin::Picked { .. }, _) => decoder_info(
            "main thread",
            Some("a picked folder's files are read on the page's thread".into()),
        ),
    }
    let tick = Closure::<dyn FnMut()>::new(move || pump(&remote, &origin, options));
    let Some(window) = web_sys::window() else {
        return;
    };
    if let Some(old) = PUMP.with(|p| p.take()) {
        window.clear_interval_with_handle(old);
    }
    if let Ok(id) = window
        .set_interval_with_callback_and_timeout_and_arguments_0(tick.as_ref().unchecked_ref(), 4)
    {
        PUMP.with(|p| p.set(Some(id)));
    }
    // A stopped pump's closure is a few bytes: kept for the page's life.
    tick.forget();
}

fn pump(remote: &Arc<RemoteChunks>, origin: &Origin, options: PumpOptions) {
    if options.workers
        && matches!(origin, Origin::Http(_))
        && !workers::started()
        && strata_viewer::web::state().contains("\"page_to_first_frame_ms\"")
    {
        start_workers();
    }
    for id in remote.take_cancelled() {
        if let Some(flight) = FLIGHTS.with(|f| f.borrow_mut().remove(&id)) {
            clear_timer(flight.timer);
            flight.abort.abort();
        }
    }
    for page in remote.start() {
        let seq = SEQ.with(|s| {
            s.set(s.get() + 1);
            s.get()
        });
        let worker = match origin {
            Origin::Http(base) if options.workers => next_worker().map(|w| (w, base)),
            _ => None,
        };
        let abort = match worker {
            Some(((index, worker), base)) => {
                let message = js_sys::Object::new();
                set(&message, "kind", &"read".into());
                set(&message, "id", &(seq as f64).into());
                // Absolute: the worker resolves against its script's URL.
                let base = web_sys::Url::new_with_base(base, &page_url())
                    .map_or_else(|_| base.clone(), |u| u.href());
                set(&message, "base", &base.into());
                set(&message, "level", &page.level.into());
                set(&message, "cx", &page.cx.into());
                set(&message, "cy", &page.cy.into());
                set(&message, "timeoutMs", &options.timeout_ms.into());
                if let Err(e) = worker.post_message(&message) {
                    worker_failed(index, &describe(&e));
                    remote.deliver(
                        page,
                        Err(format!("the decoding worker failed: {}", describe(&e))),
                        0,
                    );
                    continue;
                }
                SENT.with(|s| {
                    s.borrow_mut().insert(
                        seq,
                        Sent {
                            remote: remote.clone(),
                            origin: origin.clone(),
                            options,
                            page,
                        },
                    )
                });
                Abort::Worker(worker, seq)
            }
            None => {
                let Ok(controller) = web_sys::AbortController::new() else {
                    remote.deliver(page, Err("no AbortController".into()), 0);
                    continue;
                };
                let signal = controller.signal();
                let (remote, origin) = (remote.clone(), origin.clone());
                wasm_bindgen_futures::spawn_local(async move {
                    let read = read_page(&origin, page, &signal, options.timeout_ms).await;
                    finish(&remote, &origin, options, page, seq, read, false);
                });
                Abort::Here(controller)
            }
        };
        // The timeout aborts through the same path as a cancel.
        let timer = abort_after(abort.clone(), options.timeout_ms);
        FLIGHTS.with(|f| f.borrow_mut().insert(page.id, Flight { seq, abort, timer }));
    }
}

/// The page's own URL (`location.href`).
fn page_url() -> String {
    web_sys::window()
        .and_then(|w| w.location().href().ok())
        .unwrap_or_default()
}

/// A timer that aborts a read after `ms` (its handle, to clear).
fn abort_after(abort: Abort, ms: u32) -> Option<i32> {
    let on_timeout = Closure::once_into_js(move || abort.abort());
    web_sys::window().and_then(|w| {
        w.set_timeout_with_callback_and_timeout_and_arguments_0(
            on_timeout.unchecked_ref(),
            i32::try_from(ms).unwrap_or(i32::MAX),
        )
        .ok()
    })
}

fn clear_timer(timer: Option<i32>) {
    if let (Some(w), Some(t)) = (web_sys::window(), timer) {
        w.clear_timeout_with_handle(t);
    }
}

/// Read `seq` of `page` ended (`in_worker`: its bytes checked and inflated
/// there): delivered unless it was cancelled meanwhile (its flight gone,
/// or the page asked for again by a newer read); then the next reads start.
fn finish(
    remote: &Arc<RemoteChunks>,
    origin: &Origin,
    options: PumpOptions,
    page: PageRef,
    seq: u64,
    read: Read,
    in_worker: bool,
) {
    let flight = FLIGHTS.with(|f| {
        let mut f = f.borrow_mut();
        if f.get(&page.id).is_some_and(|flight| flight.seq == seq) {
            f.remove(&page.id)
        } else {
            None
        }
    });
    let Some(flight) = flight else {
        return;
    };
    clear_timer(flight.timer);
    PAGE_THREAD.with(|t| {
        let mut t = t.get();
        t.ms += read.ms;
        t.pages += 1;
        t.in_workers += u64::from(in_worker);
        if in_worker {
            t.workers_ms += read.ms;
        }
        PAGE_THREAD.set(t);
    });
    remote.deliver(page, read.planes, read.bytes);
    publish(remote);
    // Start the next read at once rather than at the next tick.
    pump(remote, origin, options);
}

/// Read page (`cx`, `cy`) of `level` of the store at `base` in a worker
/// (`www/decode-worker.js` calls it): `{heights, metas, bytes}` (the planes
/// as `Uint8Array`s of their own, to transfer) or `{error, bytes}`.
#[wasm_bindgen(js_name = strataWorkerRead)]
pub async fn worker_read(
    base: String,
    level: u32,
    cx: u32,
    cy: u32,
    timeout_ms: u32,
    signal: web_sys::AbortSignal,
) -> JsValue {
    let page = PageRef {
        id: 0,
        level,
        cx,
        cy,
    };
    let read = read_page(&Origin::Http(base), page, &signal, timeout_ms).await;
    let answer = js_sys::Object::new();
    set(&answer, "bytes", &(read.bytes as f64).into());
    match read.planes {
        Ok((heights, metas)) => {
            set(
                &answer,
                "heights",
                &js_sys::Uint8Array::from(&heights[..]).into(),
            );
            set(
                &answer,
                "metas",
                &js_sys::Uint8Array::from(&metas[..]).into(),
            );
        }
        Err(error) => set(&answer, "error", &error.into()),
    }
    answer.into()
}

/// The stream's numbers in the page state (`stream`; `stream_decoder`'s
/// page-thread time).
fn publish(remote: &RemoteChunks) {
    if let Ok(value) = serde_json::to_value(remote.stats()) {
        strata_viewer::web::set_page_info("stream", value);
    }
    let t = PAGE_THREAD.with(|t| t.get());
    strata_viewer::web::set_page_info(
        "stream_page_thread",
        serde_json::json!({
            "ms": t.ms,
            "pages": t.pages,
            "in_workers": t.in_workers,
            "workers_ms": t.workers_ms,
        }),
    );
}
