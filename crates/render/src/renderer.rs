//! [`Renderer`]: the shared frame plus the methods built on it, the API the
//! CLI, the harness and the viewer drive: build, `render_frame`, `apply_edit`,
//! read back, report memory.
//!
//! One method is active and drawn by `render_frame`; others may be kept
//! (the viewer switches between them without reloading the level). Every kept
//! method follows every edit, so switching never shows stale terrain.

use crate::depth_read::DepthReader;
use crate::frame::{Globals, LevelShape, Shared, TerrainColors};
use crate::gpu::{ErrorSink, Gpu, wait_device};
use crate::methods::{self, Frame, FrameTargets, Method, MethodId, MethodSettings, RetainedBytes};
use crate::shadow::{ShadowFrame, ShadowPass};
use crate::timing::{FrameTimings, PassTimer};
use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use web_time::Instant;

/// What [`Renderer::measure`] saw.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    /// Wall-clock ms of the first frame (pipelines warming up).
    pub first_frame_ms: f64,
    /// Wall-clock ms of the untimed warm-up frames together.
    pub warmup_ms: f64,
    /// Each timed frame.
    pub timings: Vec<FrameTimings>,
}

/// A built method and the settings it was built with.
struct Built {
    method: Box<dyn Method>,
    settings: MethodSettings,
}

/// Methods drawing one level at one size over one shared frame.
pub struct Renderer {
    /// Shared with background method builds ([`Renderer::shared_handle`]).
    shared: Arc<Shared>,
    /// Every kept method; `methods[active]` is drawn.
    methods: Vec<Built>,
    active: usize,
    shadow: ShadowPass,
    pub(crate) timer: PassTimer,
    pub(crate) errors: ErrorSink,
    level_shape: LevelShape,
    frames: u64,
    adapter: crate::gpu::AdapterReport,
    setup_ms: f64,
    /// Skip the shadow pass while the map would come out the same.
    shadow_reuse: bool,
    /// The frame the shadow map holds, while no edit has changed it.
    shadow_drawn: Option<ShadowFrame>,
    /// Cast only the shadow texels the view can sample (`ShadowCover`).
    shadow_cull: bool,
    /// Fill the shared depth target every frame, also for the methods that
    /// keep depth in an image of their own ([`Renderer::set_depth_attachment`]).
    depth_attachment: bool,
    /// Whether the shared depth target holds the last frame's depth.
    pub(crate) depth_target_current: bool,
    /// Whether the shared colour target holds the last frame's colour (not
    /// after an embedding frame whose shading stored it into the caller's
    /// texture: [`Renderer::render_into`]).
    pub(crate) color_target_current: bool,
    /// Whether the last frame drew its depth into the caller's texture, not
    /// the shared target (a rasterising method's embedding frame).
    depth_in_caller: bool,
    /// The road the last [`Renderer::render_into`] took.
    pub(crate) last_road: Option<crate::composite_split::CompositeRoute>,
    /// Depth read-back through a pass, where depth copies are missing.
    depth_reader: Option<DepthReader>,
    /// The newest frame's submission ([`Renderer::hold_busy`] bounds the queue by it).
    last_submission: Option<wgpu::SubmissionIndex>,
    /// Called by [`Renderer::apply_edit`] after the GPU copies changed.
    edit_listener: Option<EditListener>,
    /// Pipelines that copy the frame into a caller's targets ([`Renderer::render_into`]).
    pub(crate) composite: crate::composite::CompositeCache,
    /// Colour and depth each by its cheapest way ([`crate::composite_split`]).
    pub(crate) split: crate::composite_split::SplitCache,
}

/// Frames [`Renderer::hold_busy`] lets queue up before it waits for the oldest.
const FRAMES_IN_FLIGHT: usize = 3;

/// Something that follows the level's edits on the CPU (a terrain collider,
/// `strata_collide::TerrainCollider::apply_edit`): called with the edited
/// level and the dirty rectangles inside [`Renderer::apply_edit`], after the
/// GPU data changed, so both change on the same consistency boundary.
pub type EditListener = Box<dyn FnMut(&Level, &[DirtyRect]) + Send>;

