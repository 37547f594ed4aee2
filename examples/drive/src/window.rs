//! The windowed mode: your window, your surface, your depth texture; Strata
//! draws into the surface's own colour view and that depth texture, then
//! the vehicle is drawn over them.

use std::sync::Arc;
use std::time::Instant;
use strata_example_drive::{DEPTH, Drive, open_gpu};
use strata_render::{COLOR_TARGET_FORMATS, Gpu};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

/// Open the window and drive until it is closed.
pub fn run(method: &str, size: (u32, u32), seconds: Option<f32>) -> anyhow::Result<()> {
    let no_display =
        std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none();
    let event_loop = EventLoop::new().map_err(|e| {
        let why = match no_display {
            true => "no display (DISPLAY and WAYLAND_DISPLAY are unset)".to_string(),
            false => e.to_string(),
        };
        anyhow::anyhow!("cannot open a window: {why}; run headless with --frames N --out DIR")
    })?;
    let mut app = App {
        method: method.to_string(),
        size,
        seconds,
        state: None,
        error: None,
        display: event_loop.owned_display_handle(),
    };
    event_loop.run_app(&mut app)?;
    app.error.map_or(Ok(()), Err)
}

struct App {
    method: String,
    size: (u32, u32),
    seconds: Option<f32>,
    state: Option<State>,
    error: Option<anyhow::Error>,
    display: winit::event_loop::OwnedDisplayHandle,
}

/// Everything that lives while the window is open.
struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    drive: Drive,
    depth: wgpu::TextureView,
    start: Instant,
    frames: u32,
}

fn depth_view(device: &wgpu::Device, size: (u32, u32)) -> wgpu::TextureView {
    strata_example_drive::target(
        device,
        "window depth",
        size,
        DEPTH,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    )
    .create_view(&Default::default())
}

impl State {
    fn open(app: &App, event_loop: &ActiveEventLoop) -> anyhow::Result<Self> {
        let attributes = Window::default_attributes()
            .with_title(format!("Strata drive: {}", app.method))
            .with_inner_size(winit::dpi::PhysicalSize::new(app.size.0, app.size.1));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(app.display.clone()),
            ));
        let surface = instance.create_surface(Arc::clone(&window))?;
        let gpu = open_gpu(instance, Some(&surface))?;
        let inner = window.inner_size();
        let size = (inner.width.max(1), inner.height.max(1));
        // The surface's own format, if render_into draws into it.
        let offered = surface.get_capabilities(&gpu.adapter).formats;
        let format = offered
            .iter()
            .copied()
            .find(|f| COLOR_TARGET_FORMATS.contains(f))
            .ok_or_else(|| {
                anyhow::anyhow!("the window offers none of render_into's formats: {offered:?}")
            })?;
        let mut config = surface
            .get_default_config(&gpu.adapter, size.0, size.1)
            .ok_or_else(|| anyhow::anyhow!("this adapter cannot present to the window"))?;
        config.format = format;
        surface.configure(&gpu.device, &config);
        let drive = Drive::new(&gpu, &app.method, format, size)?;
        let depth = depth_view(&gpu.device, size);
        window.request_redraw();
        Ok(State {
            window,
            surface,
            config,
            drive,
            depth,
            gpu,
            start: Instant::now(),
            frames: 0,
        })
    }

    fn resize(&mut self, size: (u32, u32)) -> anyhow::Result<()> {
        let size = (size.0.max(1), size.1.max(1));
        (self.config.width, self.config.height) = size;
        self.surface.configure(&self.gpu.device, &self.config);
        self.depth = depth_view(&self.gpu.device, size);
        self.drive.resize(size)
    }

    fn redraw(&mut self) -> anyhow::Result<()> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.gpu.device, &self.config);
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                anyhow::bail!("the window's swapchain refused a frame")
            }
        };
        let color = frame.texture.create_view(&Default::default());
        // Back and forth along the road, 12 s each way.
        let phase = (self.start.elapsed().as_secs_f32() / 12.0) % 2.0;
        let t = if phase < 1.0 { phase } else { 2.0 - phase };
        self.drive.draw(Some(t), &color, None, &self.depth)?;
        self.window.pre_present_notify();
        self.gpu.queue.present(frame);
        self.frames += 1;
        self.window.request_redraw();
        Ok(())
    }
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        eprintln!("drive: {error:#}");
        self.error = Some(error);
        self.state = None;
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_none() {
            match State::open(self, event_loop) {
                Ok(state) => self.state = Some(state),
                Err(e) => self.fail(event_loop, e),
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(state) = &mut self.state else { return };
        let result = match event {
            WindowEvent::CloseRequested => {
                self.state = None;
                event_loop.exit();
                return;
            }
            WindowEvent::Resized(size) => state.resize((size.width, size.height)),
            WindowEvent::RedrawRequested
                if self
                    .seconds
                    .is_some_and(|s| state.start.elapsed().as_secs_f32() >= s) =>
            {
                let secs = state.start.elapsed().as_secs_f32();
                println!(
                    "drive: {} frames in {secs:.1} s ({} into {:?} + {DEPTH:?})",
                    state.frames, self.method, state.config.format
                );
                self.state = None;
                event_loop.exit();
                return;
            }
            WindowEvent::RedrawRequested => state.redraw(),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }
}
