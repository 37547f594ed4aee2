//! The page's progress bar and its line, and yielding to the browser: what
//! the viewer's page and `?compare` both show while they work.

use wasm_bindgen::JsCast;
use wasm_bindgen_futures::JsFuture;

/// Let the browser paint and handle input.
pub async fn yield_to_browser() {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        if let Some(window) = web_sys::window() {
            let _ = window.set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, 0);
        }
    });
    let _ = JsFuture::from(promise).await;
}

/// Show (or with `None` hide) the page's progress bar and its line.
pub fn progress(fraction: Option<f64>, text: &str) {
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    if let Some(bar) = document
        .get_element_by_id("strata-progress")
        .and_then(|e| e.dyn_into::<web_sys::HtmlProgressElement>().ok())
    {
        match fraction {
            Some(f) => {
                bar.set_value(f);
                let _ = bar.set_attribute("style", "display: inline-block");
            }
            None => {
                let _ = bar.set_attribute("style", "display: none");
            }
        }
    }
    if let Some(line) = document.get_element_by_id("strata-status") {
        line.set_text_content(Some(text));
    }
}