impl Renderer {
    /// Upload `level`, build `method` (its [`methods::MethodEntry`], or a
    /// name of [`methods::names`]) for `width` x `height` targets. An unknown name, or
    /// a method this adapter cannot run, is an error naming it.
    ///
    /// ```no_run
    /// # fn f(gpu: &strata_render::Gpu, world: &strata_level::World) -> anyhow::Result<()> {
    /// use strata_render::{MethodSettings, Renderer, TerrainColors};
    /// let colors = TerrainColors::from_world(world);
    /// let renderer = Renderer::new(gpu, &world.level, &colors, "mesh",
    ///                              &MethodSettings::default(), 1280, 800)?;
    /// # Ok(()) }
    /// ```
    pub fn new(
        gpu: &Gpu,
        level: &Level,
        colors: &TerrainColors,
        method: &(impl MethodId + ?Sized),
        settings: &MethodSettings,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Self> {
        let start = Instant::now();
        // Unknown names, and methods this adapter cannot run, fail before
        // any GPU work.
        methods::check_support(method, &gpu.caps)?;
        let mut shared = Shared::new(
            &gpu.device,
            &gpu.queue,
            &gpu.caps,
            level,
            colors,
            width,
            height,
        )?;
        shared.options = gpu.options.clone();
        let shared = Arc::new(shared);
        let method = methods::create(method, &shared, level, settings)?;
        Self::assemble(gpu, shared, method, settings, LevelShape::of(level), start)
    }

    /// The renderer around a shared frame and its first method, once the
    /// GPU has finished building them (`setup_ms` counts from `start`).
    fn assemble(
        gpu: &Gpu,
        shared: Arc<Shared>,
        method: Box<dyn Method>,
        settings: &MethodSettings,
        level_shape: LevelShape,
        start: Instant,
    ) -> anyhow::Result<Self> {
        let shadow = ShadowPass::new(&shared)?;
        let depth_reader = DepthReader::new(&gpu.device, &gpu.caps)?;
        let timer = PassTimer::new(&gpu.device, &gpu.queue, gpu.report.timestamps);
        let mut renderer = Renderer {
            shared,
            methods: vec![Built {
                method,
                settings: settings.clone(),
            }],
            active: 0,
            shadow,
            timer,
            errors: gpu.errors.clone(),
            level_shape,
            frames: 0,
            last_submission: None,
            adapter: gpu.report.clone(),
            setup_ms: 0.0,
            shadow_reuse: gpu.options.shadow_reuse,
            shadow_drawn: None,
            shadow_cull: gpu.options.shadow_cull,
            depth_attachment: gpu.options.depth_attachment,
            depth_target_current: false,
            color_target_current: true,
            depth_in_caller: false,
            last_road: None,
            depth_reader,
            edit_listener: None,
            composite: Default::default(),
            split: Default::default(),
        };
        wait_device(&renderer.shared.device, &renderer.errors)?;
        renderer.setup_ms = ms(start);
        Ok(renderer)
    }

    /// Draw the world of `source` through a fixed GPU budget (`crate::paged`,
    /// issue 33): only pages the view needs are resident, streamed from
    /// `source` by reader threads. The method must be one that draws paged
    /// terrain ([`crate::paged::PAGED_METHODS`]); the others are refused,
    /// naming those that can.
    #[allow(clippy::too_many_arguments)]
    pub fn new_paged(
        gpu: &Gpu,
        source: Arc<dyn crate::paged::PageSource>,
        colors: &TerrainColors,
        method: &(impl MethodId + ?Sized),
        settings: &MethodSettings,
        width: u32,
        height: u32,
        paging: crate::paged::PagedOptions,
    ) -> anyhow::Result<Self> {
        let start = Instant::now();
        methods::check_support(method, &gpu.caps)?;
        let entry = method.entry()?;
        let compute = match entry.name {
            "ray-exact" => true,
            "ray-exact-fragment" | "mesh" => false,
            other => anyhow::bail!(
                "`{other}` draws whole worlds only; paged worlds (past the whole-world limits, or with a GPU budget) are drawn by {}",
                crate::paged::PAGED_METHODS.join(", ")
            ),
        };
        let options = crate::options::ExactOptions {
            compute,
            ..gpu.options.exact
        };
        let is_mesh = entry.name == "mesh";
        let budget = paging.gpu_budget;
        // The mesh's index pool shares the budget with the atlas.
        let (paging, pool_bytes) = if is_mesh {
            methods::mesh::paged::split_budget(&paging, source.as_ref())?
        } else {
            (paging, 0)
        };
        let step = if is_mesh {
            methods::mesh::paged::PYRAMID_STEP
        } else {
            options.pyramid_step()
        };
        let (atlas, plan) =
            crate::paged::PagedTerrain::atlas(&gpu.device, source.as_ref(), &paging, step)?;
        let (w, h) = source.size();
        let mut shared = Shared::with_terrain(
            &gpu.device,
            &gpu.queue,
            &gpu.caps,
            atlas,
            colors,
            width,
            height,
        )?;
        shared.options = gpu.options.clone();
        let shared = Arc::new(shared);
        let level_shape = LevelShape {
            width: w,
            height: h,
            mid_rule: source.mid_rule(),
        };
        let threads = paging.threads;
        let paged = crate::paged::PagedTerrain::new(&shared, source, plan, paging, step)?;
        let method: Box<dyn Method> = if is_mesh {
            methods::mesh::paged::build(&shared, paged, settings, budget, pool_bytes, threads)?
        } else {
            Box::new(methods::ray_exact::build_paged(&shared, paged, options)?)
        };
        Self::assemble(gpu, shared, method, settings, level_shape, start)
    }

    /// Whether this renderer draws paged terrain ([`Renderer::new_paged`]).
    pub fn is_paged(&mut self) -> bool {
        self.paged_terrain().is_some()
    }

    /// The active method's paged terrain, if it draws one: its statistics
    /// and plan ([`Renderer::refresh_pages`] after an edit of its source).
    pub fn paged_terrain(&mut self) -> Option<&mut crate::paged::PagedTerrain> {
        self.methods[self.active].method.paged_terrain()
    }

    /// The paged terrain's source changed inside `chunks` (an edit batch
    /// written to its store, the cache told): refresh their coarse level and
    /// resident pages, so the next frame shows the edit.
    pub fn refresh_pages(&mut self, chunks: &[u32]) -> anyhow::Result<()> {
        let shared = Arc::clone(&self.shared);
        self.methods[self.active]
            .method
            .refresh_pages(&shared, chunks)?;
        self.shadow_drawn = None;
        Ok(())
    }

    /// Draw `camera`'s frame until no pixel of it is pending (paged
    /// terrain: every page it reads resident), at most `most` frames; the
    /// frames it took. A whole world is converged at once (0). An error when
    /// it does not converge: the budget is smaller than the view reads, or
    /// pages fail to read.
    pub fn converge(&mut self, camera: &Camera, most: u32) -> anyhow::Result<u32> {
        if !self.is_paged() {
            return Ok(0);
        }
        for frame in 1..=most {
            self.render_frame(camera)?;
            let stats = self.paged_terrain().map(|p| p.stats()).unwrap_or_default();
            // The first frame's feedback may predate its own uploads.
            if frame > 1 && stats.converged() {
                return Ok(frame);
            }
            if stats.in_flight > 0 {
                // Let the readers catch up rather than spin on the GPU.
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        }
        let stats = self.paged_terrain().map(|p| p.stats()).unwrap_or_default();
        anyhow::bail!(
            "the view did not converge in {most} frames: {} pixels and {} shadow texels still pending with {} of {} slots resident{}",
            stats.pending_pixels,
            stats.pending_shadow_texels,
            stats.resident_pages,
            stats.slots,
            stats
                .first_error
                .map(|e| format!("; {e}"))
                .unwrap_or_else(|| " (a larger --gpu-budget holds more of the view)".into())
        )
    }

    /// The active method's `R32Float` depth image, where it keeps one
    /// (the compute marches; [`methods::Method::depth_image`]).
    pub(crate) fn active_depth_image(&self) -> Option<&wgpu::Texture> {
        self.methods[self.active].method.depth_image()
    }

    /// The method drawn now.
    pub(crate) fn active_method(&self) -> &dyn Method {
        self.methods[self.active].method.as_ref()
    }

    /// The active method's name.
    pub fn method_name(&self) -> &'static str {
        self.methods[self.active].method.name()
    }

    /// The names of the kept methods, in the order they were built.
    pub fn method_names(&self) -> Vec<&'static str> {
        self.methods.iter().map(|b| b.method.name()).collect()
    }

