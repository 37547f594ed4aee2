//! The page's entry point for the browser build of the viewer (see
//! `www/index.html`): read the URL's parameters, get the world (generated in
//! the page a band of rows at a time under a progress bar, or fetched with
//! `?level=URL`), then hand `strata_viewer` to the browser's event loop.
//! Errors and panics are shown in the page.
//!
//! URL parameters: `backend=webgl2`, `method=NAME`, `view=NAME`,
//! `NAME=SETTING` (a method's knobs: `voxel=X,Y,Z`, `ray=64`, `mesh=0.75`),
//! `size=WxH` (canvas), `scale=F` (picture / canvas), `world=WxH` and
//! `seed=N` (the generated world), `level=URL` (a world directory or a
//! store; a store's chunks with `chunk-timeout-ms=MS` and `decode=main` to
//! decode them on the page's thread, see `stream.rs`), `compare` (the
//! quick protocol instead of the viewer; `views=A,B` to narrow it; see
//! `compare.rs`).
//!
//! The same module also runs in the page's decoding workers
//! (`www/decode-worker.js`), where there is no window: there it only
//! answers `stream::worker_read`.
#![cfg(target_arch = "wasm32")]

mod compare;
mod page;
mod progress;
mod stream;

use wasm_bindgen::prelude::*;

/// Runs when the module is instantiated (in a decoding worker: nothing
/// but a panic hook that logs).
#[wasm_bindgen(start)]
pub fn main() {
    if web_sys::window().is_none() {
        std::panic::set_hook(Box::new(|info| {
            web_sys::console::error_1(&format!("Strata's decoding worker panicked: {info}").into());
        }));
        return;
    }
    std::panic::set_hook(Box::new(|info| {
        strata_viewer::web::show_error(&format!("Strata panicked: {info}"));
    }));
    wasm_bindgen_futures::spawn_local(async {
        if let Err(error) = page::run().await {
            strata_viewer::web::show_error(&format!("{error:#}"));
        }
    });
}

/// Queue viewer script commands (the `--script` language, one per line);
/// returns the count the state's `taken` reaches once the viewer has them.
#[wasm_bindgen(js_name = strataRun)]
pub fn strata_run(text: &str) -> Result<u32, JsValue> {
    strata_viewer::web::push_commands(text).map_err(|e| JsValue::from_str(&format!("{e:#}")))
}

/// The viewer's state after its last frame, JSON (see the viewer's `page_state`).
#[wasm_bindgen(js_name = strataState)]
pub fn strata_state() -> String {
    strata_viewer::web::state()
}

/// The results file (`results-<adapter>.json`) of a finished `?compare`
/// run; `undefined` before it finishes.
#[wasm_bindgen(js_name = strataResults)]
pub fn strata_results() -> Option<String> {
    compare::results_json()
}
