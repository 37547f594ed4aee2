//! The browser seams: the page's canvas as the window, the event loop handed
//! to the browser, the device requested asynchronously, a page script's
//! commands and the viewer's state through two JS functions, downloads
//! instead of files, and errors shown in the page.

use crate::viewer::Viewer;
use crate::{App, Options, Script};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;
use strata_render::Gpu;
use wasm_bindgen::JsCast;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::platform::web::{EventLoopExtWebSys, WindowAttributesExtWebSys};
use winit::window::{Window, WindowAttributes};

/// The canvas the page provides for the viewer.
pub const CANVAS_ID: &str = "strata-canvas";
/// The element errors are written to.
pub const ERROR_ID: &str = "strata-error";

/// Which browser API draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    WebGpu,
    WebGl2,
}

impl Backend {
    /// The wgpu backends an instance for this API uses.
    pub fn backends(self) -> wgpu::Backends {
        match self {
            Backend::WebGpu => wgpu::Backends::BROWSER_WEBGPU,
            Backend::WebGl2 => wgpu::Backends::GL,
        }
    }
}

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
    /// A world the page loaded (a picked folder) for the viewer to show next.
    static NEXT_WORLD: RefCell<Option<strata_level::World>> = const { RefCell::new(None) };
}

/// Show `world` in the viewer from its next frame on (the window, device,
/// method and settings stay; the camera goes to the world's first view).
pub fn open_world(world: strata_level::World) {
    NEXT_WORLD.with(|w| *w.borrow_mut() = Some(world));
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
pub(crate) fn take_commands() -> Vec<Script> {
    let taken: Vec<Script> = COMMANDS.with(|c| c.borrow_mut().drain(..).collect());
    TAKEN.set(TAKEN.get() + taken.len() as u32);
    taken
}

/// The viewer's last published state, JSON.
pub fn state() -> String {
    STATE.with(|s| s.borrow().clone())
}

/// Publish the state (once per frame).
pub(crate) fn publish(mut state: serde_json::Value, frames: u64) {
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
pub(crate) fn canvas_attributes(attributes: WindowAttributes) -> WindowAttributes {
    let canvas = document()
        .and_then(|d| d.get_element_by_id(CANVAS_ID))
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok());
    match canvas {
        Some(canvas) => attributes.with_canvas(Some(canvas)),
        None => attributes.with_append(true),
    }
}

/// Hand the viewer to the browser's event loop (returns at once; the page
/// then runs it).
pub fn start(options: Options, backend: Backend) -> anyhow::Result<()> {
    let event_loop =
        EventLoop::new().map_err(|e| anyhow::anyhow!("cannot start the page's event loop: {e}"))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    event_loop.spawn_app(App {
        options: Some(options),
        backend,
        opening: None,
        viewer: None,
        error: None,
    });
    Ok(())
}

type Device = anyhow::Result<(Gpu, wgpu::Surface<'static>)>;

/// The window while its device is requested.
pub(crate) struct Opening {
    window: std::sync::Arc<Window>,
    options: Options,
    device: Rc<RefCell<Option<Device>>>,
}

impl App {
    pub(crate) fn open(&mut self, event_loop: &ActiveEventLoop) {
        let Some(options) = self.options.take() else {
            return;
        };
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: self.backend.backends(),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let (window, surface) = match Viewer::open_window(event_loop, &options, &instance) {
            Ok(opened) => opened,
            Err(error) => return self.fail(event_loop, error),
        };
        let device = Rc::new(RefCell::new(None));
        let slot = Rc::clone(&device);
        let backend = self.backend;
        let choice = options.adapter;
        wasm_bindgen_futures::spawn_local(async move {
            let result = Gpu::with_instance_async(instance, Some(&surface), &choice)
                .await
                .map(|gpu| (gpu, surface))
                .map_err(|e| match backend {
                    Backend::WebGpu => e.context(
                        "no WebGPU adapter in this browser (navigator.gpu missing, or it \
                         refused the default limits); try ?backend=webgl2",
                    ),
                    Backend::WebGl2 => e.context("no WebGL2 context in this browser"),
                });
            *slot.borrow_mut() = Some(result);
        });
        self.opening = Some(Opening {
            window,
            options,
            device,
        });
    }

    /// Build the viewer once the device has come; swap in a world the page
    /// loaded since.
    pub(crate) fn poll_opening(&mut self, event_loop: &ActiveEventLoop) {
        self.poll_device(event_loop);
        if self.viewer.is_some()
            && let Some(world) = NEXT_WORLD.with(|w| w.borrow_mut().take())
            && let Some(viewer) = self.viewer.take()
        {
            let parts = viewer.hand_over();
            let inner = parts.window.inner_size();
            let options = Options {
                world,
                method: parts.method,
                settings: parts.settings,
                size: (inner.width.max(1), inner.height.max(1)),
                render_scale: Some(parts.render_scale),
                view: None,
                script: None,
                vsync: parts.vsync,
                adapter: Default::default(),
                out: parts.out,
                save: Default::default(),
                physics: false,
            };
            let opened = Viewer::new(parts.window, parts.surface, parts.gpu, options);
            self.opened(event_loop, opened);
        }
    }

    fn poll_device(&mut self, event_loop: &ActiveEventLoop) {
        let ready = self
            .opening
            .as_ref()
            .is_some_and(|o| o.device.borrow().is_some());
        if !ready {
            return;
        }
        let Some(opening) = self.opening.take() else {
            return;
        };
        let device = opening.device.borrow_mut().take();
        let opened = match device {
            Some(Ok((gpu, surface))) => Viewer::new(opening.window, surface, gpu, opening.options),
            Some(Err(error)) => Err(error),
            None => return,
        };
        self.opened(event_loop, opened);
    }

    /// A page has no end: the script's `quit` stops drawing.
    pub(crate) fn finish(&mut self, _: &ActiveEventLoop) {
        if let Some(viewer) = &self.viewer {
            web_sys::console::log_1(&viewer.summary().into());
        }
        self.viewer = None;
    }

    pub(crate) fn fail(&mut self, _: &ActiveEventLoop, error: anyhow::Error) {
        show_error(&format!("{error:#}"));
        self.viewer = None;
        self.error.get_or_insert(error);
    }
}