    /// The settings method `name` was built with, if it is kept.
    pub fn settings_of(&self, name: &str) -> Option<&MethodSettings> {
        self.find(name).map(|i| &self.methods[i].settings)
    }

    fn find(&self, name: &str) -> Option<usize> {
        self.methods.iter().position(|b| b.method.name() == name)
    }

    /// Build method `name` on this renderer's shared frame (replacing a kept
    /// one of that name) without activating it.
    pub fn build_method(
        &mut self,
        level: &Level,
        name: &(impl MethodId + ?Sized),
        settings: &MethodSettings,
    ) -> anyhow::Result<()> {
        let method = methods::create(name, &self.shared, level, settings)?;
        wait_device(&self.shared.device, &self.errors)?;
        self.insert_method(method, settings.clone());
        Ok(())
    }

    /// Keep a method built elsewhere on [`Renderer::shared_handle`] (a
    /// background thread, say), replacing a kept one of the same name. The
    /// caller must have applied every edit made since its build started.
    pub fn insert_method(&mut self, method: Box<dyn Method>, settings: MethodSettings) {
        let built = Built { method, settings };
        match self.find(built.method.name()) {
            Some(i) => self.methods[i] = built,
            None => self.methods.push(built),
        }
    }

    /// Give kept method `name` new settings in place where it can (see
    /// [`Method::update_settings`]): `Ok(true)` when it took them, `Ok(false)`
    /// when it must be rebuilt (or is not kept).
    pub fn update_settings(
        &mut self,
        name: &str,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        let Some(i) = self.find(name) else {
            return Ok(false);
        };
        let built = &mut self.methods[i];
        let taken = built.method.update_settings(&self.shared, settings)?;
        if taken {
            built.settings = settings.clone();
        }
        Ok(taken)
    }

