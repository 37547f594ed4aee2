//! A Strata store streamed over HTTP (issue 34): only the metadata up front
//! (the root `zarr.json` with the world's attributes, the planes' and the
//! summary's `zarr.json`, the summary's chunks for the coarse level), then
//! chunk objects fetched as the paged terrain asks for them.
//!
//! The seam to the renderer is [`RemoteChunks`]: the streamer tells it each
//! frame what it wants; the pump here, run by a timer (no threads in the
//! page), starts `fetch`es up to the cap ([`MOST_IN_FLIGHT`] pages, two
//! requests each), aborts those the camera no longer wants
//! (`AbortController`), gives up on a request after [`TIMEOUT_MS`], and
//! hands the decoded planes (gzip inflated and the crc32c checked on the
//! page's thread: `strata_store::http`) or the error back. The paged
//! terrain retries a failed chunk `read_tries` times, then reports it;
//! resident pages keep drawing.

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

/// Pages fetched at a time (two requests each: Chromium opens six
/// connections per host over HTTP/1.1).
pub const MOST_IN_FLIGHT: usize = 3;
/// A request not answered in this time is aborted and counts as failed.
pub const TIMEOUT_MS: i32 = 10_000;
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

    /// Object `key` (`heights/c/3/1`), `None` when there is none.
    async fn get(
        &self,
        key: &str,
        signal: Option<&web_sys::AbortSignal>,
    ) -> Result<Option<Vec<u8>>, String> {
        match self {
            Origin::Http(base) => {
                let url = format!("{base}{key}");
                match signal {
                    Some(signal) => fetch_with(&url, signal).await,
                    None => fetch(&url).await.map_err(|e| format!("{e:#}")),
                }
            }
            Origin::Picked { files, .. } => {
                let Some(file) = files.get(key) else {
                    return Ok(None);
                };
                let buffer = JsFuture::from(file.array_buffer())
                    .await
                    .map_err(|e| format!("reading {key}: {}", describe(&e)))?;
                Ok(Some(js_sys::Uint8Array::new(&buffer).to_vec()))
            }
        }
    }

    /// Object `key`, which the store must have.
    async fn required(
        &self,
        key: &str,
        signal: Option<&web_sys::AbortSignal>,
    ) -> Result<Vec<u8>, String> {
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

/// The chunk objects of page `page`, fetched and decoded.
async fn read_page(
    origin: &Origin,
    page: PageRef,
    signal: &web_sys::AbortSignal,
) -> (Result<strata_render::paged::Planes, String>, u64) {
    let cell = [u64::from(page.cy), u64::from(page.cx)];
    let prefix = if page.level == 0 {
        String::new()
    } else {
        format!("lod/{}/", page.level)
    };
    let mut bytes = 0u64;
    // Both requests go out before either is awaited.
    let requests = [HEIGHTS, METAS].map(|name| {
        let key = format!("{prefix}{}", http::chunk_key(name, &cell));
        let request = {
            let (origin, key) = (origin.clone(), key.clone());
            async move { origin.required(&key, Some(signal)).await }
        };
        (name, format!("{}{key}", origin.label()), request)
    });
    let mut planes = Vec::new();
    for (name, url, request) in requests {
        let raw = match request.await {
            Ok(raw) => raw,
            Err(e) => return (Err(e), bytes),
        };
        bytes += raw.len() as u64;
        let array = format!("{prefix}{name}");
        match http::decode_chunk(&array, &cell, &raw, (PAGE * PAGE) as usize) {
            Ok(plane) => planes.push(plane),
            Err(e) => return (Err(format!("{url}: {e}")), bytes),
        }
    }
    let metas = planes.pop().unwrap_or_default();
    let heights = planes.pop().unwrap_or_default();
    (Ok((heights, metas)), bytes)
}

/// GET `url` with `signal`: its bytes, `None` on 404, or why not.
async fn fetch_with(url: &str, signal: &web_sys::AbortSignal) -> Result<Option<Vec<u8>>, String> {
    let window = web_sys::window().ok_or("no window")?;
    let init = web_sys::RequestInit::new();
    init.set_signal(Some(signal));
    let response = JsFuture::from(window.fetch_with_str_and_init(url, &init))
        .await
        .map_err(|e| {
            if signal.aborted() {
                format!("GET {url}: no answer in {} s (aborted)", TIMEOUT_MS / 1000)
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
            format!(
                "GET {url}: body cut off: no answer in {} s",
                TIMEOUT_MS / 1000
            )
        } else {
            format!("GET {url}: reading the body failed: {}", describe(&e))
        }
    })?;
    Ok(Some(js_sys::Uint8Array::new(&buffer).to_vec()))
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
    /// The abort controllers of reads in flight, by page id.
    static FLIGHTS: RefCell<HashMap<u32, (u64, web_sys::AbortController)>> = RefCell::new(HashMap::new());
    /// The pump's interval timer.
    static PUMP: std::cell::Cell<Option<i32>> = const { std::cell::Cell::new(None) };
    /// Numbers the reads, so a cancelled one's late answer is told apart.
    static SEQ: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Fetch the chunk under map point (`x`, `y`) now and keep it (the viewer
/// places a view's camera on the column there).
pub async fn prefetch_at(
    origin: &Origin,
    remote: &RemoteChunks,
    x: f32,
    y: f32,
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
    let (planes, _) = read_page(origin, page, &controller.signal()).await;
    let planes = planes.map_err(|e| anyhow::anyhow!("the chunk under a view: {e}"))?;
    remote.pin(0, cx, cy, planes);
    Ok(())
}

/// Run the pump for `remote` (every few milliseconds, until another store
/// is opened).
pub fn start_pump(remote: Arc<RemoteChunks>, origin: Origin) {
    let tick = Closure::<dyn FnMut()>::new(move || pump(&remote, &origin));
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

fn pump(remote: &Arc<RemoteChunks>, origin: &Origin) {
    for id in remote.take_cancelled() {
        if let Some((_, c)) = FLIGHTS.with(|f| f.borrow_mut().remove(&id)) {
            c.abort();
        }
    }
    for page in remote.start() {
        let Ok(controller) = web_sys::AbortController::new() else {
            remote.deliver(page, Err("no AbortController".into()), 0);
            continue;
        };
        let signal = controller.signal();
        // The timeout aborts through the same controller.
        let on_timeout = {
            let c = controller.clone();
            Closure::once_into_js(move || c.abort())
        };
        let timer = web_sys::window().and_then(|w| {
            w.set_timeout_with_callback_and_timeout_and_arguments_0(
                on_timeout.unchecked_ref(),
                TIMEOUT_MS,
            )
            .ok()
        });
        let seq = SEQ.with(|s| {
            s.set(s.get() + 1);
            s.get()
        });
        FLIGHTS.with(|f| f.borrow_mut().insert(page.id, (seq, controller)));
        let (remote, origin) = (remote.clone(), origin.clone());
        wasm_bindgen_futures::spawn_local(async move {
            let (planes, bytes) = read_page(&origin, page, &signal).await;
            if let (Some(w), Some(t)) = (web_sys::window(), timer) {
                w.clear_timeout_with_handle(t);
            }
            // A read cancelled meanwhile (its controller gone, or the page
            // asked for again by a newer read) says nothing.
            let ours = FLIGHTS.with(|f| {
                let mut f = f.borrow_mut();
                let ours = f.get(&page.id).is_some_and(|(s, _)| *s == seq);
                if ours {
                    f.remove(&page.id);
                }
                ours
            });
            if !ours {
                return;
            }
            remote.deliver(page, planes, bytes);
            publish(&remote);
            // Start the next read at once rather than at the next tick.
            pump(&remote, &origin);
        });
    }
}

/// The stream's numbers in the page state (`stream`).
fn publish(remote: &RemoteChunks) {
    if let Ok(value) = serde_json::to_value(remote.stats()) {
        strata_viewer::web::set_page_info("stream", value);
    }
}
