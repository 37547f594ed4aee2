//! `strata view`: a window onto a level. Fly around it, switch between the
//! methods live (each built on first use in the background, then kept), dig
//! craters with the mouse and undo them, compare two methods side by side,
//! and read frame rate, GPU time per pass and memory off an overlay. A
//! script (`--script`) drives the same window without a person.
//!
//! Everything is drawn through the harness's [`strata_render::Renderer`],
//! so what the window shows is what `strata compare` measures.
//!
//! Modules: [`fly`] (camera), [`dig`] (pick, crater, undo), [`knobs`]
//! (settings), [`minimap`], [`script`], [`physics`] (the rigid-body toy;
//! `bodies` draws it),
//! [`builds`] (background method builds), [`save`] (Ctrl+S), [`paged`] (stores and
//! `--gpu-budget`: paged terrain, digging through an edit layer), [`present`] (picture to window),
//! [`overlay`] (egui), [`viewer`] (state and frame), and here the event loop.
//!
//! Stability: this crate is the `strata view` window and the web page, not a library API. Its public items
//! serve the `strata` binary and the tests and may change between
//! revisions; the embedding API is `strata-render` with the GPU-free crates
//! (`strata-level`, `strata-camera`, `strata-mesh`, `strata-reference`,
//! `strata-collide`, `strata-physics`, `strata-export`), which are documented
//! item by item (`#![warn(missing_docs)]`).

#[cfg(not(target_arch = "wasm32"))]
pub mod bodies;
pub mod builds;
pub mod dig;
pub mod fly;
pub mod knobs;
pub mod minimap;
pub mod overlay;
#[cfg(target_arch = "wasm32")]
mod page;
pub mod paged;
pub mod physics;
pub mod platform;
pub mod present;
pub mod save;
pub mod script;
pub mod viewer;
#[cfg(target_arch = "wasm32")]
pub mod web;
#[cfg(not(target_arch = "wasm32"))]
pub mod x_display;

use std::path::PathBuf;
use strata_level::World;
use strata_render::MethodSettings;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::window::WindowId;

pub use overlay::CONTROLS;
pub use script::Script;

/// How to open the viewer.
pub struct Options {
    pub world: World,
    /// The method to draw (built in the background while `ray` shows).
    pub method: String,
    /// Settings methods are built with (the overlay changes them).
    pub settings: MethodSettings,
    /// The window's inner size at start, pixels.
    pub size: (u32, u32),
    /// Picture size as a fraction of the window's; `None`: 1, or 0.5 on a CPU adapter.
    pub render_scale: Option<f32>,
    /// The level's view to start at (default: its first).
    pub view: Option<String>,
    pub script: Option<Script>,
    pub vsync: bool,
    /// The backend and adapter to draw on (`--backend`, `--adapter`).
    pub adapter: strata_render::AdapterChoice,
    /// The renderer's measuring switches and test hooks (the CLI's, from
    /// the environment; the page's are the defaults).
    pub render: strata_render::RenderOptions,
    /// Where screenshots taken with P or the overlay go.
    pub out: PathBuf,
    /// Where Ctrl+S and script `save` may write the edited world.
    pub save: save::SaveOptions,
    /// Start with the physics toy on (key O toggles it).
    pub physics: bool,
    /// Draw through paged terrain (issue 33): `world`'s level is then a
    /// stand-in and the map is read from these pages as the view needs them.
    pub paged: Option<paged::PagedWorld>,
}

/// Open the window and run until it is closed or the script ends.
#[cfg(not(target_arch = "wasm32"))]
pub fn run(options: Options) -> anyhow::Result<()> {
    use anyhow::Context;
    let event_loop = winit::event_loop::EventLoop::new().context(
        "cannot open a window: no display (set DISPLAY or WAYLAND_DISPLAY, or run under Xvfb)",
    )?;
    let mut app = App {
        options: Some(options),
        display: event_loop.owned_display_handle(),
        viewer: None,
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    match app.error {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

/// Natively: the window, then the device (blocking), then the viewer.
#[cfg(not(target_arch = "wasm32"))]
struct App {
    options: Option<Options>,
    display: winit::event_loop::OwnedDisplayHandle,
    viewer: Option<viewer::Viewer>,
    error: Option<anyhow::Error>,
}

#[cfg(not(target_arch = "wasm32"))]
impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) {
        let Some(options) = self.options.take() else {
            return;
        };
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            self.display.clone(),
        ));
        desc.backends = options.adapter.backend.backends();
        desc.flags = strata_render::adapter::instance_flags(desc.flags);
        let instance = wgpu::Instance::new(desc);
        let opened = viewer::Viewer::open_window(event_loop, &options, &instance).and_then(
            |(window, surface)| {
                let gpu =
                    strata_render::Gpu::with_instance(instance, Some(&surface), &options.adapter)?;
                viewer::Viewer::new(window, surface, gpu, options)
            },
        );
        self.opened(event_loop, opened);
    }

    fn finish(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(viewer) = &self.viewer {
            eprintln!("strata view: {}", viewer.summary());
        }
        self.viewer = None;
        event_loop.exit();
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        eprintln!("strata view: stopping: {error:#}");
        // The level lives on the CPU: a lost device loses no edits.
        if let Some(viewer) = &mut self.viewer {
            viewer.rescue();
        }
        self.error.get_or_insert(error);
        // Drop the window and GPU state before the loop ends.
        self.viewer = None;
        event_loop.exit();
    }

    /// Nothing to wait for natively: the device came in `open`.
    fn poll_opening(&mut self, _: &ActiveEventLoop) {}
}

/// In a browser: the window, the device awaited (see [`web`]), the viewer.
#[cfg(target_arch = "wasm32")]
struct App {
    options: Option<Options>,
    backend: web::Backend,
    opening: Option<web::Opening>,
    viewer: Option<viewer::Viewer>,
    error: Option<anyhow::Error>,
}

impl App {
    fn opened(&mut self, event_loop: &ActiveEventLoop, opened: anyhow::Result<viewer::Viewer>) {
        match opened {
            Ok(viewer) => {
                viewer.window().request_redraw();
                self.viewer = Some(viewer);
            }
            Err(error) => self.fail(event_loop, error),
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        self.open(event_loop);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(viewer) = &mut self.viewer else {
            return;
        };
        let result = viewer.on_window_event(&event);
        let quit = viewer.should_quit();
        match result {
            Err(error) => self.fail(event_loop, error),
            Ok(()) if quit => self.finish(event_loop),
            Ok(()) => {}
        }
    }

    fn device_event(
        &mut self,
        _: &ActiveEventLoop,
        _: winit::event::DeviceId,
        event: winit::event::DeviceEvent,
    ) {
        if let (Some(viewer), winit::event::DeviceEvent::MouseMotion { delta }) =
            (&mut self.viewer, event)
        {
            viewer.on_mouse_motion(delta.0, delta.1);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        self.poll_opening(event_loop);
        // Draw continuously (the frame rate is part of what is shown), except
        // where the viewer asks to wait.
        let Some(viewer) = &self.viewer else { return };
        match viewer.next_frame_due() {
            Some(at) if at > web_time::Instant::now() => {
                event_loop.set_control_flow(ControlFlow::WaitUntil(at));
            }
            _ => {
                event_loop.set_control_flow(ControlFlow::Poll);
                viewer.window().request_redraw();
            }
        }
    }
}