    /// Draw method `name` from the next frame on; it must have been built.
    pub fn activate(&mut self, name: &str) -> anyhow::Result<()> {
        self.active = self.find(name).ok_or_else(|| {
            anyhow::anyhow!(
                "method `{name}` is not built; kept: {}",
                self.method_names().join(", ")
            )
        })?;
        Ok(())
    }

    /// Turn the shared shadow map on or off for every kept method (a frame
    /// setting: no method data depends on it).
    pub fn set_shadows(&mut self, on: bool) {
        for built in &mut self.methods {
            built.settings.shadows = on;
        }
    }

    /// Draw at `width` x `height` from the next frame on: new shared targets,
    /// and every kept method rebinds or resizes what depended on the old ones
    /// (nothing is rebuilt from the level). Refused while a method built on
    /// [`Renderer::shared_handle`] still holds the shared frame.
    pub fn resize(&mut self, width: u32, height: u32) -> anyhow::Result<()> {
        if (width, height) == (self.shared.width, self.shared.height) {
            return Ok(());
        }
        let old = (self.shared.width, self.shared.height);
        self.resize_all(width, height).or_else(|error| {
            // Leave the renderer as it was: every method at the old size.
            self.resize_all(old.0, old.1)?;
            Err(error)
        })?;
        self.shadow_drawn = None;
        wait_device(&self.shared.device, &self.errors)
    }

    fn resize_all(&mut self, width: u32, height: u32) -> anyhow::Result<()> {
        let shared = Arc::get_mut(&mut self.shared).ok_or_else(|| {
            anyhow::anyhow!("cannot resize while a method is being built on the shared frame")
        })?;
        shared.resize_targets(width, height)?;
        for built in &mut self.methods {
            built.method.resize(&self.shared)?;
        }
        Ok(())
    }

    /// Skip the shadow pass when the map would be the one already drawn (the
    /// same fitted frame, no edit since): for interactive use, where a still
    /// camera or an A/B pair redraws it for nothing. Off by default, so every
    /// frame the protocol measures pays for its shadow map.
    pub fn set_shadow_reuse(&mut self, on: bool) {
        self.shadow_reuse = on;
    }

