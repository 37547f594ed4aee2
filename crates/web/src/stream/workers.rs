//! The decoding Web Workers of a streamed store ([`super::WORKERS`] of
//! them, `www/decode-worker.js`): started once after the first frame, each
//! handed this wasm module to instantiate; reads go to a ready one in turn,
//! and a worker that fails sends every read back to the page's thread.

use super::{Read, SENT, Sent, WORKERS, clock_ms, describe, get, set};
use std::cell::RefCell;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

/// The worker script, next to `index.html` (`crates/web/build.sh` copies it).
const WORKER_SCRIPT: &str = "decode-worker.js";

thread_local! {
    /// The decoding workers (created with the first streamed URL's pump).
    static POOL: RefCell<Option<Pool>> = const { RefCell::new(None) };
}

/// Whether the workers were started (or tried).
pub(super) fn started() -> bool {
    POOL.with(|p| p.borrow().is_some())
}

/// The decoding workers: each is used once it said it is ready.
struct Pool {
    workers: Vec<web_sys::Worker>,
    ready: Vec<bool>,
    next: usize,
    /// Why reads run on the page's thread now (none while a worker can take them).
    broken: Option<String>,
}

/// Where chunks are decoded, in the page state (`stream_decoder`) and the console.
pub(super) fn decoder_info(place: &str, why: Option<String>) {
    let text = match &why {
        Some(why) => format!("strata: chunks are decoded on the {place} ({why})"),
        None => format!("strata: chunks are decoded in {WORKERS} Web Workers"),
    };
    web_sys::console::log_1(&text.into());
    strata_viewer::web::set_page_info(
        "stream_decoder",
        serde_json::json!({ "where": place, "why": why }),
    );
}

/// Start the decoding workers once (they serve every store the page opens).
pub(super) fn start_workers() {
    if POOL.with(|p| p.borrow().is_some()) {
        return;
    }
    let pool = match spawn_workers() {
        Ok(workers) => {
            // Reads run here until a worker says it is ready.
            decoder_info("main thread", Some("the workers are starting".into()));
            Pool {
                ready: vec![false; workers.len()],
                workers,
                next: 0,
                broken: None,
            }
        }
        Err(why) => {
            decoder_info("main thread", Some(why.clone()));
            Pool {
                workers: Vec::new(),
                ready: Vec::new(),
                next: 0,
                broken: Some(why),
            }
        }
    };
    POOL.with(|p| *p.borrow_mut() = Some(pool));
}

/// [`WORKERS`] module workers running [`WORKER_SCRIPT`], each handed this
/// wasm module (compiled once) to instantiate.
fn spawn_workers() -> Result<Vec<web_sys::Worker>, String> {
    let options = web_sys::WorkerOptions::new();
    options.set_type(web_sys::WorkerType::Module);
    let mut workers = Vec::new();
    for index in 0..WORKERS {
        let worker = web_sys::Worker::new_with_options(WORKER_SCRIPT, &options)
            .map_err(|e| format!("no Web Worker: {}", describe(&e)))?;
        let on_message = Closure::<dyn FnMut(web_sys::MessageEvent)>::new(
            move |event: web_sys::MessageEvent| from_worker(index, &event.data()),
        );
        worker.set_onmessage(Some(on_message.as_ref().unchecked_ref()));
        on_message.forget();
        let on_error = Closure::<dyn FnMut(web_sys::Event)>::new(move |event: web_sys::Event| {
            let message = get(&event, "message")
                .as_string()
                .unwrap_or_else(|| format!("{WORKER_SCRIPT} did not load"));
            worker_failed(index, &message);
        });
        worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
        on_error.forget();
        let init = js_sys::Object::new();
        set(&init, "kind", &"init".into());
        set(&init, "module", &wasm_bindgen::module());
        worker
            .post_message(&init)
            .map_err(|e| format!("the worker takes no module: {}", describe(&e)))?;
        workers.push(worker);
    }
    Ok(workers)
}

/// A worker's message: `ready`, `failed`, or a read's answer.
fn from_worker(index: usize, data: &JsValue) {
    match get(data, "kind").as_string().as_deref() {
        Some("ready") => {
            let first = POOL.with(|p| {
                let mut p = p.borrow_mut();
                let Some(pool) = p.as_mut().filter(|pool| pool.broken.is_none()) else {
                    return false;
                };
                let first = !pool.ready.contains(&true);
                pool.ready[index] = true;
                first
            });
            if first {
                decoder_info("worker", None);
            }
        }
        Some("failed") => {
            let why = get(data, "error").as_string().unwrap_or_default();
            worker_failed(index, &why);
        }
        _ => {
            let seq = get(data, "id").as_f64().unwrap_or(-1.0) as u64;
            let Some(sent) = SENT.with(|s| s.borrow_mut().remove(&seq)) else {
                return;
            };
            let start = clock_ms();
            let planes = match get(data, "error").as_string() {
                Some(error) => Err(error),
                None => {
                    let plane = |key| js_sys::Uint8Array::new(&get(data, key)).to_vec();
                    Ok((plane("heights"), plane("metas")))
                }
            };
            let read = Read {
                planes,
                bytes: get(data, "bytes").as_f64().unwrap_or(0.0) as u64,
                ms: clock_ms() - start,
            };
            sent.finish(seq, read);
        }
    }
}

/// Worker `index` failed (its script did not load, the module did not
/// instantiate, or it stopped): from now on reads run on the page's thread,
/// and those it had fail (the paged terrain retries them).
pub(super) fn worker_failed(index: usize, why: &str) {
    let why = format!("decoding worker {index} failed: {why}");
    let newly = POOL.with(|p| {
        let mut p = p.borrow_mut();
        let pool = p.as_mut()?;
        for worker in &pool.workers {
            worker.terminate();
        }
        pool.ready.iter_mut().for_each(|r| *r = false);
        pool.broken
            .is_none()
            .then(|| pool.broken = Some(why.clone()))
    });
    if newly.is_some() {
        decoder_info("main thread", Some(why.clone()));
    }
    let lost: Vec<(u64, Sent)> = SENT.with(|s| s.borrow_mut().drain().collect());
    for (seq, sent) in lost {
        let read = Read {
            planes: Err(why.clone()),
            bytes: 0,
            ms: 0.0,
        };
        sent.finish(seq, read);
    }
}

/// A ready worker to hand the next read to (round robin), if any.
pub(super) fn next_worker() -> Option<(usize, web_sys::Worker)> {
    POOL.with(|p| {
        let mut p = p.borrow_mut();
        let pool = p.as_mut().filter(|pool| pool.broken.is_none())?;
        let n = pool.workers.len();
        (0..n).find_map(|k| {
            let i = (pool.next + k) % n;
            pool.ready[i].then(|| {
                pool.next = i + 1;
                (i, pool.workers[i].clone())
            })
        })
    })
}
