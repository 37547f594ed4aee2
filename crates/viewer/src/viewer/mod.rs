//! The viewer's state and its frame: input to camera, script steps, finished
//! builds, the method (or A/B pair) drawn through the harness's
//! [`Renderer`], the overlay, and the swapchain. Input handling is in
//! `input`, method switching and knobs in `switching`, views and flying to a
//! point in `navigation`, script running in `scripted`, the score and screenshot
//! read-backs (finished a frame or more later) in `readback`, digging,
//! undo, saving and the memory report in `editing`.

mod editing;
mod input;
mod navigation;
mod paged;
mod readback;
mod scripted;
mod switching;

use crate::Options;
use crate::builds::Builds;
use crate::dig::Digger;
use crate::fly::FlyCamera;
use crate::minimap::Minimap;
use crate::overlay::{self, Action, Building, Drawn, Editable, Overlay, Status};
use crate::physics::PhysicsToy;
use crate::platform::Platform;
use crate::present::{Compositor, WINDOW_FORMAT};
use crate::save::Saver;
use anyhow::{Context, bail};
use readback::Scoring;
use scripted::Player;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{EditSite, Level, ViewSpec};
use strata_render::gpu::TextureReadback;
use strata_render::timing::PassTimer;
use strata_render::{FrameTimings, Gpu, MethodSettings, Renderer, TerrainColors, methods};
use web_time::Instant;
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::KeyCode;
use winit::window::Window;

/// The method the window opens with while the asked-for one is built: the
/// cheapest to set up.
const FIRST_METHOD: &str = "ray";
/// Redraw interval while a build runs on a CPU adapter and nothing moves.
const BUILD_FRAME_INTERVAL: std::time::Duration = std::time::Duration::from_millis(250);
/// Lines of the overlay's log kept.
const LOG_LINES: usize = 8;

/// Sums over the frames a method drew.
#[derive(Default)]
struct Totals {
    frames: u32,
    /// Frames with GPU timestamps (none on adapters without them).
    timed_frames: u32,
    gpu_ms: f64,
    wait_ms: f64,
}

pub struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    renderer: Renderer,
    compositor: Compositor,
    /// Times the viewer's own passes: compose, overlay, present.
    passes: PassTimer,
    overlay: Overlay,
    builds: Builds,
    level: Arc<Level>,
    /// The palette ramps, for the map.
    colors: TerrainColors,
    /// The level from above, repainted where it is dug.
    map: Minimap,
    views: Vec<ViewSpec>,
    digger: Digger,
    /// The rigid-body toy (key O).
    physics: PhysicsToy,
    fly: FlyCamera,
    /// Picture size over window size.
    render_scale: f32,
    /// The render size the window asks for, applied once no build holds
    /// the shared frame.
    resize_to: Option<(u32, u32)>,
    /// The settings methods are (re)built with; the overlay edits them.
    settings: MethodSettings,
    /// Drawn right of the active method in A/B mode.
    split: Option<String>,
    /// Where the A/B divider stands, fraction of the picture's width.
    split_at: f32,
    /// The method asked for while it is being built.
    waiting_for: Option<String>,
    previous_method: String,
    keys: HashSet<KeyCode>,
    ctrl: bool,
    shift: bool,
    cursor: Option<(f32, f32)>,
    looking: bool,
    /// The platform sends raw mouse motion (used for looking when it does).
    raw_motion: bool,
    last_frame: Instant,
    /// When `new` started (for the first-frame time).
    opened: Instant,
    frame_ms: f64,
    timings: Vec<(String, FrameTimings)>,
    /// The viewer's own passes in the last frame.
    window_timings: FrameTimings,
    totals: Vec<(String, Totals)>,
    log: Vec<String>,
    /// The last scores against the reference (method, metrics).
    scores: Vec<(String, strata_reference::Metrics)>,
    /// Scores finished so far (a script waits for the next one).
    scored: u32,
    /// Frames drawn since the window opened.
    frames: u64,
    player: Option<Player>,
    /// A score waiting for its depth read-backs (they complete a frame
    /// later: in a browser only once the page has yielded).
    scoring: Option<Scoring>,
    screenshot_after_frame: Option<PathBuf>,
    /// A screenshot waiting for its read-back.
    screenshot_reading: Option<(PathBuf, TextureReadback)>,
    screenshots: u32,
    out: PathBuf,
    /// The loaded world's other files, for saving the edited level.
    saver: Saver,
    /// Edits made since the world was loaded or last saved.
    unsaved: bool,
    quit: bool,
    /// Native window or browser page.
    platform: Platform,
    /// Paged terrain (issue 33): the world's pages and the undo of digs
    /// over them; `level` is then a stand-in.
    paged: Option<paged::PagedState>,
}