    /// Make every frame's depth land in the shared depth target
    /// (`shared().depth_view`), for a caller that draws over Strata's own
    /// targets with the depth test after [`Renderer::render_frame`] (the
    /// viewer's physics bodies). Methods that rasterise write it anyway; the
    /// compute marches (`ray-compute`, `voxel-compute`, `ray-exact`) write
    /// depth into an image of their own and, with this off (the default),
    /// skip the full-screen copy into the target: 0.076 ms of a frame at
    /// 1280x800 on an H100. [`Renderer::read_depth`] and
    /// [`Renderer::render_into`] see the frame's depth either way.
    pub fn set_depth_attachment(&mut self, on: bool) {
        self.depth_attachment = on;
    }

    /// Cast only the shadow texels this frame's view can sample (on by
    /// default; `ShadowCover`): off casts all 1024², which gives the same
    /// picture at more cost (a test checks it) and is kept for measuring.
    #[doc(hidden)]
    pub fn set_shadow_cull(&mut self, on: bool) {
        self.shadow_cull = on;
    }

    /// The shared frame, for building methods off the render thread:
    /// `methods::create(name, &handle, level, settings)`.
    pub fn shared_handle(&self) -> Arc<Shared> {
        Arc::clone(&self.shared)
    }

    /// The adapter this renderer runs on.
    pub fn adapter(&self) -> &crate::gpu::AdapterReport {
        &self.adapter
    }

    /// Wall-clock ms `new` took: terrain upload, pipelines, method data,
    /// waiting for the GPU to finish them (the protocol's "setup").
    pub fn setup_ms(&self) -> f64 {
        self.setup_ms
    }

    /// The active method's settings.
    pub fn settings(&self) -> &MethodSettings {
        &self.methods[self.active].settings
    }

    /// The shared resources (for tests and tools that inspect them).
    pub fn shared(&self) -> &Shared {
        &self.shared
    }

    /// Render one frame into Strata's own targets ([`Shared::color_view`],
    /// and [`Shared::depth_view`] for every method once
    /// [`Renderer::set_depth_attachment`] is on, else the compute marches
    /// keep depth in their own image: [`Renderer::read_depth`] reads it
    /// either way) and wait for it. GPU time is the sum of the
    /// per-pass timestamp intervals; CPU time is submit until the GPU is done.
    /// `camera` must be of the renderer's size. To draw into your own
    /// targets instead, see [`Renderer::render_into`].
    ///
    /// ```no_run
    /// # fn f(renderer: &mut strata_render::Renderer) -> anyhow::Result<()> {
    /// let camera = strata_camera::Camera::new(glam::Vec3::new(128.0, 0.0, 120.0),
    ///                                         0.0, -30.0, 1280, 800)?;
    /// let t = renderer.render_frame(&camera)?;
    /// println!("{:?} ms on the GPU, {} ms waiting", t.gpu_ms, t.cpu_ms);
    /// # Ok(()) }
    /// ```
    pub fn render_frame(&mut self, camera: &Camera) -> anyhow::Result<FrameTimings> {
        let record_ms = self.submit_frame(camera)?;
        let submit_start = Instant::now();
        wait_device(&self.shared.device, &self.errors)?;
        let cpu_ms = ms(submit_start);
        self.methods[self.active].method.frame_done(&self.shared)?;

        let (gpu_ms, passes) = self.timer.read(&self.shared.device, &self.errors)?;
        Ok(FrameTimings {
            gpu_ms,
            cpu_ms,
            record_ms,
            passes,
            untimed_passes: self.timer.untimed(),
        })
    }

    /// Keep the GPU busy with this camera's frames, submitted back to back
    /// (at most `FRAMES_IN_FLIGHT`, 3, queued), for `duration` of wall clock;
    /// returns how many frames ran. Why: a GPU lowers its clock when it is
    /// mostly idle, and the protocol's submit-and-wait frames leave it idle
    /// most of the time: on the H100 the SM clock fell from 1980 MHz to
    /// 700–1000 MHz a few seconds into a run, so a method measured later in
    /// one process looked up to 2.5x slower. Running this before a cell's
    /// timed frames measures every method at the clock a GPU-bound
    /// application gets. Frames here are untimed (their stamps are not read).
    pub fn hold_busy(
        &mut self,
        camera: &Camera,
        duration: std::time::Duration,
    ) -> anyhow::Result<u32> {
        let start = Instant::now();
        let mut in_flight = std::collections::VecDeque::new();
        let mut frames = 0;
        while start.elapsed() < duration {
            self.submit_frame(camera)?;
            in_flight.push_back(self.last_submission.clone());
            frames += 1;
            if in_flight.len() > FRAMES_IN_FLIGHT
                && let Some(Some(oldest)) = in_flight.pop_front()
            {
                let _ = self.shared.device.poll(wgpu::PollType::Wait {
                    submission_index: Some(oldest),
                    timeout: Some(crate::gpu::GPU_WAIT_TIMEOUT),
                });
                self.errors.check()?;
            }
        }
        wait_device(&self.shared.device, &self.errors)?;
        Ok(frames)
    }

