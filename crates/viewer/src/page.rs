//! The page the viewer runs in (wasm32): its canvas, its error line, the
//! state the viewer publishes to the page's scripts (and the browser test),
//! the commands they push, and downloads. The platform object
//! (`platform.rs`) and the browser seams (`web.rs`) both use it.

use crate::Script;
use std::cell::RefCell;
use std::collections::VecDeque;
use wasm_bindgen::JsCast;
use winit::platform::web::WindowAttributesExtWebSys;
use winit::window::WindowAttributes;

/// The canvas the page provides for the viewer.
pub const CANVAS_ID: &str = "strata-canvas";
/// The element errors are written to.
pub const ERROR_ID: &str = "strata-error";

thread_local! {
    static COMMANDS: RefCell<VecDeque<Script>> = const { RefCell::new(VecDeque::new()) };
    static STATE: RefCell<String> = RefCell::new("{\"phase\":\"loading\"}".into());
    static FIRST_FRAME_MS: RefCell<Option<f64>> = const { RefCell::new(None) };
    /// Scripts pushed and taken by the viewer so far (a page script waits
    /// for `taken` to reach what its push returned, then for `idle`).
    static PUSHED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    static TAKEN: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
    /// What the page measured before the viewer started (world generation
    /// or download time), carried in every published state.
    static PAGE_INFO: RefCell<serde_json::Map<String, serde_json::Value>> = RefCell::new(serde_json::Map::new());
}

/// Remember a page measurement (shown in every published state).
pub fn set_page_info(key: &str, value: serde_json::Value) {
    PAGE_INFO.with(|p| p.borrow_mut().insert(key.to_string(), value));
}

/// Queue script commands (the `--script` language) for the viewer; a bad
/// line is refused whole, with its reason. Returns how many scripts have
/// been pushed so far (the state's `taken` reaches it once the viewer has
/// them).
pub fn push_commands(text: &str) -> anyhow::Result<u32> {
    let script = Script::parse(text)?;
    COMMANDS.with(|c| c.borrow_mut().push_back(script));
    PUSHED.set(PUSHED.get() + 1);
    Ok(PUSHED.get())
}

/// Commands queued since the last frame.
pub fn take_commands() -> Vec<Script> {
    let taken: Vec<Script> = COMMANDS.with(|c| c.borrow_mut().drain(..).collect());
    TAKEN.set(TAKEN.get() + taken.len() as u32);
    taken
}

/// The viewer's last published state, JSON.
pub fn state() -> String {
    STATE.with(|s| s.borrow().clone())
}

/// Publish the state (once per frame).
pub fn publish(mut state: serde_json::Value, frames: u64) {
    if frames > 0 {
        let first = FIRST_FRAME_MS.with(|f| *f.borrow_mut().get_or_insert_with(now_ms));
        state["page_to_first_frame_ms"] = first.into();
    }
    state["taken"] = TAKEN.get().into();
    PAGE_INFO.with(|p| {
        for (k, v) in p.borrow().iter() {
            state[k] = v.clone();
        }
    });
    set_state(state);
}

/// Replace the published state (the page's loading phases use this too).
pub fn set_state(state: serde_json::Value) {
    STATE.with(|s| *s.borrow_mut() = state.to_string());
}

/// Milliseconds since the page started loading.
pub fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or(0.0, |p| p.now())
}

/// Show an error in the page (and the console, and the state the page's
/// scripts read).
pub fn show_error(message: &str) {
    web_sys::console::error_1(&message.into());
    if let Some(element) = document().and_then(|d| d.get_element_by_id(ERROR_ID)) {
        element.set_text_content(Some(message));
        let _ = element.set_attribute("style", "display: block");
    }
    STATE.with(|s| {
        let mut state: serde_json::Value =
            serde_json::from_str(&s.borrow()).unwrap_or_else(|_| serde_json::json!({}));
        state["error"] = message.into();
        *s.borrow_mut() = state.to_string();
    });
}

/// Show `message` on the page's status line (above the canvas): news that
/// is not an error of the page, such as chunks of a streamed store that
/// failed to read while the rest draws.
pub fn show_notice(message: &str) {
    web_sys::console::warn_1(&message.into());
    if let Some(line) = document().and_then(|d| d.get_element_by_id("strata-status")) {
        line.set_text_content(Some(message));
    }
}

/// Hide the page's error box (a new attempt is under way).
pub fn clear_error() {
    if let Some(element) = document().and_then(|d| d.get_element_by_id(ERROR_ID)) {
        element.set_text_content(None);
        let _ = element.set_attribute("style", "display: none");
    }
}

fn document() -> Option<web_sys::Document> {
    web_sys::window()?.document()
}

/// Offer `bytes` as a download named `name`.
pub fn download(name: &str, bytes: &[u8]) -> anyhow::Result<()> {
    let fail = |what: &str| anyhow::anyhow!("offering {name} for download: {what}");
    let array = js_sys::Uint8Array::from(bytes);
    let parts = js_sys::Array::of1(&array);
    let blob = web_sys::Blob::new_with_u8_array_sequence(&parts).map_err(|_| fail("no Blob"))?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(|_| fail("no URL"))?;
    let document = document().ok_or_else(|| fail("no document"))?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(|_| fail("no <a>"))?
        .dyn_into()
        .map_err(|_| fail("not an <a>"))?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    let _ = web_sys::Url::revoke_object_url(&url);
    Ok(())
}

/// The window is the page's canvas (or one appended to the body).
pub fn canvas_attributes(attributes: WindowAttributes) -> WindowAttributes {
    let canvas = document()
        .and_then(|d| d.get_element_by_id(CANVAS_ID))
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok());
    match canvas {
        Some(canvas) => attributes.with_canvas(Some(canvas)),
        None => attributes.with_append(true),
    }
}