/// What a viewer leaves to the viewer of the next world ([`Viewer::hand_over`]).
#[cfg(target_arch = "wasm32")]
pub struct Handover {
    pub window: Arc<Window>,
    pub surface: wgpu::Surface<'static>,
    pub gpu: Gpu,
    pub method: String,
    pub settings: MethodSettings,
    pub render_scale: f32,
    pub vsync: bool,
    pub out: PathBuf,
}

fn surface_config(
    surface: &wgpu::Surface<'_>,
    gpu: &Gpu,
    size: (u32, u32),
    vsync: bool,
) -> anyhow::Result<wgpu::SurfaceConfiguration> {
    let caps = surface.get_capabilities(&gpu.adapter);
    // A linear-encoding format passes our 8-bit colours through unchanged.
    let format = caps
        .formats
        .iter()
        .copied()
        .find(|f| !f.is_srgb())
        .or_else(|| caps.formats.first().copied())
        .context("the window's surface offers no format on this adapter")?;
    let mut config = surface
        .get_default_config(&gpu.adapter, size.0.max(1), size.1.max(1))
        .context("the window's surface is not supported by this adapter")?;
    config.format = format;
    config.present_mode = if vsync {
        wgpu::PresentMode::AutoVsync
    } else {
        wgpu::PresentMode::AutoNoVsync
    };
    Ok(config)
}

/// The render size for a window size.
fn scaled(window: (u32, u32), scale: f32) -> (u32, u32) {
    let side = |v: u32| ((v as f32 * scale).round() as u32).max(1);
    (side(window.0), side(window.1))
}