    /// Record and submit one frame without waiting for it; returns the CPU
    /// ms spent preparing and recording it.
    fn submit_frame(&mut self, camera: &Camera) -> anyhow::Result<f64> {
        let record_start = Instant::now();
        let encoder = self.record_frame(camera)?;
        let commands = encoder.finish();
        let record_ms = ms(record_start);
        self.submit(commands);
        Ok(record_ms)
    }

    /// Prepare one frame and record it into a new encoder (shadow map, the
    /// active method, timestamp resolve), not yet submitted.
    pub(crate) fn record_frame(&mut self, camera: &Camera) -> anyhow::Result<wgpu::CommandEncoder> {
        let depth_attachment = self.depth_attachment;
        self.record_frame_with(camera, depth_attachment)
    }

    /// [`Renderer::record_frame`], saying whether the shared depth target
    /// must hold the frame's depth ([`Renderer::set_depth_attachment`]).
    pub(crate) fn record_frame_with(
        &mut self,
        camera: &Camera,
        depth_attachment: bool,
    ) -> anyhow::Result<wgpu::CommandEncoder> {
        let mut encoder =
            self.record_frame_into(camera, depth_attachment, FrameTargets::default())?;
        self.timer.resolve(&mut encoder);
        Ok(encoder)
    }

    /// [`Renderer::record_frame_with`] drawing colour and depth straight
    /// into the caller's views `into` where given (an embedding frame whose
    /// road chose it: `composite_split`), without resolving the frame's
    /// timestamps (the caller may time passes after it). A compute method
    /// stores colour into `into.color` from its shading
    /// ([`Method::store_color_into`]); a rasterising one attaches it.
    ///
    /// [`Method::store_color_into`]: crate::methods::Method::store_color_into
    pub(crate) fn record_frame_into(
        &mut self,
        camera: &Camera,
        depth_attachment: bool,
        into: FrameTargets<'_>,
    ) -> anyhow::Result<wgpu::CommandEncoder> {
        if camera.width != self.shared.width || camera.height != self.shared.height {
            anyhow::bail!(
                "camera is {}x{} but the renderer was built for {}x{}",
                camera.width,
                camera.height,
                self.shared.width,
                self.shared.height
            );
        }
        let shadows = self.settings().shadows;
        let mut shadow = ShadowFrame::fit(camera, shadows);
        if !self.shadow_cull {
            shadow.cover = strata_camera::light::ShadowCover::EVERY_TEXEL;
        }
        let globals = Globals::new(camera, &self.level_shape, &shadow);
        self.shared
            .queue
            .write_buffer(&self.shared.globals, 0, bytemuck::bytes_of(&globals));
        let method = &mut self.methods[self.active].method;
        // Every frame says where its colour goes: a method left storing into
        // a caller's texture by the last embedding frame stores into the
        // shared target again.
        let stored = method.store_color_into(&self.shared, into.color)? && into.color.is_some();
        if into.color.is_some() && !stored && !method.draws_color_by_attachment() {
            anyhow::bail!(
                "{} can neither store nor draw its colour into the caller's texture",
                method.name()
            );
        }
        let targets = FrameTargets {
            color: into.color.filter(|_| !stored),
            depth: into.depth,
        };
        method.prepare(&self.shared, camera)?;

        let mut encoder = self
            .shared
            .device
            .create_command_encoder(&Default::default());
        self.timer.reset();
        let current = self.shadow_reuse && self.shadow_drawn == Some(shadow);
        let frame = Frame {
            camera,
            timer: &self.timer,
            index: self.frames,
            depth_attachment,
            targets,
        };
        let method = &self.methods[self.active].method;
        self.depth_target_current =
            (depth_attachment || method.depth_image().is_none()) && into.depth.is_none();
        self.depth_in_caller = into.depth.is_some();
        self.color_target_current = into.color.is_none();
        if shadows && !current {
            // The method may fill the map itself (the exact march does).
            if !method.record_shadow_map(&self.shared, &frame, &mut encoder) {
                self.shadow.record(&mut encoder, &self.timer);
                self.shared.shadow_map_written();
            }
            // A map cast only where this method's pixels sample it is not
            // another method's to reuse.
            self.shadow_drawn = (!method.shadow_map_is_partial()).then_some(shadow);
        }
        method.record(&self.shared, &frame, &mut encoder);
        Ok(encoder)
    }

