//! The browser seams: the page's canvas as the window, the event loop handed
//! to the browser, the device requested asynchronously, a page script's
//! commands and the viewer's state through two JS functions, downloads
//! instead of files, and errors shown in the page.

use crate::viewer::Viewer;
use crate::{App, Options};
use std::cell::RefCell;
use std::rc::Rc;
use strata_render::Gpu;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::platform::web::EventLoopExtWebSys;
use winit::window::Window;

pub use crate::page::{
    CANVAS_ID, ERROR_ID, clear_error, download, now_ms, push_commands, set_page_info, set_state,
    show_error, state,
};

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

/// A world the page loaded for the viewer to show next, paged or not.
type NextWorld = (strata_level::World, Option<crate::paged::PagedWorld>);

thread_local! {
    /// A world the page loaded (a picked folder) for the viewer to show next.
    static NEXT_WORLD: RefCell<Option<NextWorld>> = const { RefCell::new(None) };
}

/// Show `world` in the viewer from its next frame on (the window, device,
/// method and settings stay; the camera goes to the world's first view).
pub fn open_world(world: strata_level::World) {
    NEXT_WORLD.with(|w| *w.borrow_mut() = Some((world, None)));
}

/// Show a paged world (a picked store, streamed) from the next frame on,
/// as [`open_world`] (`world` its files besides the map).
pub fn open_paged_world(world: strata_level::World, paged: crate::paged::PagedWorld) {
    NEXT_WORLD.with(|w| *w.borrow_mut() = Some((world, Some(paged))));
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
        let choice = options.adapter.clone();
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
            && let Some((world, paged)) = NEXT_WORLD.with(|w| w.borrow_mut().take())
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
                render: Default::default(),
                out: parts.out,
                save: Default::default(),
                physics: false,
                paged,
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