impl Viewer {
    /// The window and its surface (the first half of opening the viewer;
    /// the device for the surface comes between, awaited in a browser).
    pub fn open_window(
        event_loop: &ActiveEventLoop,
        options: &Options,
        instance: &wgpu::Instance,
    ) -> anyhow::Result<(Arc<Window>, wgpu::Surface<'static>)> {
        let attributes = Window::default_attributes()
            .with_title(format!("Strata: {}", options.world.name))
            .with_inner_size(winit::dpi::PhysicalSize::new(
                options.size.0,
                options.size.1,
            ));
        let attributes = Platform.window_attributes(attributes);
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("opening the window")?,
        );
        let surface = instance
            .create_surface(Arc::clone(&window))
            .context("creating a wgpu surface for the window")?;
        Ok((window, surface))
    }

    /// The viewer on a window [`Viewer::open_window`] opened and a device
    /// able to present to its surface.
    pub fn new(
        window: Arc<Window>,
        surface: wgpu::Surface<'static>,
        mut gpu: Gpu,
        options: Options,
    ) -> anyhow::Result<Self> {
        let Options {
            world,
            method,
            settings,
            size,
            render_scale,
            view,
            script,
            vsync,
            adapter: _,
            render,
            out,
            save,
            physics,
            paged: paged_world,
        } = options;
        gpu.options = render;
        let opened = Instant::now();
        let _ = size;
        methods::entry(&method)?;
        let inner = window.inner_size();
        let window_size = (inner.width.max(1), inner.height.max(1));
        let config = surface_config(&surface, &gpu, window_size, vsync)?;
        surface.configure(&gpu.device, &config);

        // On a CPU rasteriser a full-size picture costs a second per frame.
        let scale = render_scale.unwrap_or(if gpu.report.device_type == "Cpu" {
            0.5
        } else {
            1.0
        });
        if !(scale > 0.0 && scale <= 4.0) {
            bail!("--render-scale {scale} must be in (0, 4]");
        }
        let render_size = scaled(window_size, scale);
        let (saver, level) = Saver::new(world, save, &out);
        let world = saver.world();
        let world_size = paged_world
            .as_ref()
            .map_or((level.width(), level.height()), |p| p.pages.size());
        let name = world.name.clone();
        let mut views = world.views.clone();
        // The edit fixture's camera is a view too: it looks at the crater site.
        if let Some(edit) = &world.edit
            && !views.iter().any(|v| v.name == edit.camera.name)
        {
            views.push(edit.camera.clone());
        }
        let start = match &view {
            Some(name) => views
                .iter()
                .find(|v| &v.name == name)
                .with_context(|| {
                    let names: Vec<_> = views.iter().map(|v| v.name.as_str()).collect();
                    format!("no view `{name}`; the level has: {}", names.join(", "))
                })?
                .clone(),
            None => views.first().cloned().unwrap_or_else(|| ViewSpec {
                name: "centre".into(),
                x: world_size.0 as f32 * 0.5,
                y: world_size.1 as f32 * 0.5,
                yaw: 0.0,
                eye: 60.0,
                under: false,
                pitch: -20.0,
            }),
        };
        let camera = match &paged_world {
            Some(p) => paged::camera_over(&p.pages, &start, render_size.0, render_size.1)?,
            None => Camera::from_view(&level, &start, render_size.0, render_size.1)?,
        };
        let colors = TerrainColors {
            palette: world.palette.colors,
            begin: world.config.begin_colors,
            end: world.config.end_colors,
        };
        let map = Minimap::new(&level, &colors);
        let mut renderer = match &paged_world {
            Some(p) => Renderer::new_paged(
                &gpu,
                p.pages.clone(),
                &colors,
                paged::first_method(&method),
                &settings,
                render_size.0,
                render_size.1,
                p.options.clone(),
            )?,
            None => Renderer::new(
                &gpu,
                &level,
                &colors,
                FIRST_METHOD,
                &settings,
                render_size.0,
                render_size.1,
            )?,
        };
        // A still camera (or the second side of an A/B pair) keeps its shadow map.
        renderer.set_shadow_reuse(true);
        // The physics bodies draw over Strata's depth target with the depth test.
        renderer.set_depth_attachment(true);
        let compositor = Compositor::new(renderer.shared(), window_size, config.format)?;
        let passes = PassTimer::new(&gpu.device, &gpu.queue, gpu.report.timestamps);
        let mut overlay = Overlay::new(&window, &gpu.device, WINDOW_FORMAT);
        // A paged world has no picture of itself in memory: no map.
        if paged_world.is_none() {
            overlay.set_map(&map);
        }
        let digger = Digger::new(world.edit.as_ref().unwrap_or(&EditSite::fostral()));
        let physics_toy = PhysicsToy::new(&level);
        let mut viewer = Viewer {
            window,
            surface,
            config,
            gpu,
            renderer,
            compositor,
            passes,
            overlay,
            builds: Builds::default(),
            level: Arc::new(level),
            colors,
            map,
            views,
            digger,
            physics: physics_toy,
            fly: FlyCamera::from_camera(&camera),
            render_scale: scale,
            resize_to: None,
            settings,
            split: None,
            split_at: 0.5,
            waiting_for: None,
            previous_method: overlay::other_method(&method).to_string(),
            keys: HashSet::new(),
            ctrl: false,
            shift: false,
            cursor: None,
            looking: false,
            raw_motion: false,
            last_frame: Instant::now(),
            opened,
            frame_ms: 0.0,
            timings: Vec::new(),
            window_timings: FrameTimings::default(),
            totals: Vec::new(),
            log: Vec::new(),
            scores: Vec::new(),
            scored: 0,
            frames: 0,
            player: script.map(Player::new),
            scoring: None,
            screenshot_after_frame: None,
            screenshot_reading: None,
            screenshots: 0,
            out,
            saver,
            unsaved: false,
            quit: false,
            platform: Platform,
            paged: paged_world.map(paged::PagedState::new),
        };
        viewer.say(format!(
            "{} ({}x{}) on {} ({}), render {}x{}; window, device and {} ready in {:.2} s",
            name,
            world_size.0,
            world_size.1,
            viewer.gpu.report.name,
            viewer.gpu.report.backend,
            render_size.0,
            render_size.1,
            viewer.renderer.method_name(),
            opened.elapsed().as_secs_f64()
        ));
        if viewer.paged.is_some() {
            viewer.say_paged_start(&method);
        } else {
            viewer.request_method(&method)?;
        }
        if physics {
            viewer.toggle_physics();
        }
        Ok(viewer)
    }

    /// Give up the window, its surface and the device, with the method and
    /// settings drawn, so a viewer of another world can take them (the page
    /// cannot open a second window or event loop).
    #[cfg(target_arch = "wasm32")]
    pub fn hand_over(self) -> Handover {
        Handover {
            method: self.renderer.method_name().to_string(),
            settings: self.settings.clone(),
            render_scale: self.render_scale,
            vsync: self.config.present_mode != wgpu::PresentMode::AutoNoVsync,
            out: self.out.clone(),
            window: self.window,
            surface: self.surface,
            gpu: self.gpu,
        }
    }

    /// The picture's size: the renderer's targets.
    fn render_size(&self) -> (u32, u32) {
        let shared = self.renderer.shared();
        (shared.width, shared.height)
    }

    pub fn window(&self) -> &Window {
        &self.window
    }

    pub fn should_quit(&self) -> bool {
        self.quit
    }

    /// When to draw next: now (`None`), or later. On a CPU rasteriser every
    /// frame takes the cores a background build needs (the mesh fit took
    /// twice as long with frames drawn meanwhile), so while one runs and
    /// nothing moves, the view is redrawn only a few times a second.
    pub fn next_frame_due(&self) -> Option<Instant> {
        let cpu_adapter = self.gpu.report.device_type == "Cpu";
        let still = !self.looking
            && self.motion().is_still()
            && self.player.as_ref().is_none_or(Player::is_waiting);
        (cpu_adapter && still && !self.builds.running().is_empty())
            .then(|| self.last_frame + BUILD_FRAME_INTERVAL)
    }

    /// Per method: frames drawn, mean GPU ms (per-pass sum) and mean wait
    /// from submit to done, over the session (printed when the window closes).
    pub fn summary(&self) -> String {
        let mut out = format!(
            "frames drawn at {}x{} on {}:",
            self.render_size().0,
            self.render_size().1,
            self.gpu.report.name
        );
        for (method, t) in &self.totals {
            let gpu = match t.timed_frames {
                0 => "no timestamps".to_string(),
                n => format!("{:>8.2} ms", t.gpu_ms / f64::from(n)),
            };
            out.push_str(&format!(
                "\n  {method:<14} {:>6} frames, GPU {gpu}, submit-to-done {:>8.2} ms",
                t.frames,
                t.wait_ms / f64::from(t.frames)
            ));
        }
        if let Some(p) = &self.paged {
            out.push_str(&format!("\n  {}", p.summary()));
        }
        out
    }

    fn say(&mut self, line: String) {
        eprintln!("strata view: {line}");
        self.log.push(line);
        if self.log.len() > LOG_LINES {
            self.log.remove(0);
        }
    }

    fn next_screenshot_path(&mut self) -> PathBuf {
        self.screenshots += 1;
        self.out
            .join(format!("screenshot-{:03}.png", self.screenshots))
    }

    /// One frame: script, builds, camera, the picture(s), overlay, present.
    fn frame(&mut self) -> anyhow::Result<()> {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f64();
        self.last_frame = now;
        self.frame_ms = if self.frame_ms == 0.0 {
            dt * 1e3
        } else {
            0.9 * self.frame_ms + 0.1 * dt * 1e3
        };
        let first = self.totals.is_empty();
        self.frames += 1;
        for script in self.platform.take_commands() {
            self.player.get_or_insert_with(Player::waiting).push(script);
        }
        self.collect_builds()?;
        self.script_step()?;
        // Held keys fly the camera; a long stall (a build) is not a jump.
        let motion = self.motion();
        if !motion.is_still() {
            self.fly.fly(&motion, dt.min(0.1) as f32, self.world_size());
        }
        if let Some(line) = self.physics.poll(&self.level) {
            self.say(line);
        }
        self.physics.advance(dt);

        if let Some(size) = self.resize_to
            && self.builds.running().is_empty()
        {
            self.resize_to = None;
            match self.renderer.resize(size.0, size.1) {
                Ok(()) => {
                    self.compositor.rebind_picture(self.renderer.shared());
                    self.say(format!("picture {}x{}", size.0, size.1));
                }
                // Too large for this adapter: keep the picture, scaled.
                Err(e) => self.say(format!("picture stays {:?}: {e:#}", self.render_size())),
            }
        }
        let camera = self.camera()?;
        let active = self.renderer.method_name();
        let mut timings = vec![(active.to_string(), self.renderer.render_frame(&camera)?)];
        self.after_paged_frame();
        self.physics.draw(self.renderer.shared(), &camera);
        let split = self
            .split
            .clone()
            .filter(|b| b != active && self.is_current(b));
        if let Some(b) = &split {
            let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
            self.compositor
                .keep_left(self.renderer.shared(), &mut encoder);
            self.gpu.queue.submit([encoder.finish()]);
            self.renderer.activate(b)?;
            let drawn = self.renderer.render_frame(&camera);
            if drawn.is_ok() {
                self.physics.draw(self.renderer.shared(), &camera);
            }
            self.renderer.activate(active)?;
            timings.push((b.clone(), drawn?));
        }
        for (method, t) in &timings {
            let i = match self.totals.iter().position(|(m, _)| m == method) {
                Some(i) => i,
                None => {
                    self.totals.push((method.clone(), Totals::default()));
                    self.totals.len() - 1
                }
            };
            let totals = &mut self.totals[i].1;
            totals.frames += 1;
            totals.gpu_ms += t.gpu_ms.unwrap_or(0.0);
            totals.timed_frames += u32::from(t.gpu_ms.is_some());
            totals.wait_ms += t.cpu_ms;
        }
        self.timings = timings;

        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.passes.reset();
        self.compositor.compose(
            &mut encoder,
            split.as_ref().map(|_| self.split_at),
            self.passes.render("compose"),
        );
        let actions = self.paint_overlay(&mut encoder);
        let surface_texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => None,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.gpu.device, &self.config);
                None
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                bail!("the window's swapchain refused a frame (validation error)")
            }
        };
        if let Some(texture) = &surface_texture {
            let view = texture.texture.create_view(&Default::default());
            self.compositor
                .present(&mut encoder, &view, self.passes.render("present"));
        }
        self.passes.resolve(&mut encoder);
        let submitted = Instant::now();
        self.gpu.queue.submit([encoder.finish()]);
        if let Some(texture) = surface_texture {
            self.window.pre_present_notify();
            self.gpu.queue.present(texture);
        }
        let (gpu_ms, passes) = self.passes.read(&self.gpu.device, &self.gpu.errors)?;
        self.window_timings = FrameTimings {
            gpu_ms,
            cpu_ms: submitted.elapsed().as_secs_f64() * 1e3,
            passes,
            ..Default::default()
        };
        if first {
            self.say(format!(
                "first frame shown {:.2} s after the window opened",
                self.opened.elapsed().as_secs_f64()
            ));
        }

        if let Some(path) = self.screenshot_after_frame.take() {
            let read = self.compositor.start_read_window();
            self.screenshot_reading = Some((path, read));
        }
        self.poll_screenshot()?;
        self.poll_score()?;
        for action in actions {
            self.on_action(action)?;
        }
        self.platform.publish(|| self.page_state(), self.frames);
        Ok(())
    }

    /// What the page's scripts (and the browser test) read after each frame.
    fn page_state(&self) -> serde_json::Value {
        let building: Vec<_> = self.builds.running().into_iter().map(|(m, _)| m).collect();
        serde_json::json!({
            "phase": "running",
            "frames": self.frames,
            "adapter": self.gpu.report,
            "active": self.renderer.method_name(),
            "split": self.split,
            "kept": self.renderer.method_names(),
            "unavailable": methods::names()
                .into_iter()
                .filter_map(|m| methods::check_support(m, &self.gpu.caps).err().map(|e| (m, e)))
                .map(|(m, e)| serde_json::json!({ "method": m, "reason": format!("{e:#}") }))
                .collect::<Vec<_>>(),
            "building": building,
            "waiting_for": self.waiting_for,
            "idle": self.player.as_ref().is_none_or(Player::is_idle)
                && building.is_empty()
                && self.scoring.is_none()
                && self.screenshot_reading.is_none(),
            "frame_ms": self.frame_ms,
            "timings": self.timings.iter().map(|(m, t)| serde_json::json!({
                "method": m, "cpu_ms": t.cpu_ms, "gpu_ms": t.gpu_ms, "record_ms": t.record_ms,
            })).collect::<Vec<_>>(),
            "level_size": self.world_size(),
            "paging": self.paging_json(),
            "render_size": self.render_size(),
            "window_size": self.compositor.window_size(),
            "undo_depth": self.undo_depth(),
            "eye": [self.fly.position.x, self.fly.position.y, self.fly.position.z],
            "cursor": self.cursor,
            "scored": self.scored,
            "scores": self.scores.iter().map(|(m, metrics)| serde_json::json!({
                "method": m, "metrics": metrics,
            })).collect::<Vec<_>>(),
            "log": self.log,
        })
    }

    fn paint_overlay(&mut self, encoder: &mut wgpu::CommandEncoder) -> Vec<Action> {
        let renderer = &self.renderer;
        let progress = &renderer.shared().progress;
        let building = self
            .builds
            .running()
            .into_iter()
            .map(|(method, seconds)| Building {
                method,
                seconds,
                done: progress.get(method),
            })
            .collect();
        let status = Status {
            adapter: &self.gpu.report,
            caps: &self.gpu.caps,
            frame_ms: self.frame_ms,
            drawn: self
                .timings
                .iter()
                .map(|(method, timings)| Drawn { method, timings })
                .chain(std::iter::once(Drawn {
                    method: "window",
                    timings: &self.window_timings,
                }))
                .collect(),
            active: renderer.method_name(),
            split: self.split.as_deref(),
            kept: renderer
                .method_names()
                .into_iter()
                .filter_map(|m| renderer.retained_bytes_of(m).map(|b| (m, b)))
                .collect(),
            shared_gpu_bytes: renderer.shared_gpu_bytes(),
            building,
            waiting_for: self.waiting_for.as_deref(),
            views: &self.views,
            camera: &self.fly,
            render_size: self.render_size(),
            window_size: self.compositor.window_size(),
            undo_depth: self.undo_depth(),
            scores: &self.scores,
            log: &self.log,
            paging: self
                .paged
                .as_ref()
                .map(|p| p.overlay_lines(self.render_size())),
        };
        let mut editable = Editable {
            settings: &mut self.settings,
            crater_radius: &mut self.digger.radius,
            crater_depth: &mut self.digger.depth,
            split_at: &mut self.split_at,
        };
        self.overlay.paint(
            &self.window,
            &self.gpu.device,
            &self.gpu.queue,
            encoder,
            self.compositor.window_view(),
            &status,
            &mut editable,
            self.passes.render("overlay"),
        )
    }

    fn on_action(&mut self, action: Action) -> anyhow::Result<()> {
        match action {
            Action::Method(name) => self.request_method(&name)?,
            Action::Split(split) => self.set_split(split)?,
            Action::View(i) => self.go_to_view(i),
            Action::Knob(knob) => self.on_knob(knob)?,
            Action::Undo => self.undo()?,
            Action::CopyView => self.copy_view("viewer"),
            Action::Score => self.score()?,
            Action::Teleport(to) => self.teleport(to),
            Action::Screenshot => {
                self.screenshot_after_frame = Some(self.next_screenshot_path());
            }
        }
        Ok(())
    }
}