    /// Submit a frame's commands and count it.
    pub(crate) fn submit(&mut self, commands: wgpu::CommandBuffer) {
        self.last_submission = Some(self.shared.queue.submit([commands]));
        self.frames += 1;
    }

    /// The protocol's frame loop: one first frame, `warmup` untimed frames,
    /// then `frames` timed ones (wall-clock ms of the first frame and of the
    /// warm-up as a whole, as preparation costs).
    pub fn measure(
        &mut self,
        camera: &Camera,
        warmup: u32,
        frames: u32,
    ) -> anyhow::Result<Measured> {
        let start = Instant::now();
        self.render_frame(camera)?;
        let first_frame_ms = ms(start);
        let start = Instant::now();
        for _ in 0..warmup {
            self.render_frame(camera)?;
        }
        let warmup_ms = ms(start);
        let timings = (0..frames)
            .map(|_| self.render_frame(camera))
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok(Measured {
            first_frame_ms,
            warmup_ms,
            timings,
        })
    }

    /// The level changed inside `rects` (`level` is the edited level): upload
    /// only those rectangles, then let every kept method update its derived
    /// data, then call the edit listener ([`Renderer::set_edit_listener`]).
    ///
    /// ```no_run
    /// # fn f(renderer: &mut strata_render::Renderer, level: &mut strata_level::Level)
    /// #     -> anyhow::Result<()> {
    /// let mut site = strata_level::EditSite::fostral();
    /// (site.centre_x, site.centre_y, site.radius, site.depth) = (180, 128, 18, 20.0);
    /// let dirty = strata_level::edit::crater(level, &site);
    /// renderer.apply_edit(level, &dirty)?;
    /// # Ok(()) }
    /// ```
    pub fn apply_edit(&mut self, level: &Level, rects: &[DirtyRect]) -> anyhow::Result<()> {
        if self.is_paged() {
            anyhow::bail!(
                "this renderer draws paged terrain: write the edit to its store, then PagedTerrain::refresh the chunks"
            );
        }
        self.shared
            .terrain
            .upload(&self.shared.queue, level, rects)?;
        self.shadow_drawn = None;
        for built in &mut self.methods {
            built.method.apply_edit(&self.shared, level, rects)?;
        }
        if let Some(listener) = &mut self.edit_listener {
            listener(level, rects);
        }
        Ok(())
    }

    /// Wait until every method has finished the derived data of every edit
    /// applied so far (`mesh`'s refits run off the frame), so that the next
    /// frame shows them all: for comparing against a fresh build. A game
    /// never needs it; the frame does not wait.
    pub fn settle_edits(&mut self) -> anyhow::Result<()> {
        let shared = Arc::clone(&self.shared);
        for built in &mut self.methods {
            built.method.settle_edits(&shared)?;
        }
        Ok(())
    }

    /// How many of the latest [`apply_edit`](Self::apply_edit) calls the
    /// last frame of the active method did not yet show in full (0 for
    /// methods whose edits are drawn by the next frame).
    pub fn pending_edits(&self) -> u64 {
        self.methods[self.active].method.pending_edits()
    }

    /// Follow every later [`apply_edit`](Self::apply_edit) on the CPU too
    /// (replaces any earlier listener; `None` removes it).
    ///
    /// ```no_run
    /// # fn f(renderer: &mut strata_render::Renderer, level: &strata_level::Level) {
    /// use std::sync::{Arc, Mutex};
    /// let collider = Arc::new(Mutex::new(strata_collide::TerrainCollider::fit(level, 1.0)));
    /// let follower = Arc::clone(&collider);
    /// renderer.set_edit_listener(Some(Box::new(move |level, rects| {
    ///     follower.lock().unwrap().apply_edit(level, rects);
    /// })));
    /// # }
    /// ```
    pub fn set_edit_listener(&mut self, listener: Option<EditListener>) {
        self.edit_listener = listener;
    }

    /// Strata's colour target after the last frame: RGBA8 (sRGB-encoded
    /// values), row-major, top row first. Blocks until copied.
    ///
    /// ```no_run
    /// # fn f(renderer: &mut strata_render::Renderer, camera: &strata_camera::Camera)
    /// #     -> anyhow::Result<()> {
    /// renderer.render_frame(camera)?;
    /// let rgba = renderer.read_color()?;
    /// let depth = renderer.read_depth()?;   // 0 near .. 1 far, 1.0 = sky
    /// let (w, h) = (renderer.shared().width, renderer.shared().height);
    /// assert_eq!((rgba.len(), depth.len()), (4 * (w * h) as usize, (w * h) as usize));
    /// # Ok(()) }
    /// ```
    pub fn read_color(&self) -> anyhow::Result<Vec<u8>> {
        self.shared_color_current()?;
        self.read_texture(&self.shared.color, wgpu::TextureAspect::All)
    }

    /// Strata's depth target after the last frame: depth-buffer values (0
    /// near .. 1 far, 1 = sky; the crate's depth convention), row-major, top
    /// row first. Blocks until copied (example: [`Renderer::read_color`]).
    pub fn read_depth(&self) -> anyhow::Result<Vec<f32>> {
        if let Some(image) = self.methods[self.active].method.depth_image() {
            let raw = self.read_texture(image, wgpu::TextureAspect::All)?;
            return Ok(bytemuck::cast_slice::<u8, f32>(&raw).to_vec());
        }
        if self.depth_in_caller {
            anyhow::bail!(
                "the frame last drawn ({}) drew its depth straight into the caller's depth texture (`render_into`), not into Strata's depth target: read it there, or draw the frame with `render_frame`",
                self.method_name()
            );
        }
        if let Some(reader) = &self.depth_reader {
            let s = &self.shared;
            return reader.read(&s.device, &s.queue, &self.errors, &s.depth);
        }
        let raw = self.read_texture(&self.shared.depth, wgpu::TextureAspect::DepthOnly)?;
        Ok(bytemuck::cast_slice::<u8, f32>(&raw).to_vec())
    }

    /// Start copying the depth target to the CPU without waiting (the
    /// browser's way: poll the result per frame; its bytes are `f32` depths).
    pub fn start_read_depth(&self) -> crate::gpu::TextureReadback {
        if let Some(image) = self.methods[self.active].method.depth_image() {
            return crate::gpu::TextureReadback::start(
                &self.shared.device,
                &self.shared.queue,
                image,
                wgpu::TextureAspect::All,
            );
        }
        if let Some(reader) = &self.depth_reader {
            let s = &self.shared;
            return reader.start(&s.device, &s.queue, &s.depth);
        }
        crate::gpu::TextureReadback::start(
            &self.shared.device,
            &self.shared.queue,
            &self.shared.depth,
            wgpu::TextureAspect::DepthOnly,
        )
    }

    /// Bytes the active method keeps beyond the shared resources.
    pub fn retained_bytes(&self) -> RetainedBytes {
        self.methods[self.active].method.retained_bytes()
    }

    /// Bytes kept method `name` keeps beyond the shared resources.
    pub fn retained_bytes_of(&self, name: &str) -> Option<RetainedBytes> {
        self.find(name)
            .map(|i| self.methods[i].method.retained_bytes())
    }

    /// Bytes of the shared resources (terrain, uniforms, shadow map, targets).
    pub fn shared_gpu_bytes(&self) -> u64 {
        self.shared.gpu_bytes()
    }

    /// Copy a 4-byte-per-texel target to the CPU, unpadding rows.
    fn read_texture(
        &self,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) -> anyhow::Result<Vec<u8>> {
        crate::gpu::read_texture(
            &self.shared.device,
            &self.shared.queue,
            &self.errors,
            texture,
            aspect,
        )
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}
