//! Embedding: draw the terrain into the caller's own colour and depth views
//! ([`Renderer::render_into`]), so the caller's rasterised objects, drawn
//! afterwards with the ordinary depth test, compose with it.
//!
//! How: by the cheapest road the targets allow ([`crate::composite_split`]).
//! Views of Strata's own formats take the frame itself: the render passes
//! attach them in place of Strata's targets, a compute shading stores its
//! colour into them. Otherwise the active method renders into Strata's own
//! targets as in [`Renderer::render_frame`], then, in the same command
//! buffer, colour reaches the caller's view by a compute dispatch into a
//! storage texture or by a copy, depth by a depth-only pass from a compute
//! method's depth image or by a copy; else by one full-screen pass that
//! writes colour and depth (`frag_depth`) and serves every format pair and
//! sample count. Every road stores the same bytes
//! (`tests/embed.rs`). A multisampled target receives each pixel's colour
//! and depth in all its samples (the terrain is drawn at one sample per
//! pixel; your objects get the MSAA).
//!
//! # Depth convention
//! The depth written is Strata's depth-buffer value under
//! [`Camera::view_proj`](strata_camera::Camera::view_proj): a right-handed,
//! z-up world; a perspective projection onto wgpu's clip space with depth
//! **0 at the near plane .. 1 at the far plane** (`camera.near`, default 1
//! world unit, and `camera.far`, default 600), not reversed; sky pixels hold
//! **1.0**. Draw your objects with the same `view_proj`, depth compare
//! [`wgpu::CompareFunction::Less`] and `LoadOp::Load` on both views.

use crate::composite::{TargetError, TargetViews, key_of, record_composite};
use crate::composite_split::{ColorRoute, CompositeRoute, DepthRoute, RouteInputs, route};
use crate::gpu::catching;
use crate::methods::FrameTargets;
use crate::renderer::Renderer;
use strata_camera::Camera;

pub use crate::composite::{COLOR_TARGET_FORMATS, DEPTH_TARGET_FORMATS};

impl Renderer {
    /// Embedding: draw one frame of the active method into the caller's
    /// colour and depth views (every pixel; see the depth convention in
    /// [`crate::embed`]) and submit it on the renderer's queue, without
    /// waiting. Draw your own objects afterwards, in a later submission or
    /// later in the same queue, with `LoadOp::Load`, the same
    /// `camera.view_proj()` and depth compare `Less`: they compose with the
    /// terrain by the depth test. GPU errors of the frame itself are reported
    /// by the next call or [`crate::Gpu::wait`].
    ///
    /// Refused with a [`TargetError`] (nothing drawn): a colour or depth
    /// format the pass cannot draw into, colour and depth of different
    /// sample counts, a target not of the renderer's size, a view of another
    /// device.
    ///
    /// ```no_run
    /// # fn f(renderer: &mut strata_render::Renderer, camera: &strata_camera::Camera,
    /// #      queue: &wgpu::Queue, surface: &wgpu::Surface, depth: &wgpu::TextureView)
    /// #      -> anyhow::Result<()> {
    /// let wgpu::CurrentSurfaceTexture::Success(frame) = surface.get_current_texture() else {
    ///     return Ok(()); // reconfigure, skip the frame...
    /// };
    /// let color = frame.texture.create_view(&Default::default());
    /// renderer.render_into(camera, &strata_render::TargetViews::new(&color, depth))?;
    /// // ... your own passes into `color` and `depth`: LoadOp::Load, depth compare Less ...
    /// queue.present(frame);
    /// # Ok(()) }
    /// ```
    pub fn render_into(
        &mut self,
        camera: &Camera,
        targets: &TargetViews<'_>,
    ) -> anyhow::Result<()> {
        let size = (self.shared().width, self.shared().height);
        let key = key_of(targets, size)?;
        let route = self.composite_route(targets, key, true);
        let device = self.shared().device.clone();
        // Errors from here on concern the caller's views (a foreign device,
        // a view wgpu refuses): caught here to name them, not left to the
        // device's error sink (in a browser they reach the sink).
        let mut composite = std::mem::take(&mut self.composite);
        let mut split = std::mem::take(&mut self.split);
        let (recorded, error) = catching(&device, wgpu::ErrorFilter::Validation, || {
            match route {
                CompositeRoute::Split { color, depth } => {
                    // Depth from the method's own image skips the blit into
                    // Strata's depth target; a copy reads that target.
                    let fill_depth = depth == DepthRoute::Copy;
                    // Targets of Strata's own formats take the frame itself.
                    let into = FrameTargets {
                        color: (color == ColorRoute::Direct).then_some(targets.color),
                        depth: (depth == DepthRoute::Direct).then_some(targets.depth),
                    };
                    let mut encoder = self.record_frame_into(camera, fill_depth, into)?;
                    split.record(
                        &mut encoder,
                        self.shared(),
                        targets,
                        (color, depth),
                        self.active_depth_image(),
                        Some(&self.timer),
                    )?;
                    if color == ColorRoute::Pass {
                        let pipeline = composite.pipeline(&device, key, false)?;
                        let group = composite.group(self.shared(), None);
                        let stamps = self.timer.render("composite colour");
                        let key = (key, false);
                        record_composite(&mut encoder, targets, key, &pipeline, &group, stamps);
                    }
                    self.timer.resolve(&mut encoder);
                    anyhow::Ok((encoder.finish(), CompositeRoute::Split { color, depth }))
                }
                CompositeRoute::Pass => {
                    // The composite reads a compute method's depth image in
                    // place, else the shared depth target: fill that.
                    let pipeline = composite.pipeline(&device, key, true)?;
                    let image = self.active_depth_image().cloned();
                    let group = composite.group(self.shared(), image.as_ref());
                    let fill_depth = image.is_none();
                    let mut encoder =
                        self.record_frame_into(camera, fill_depth, FrameTargets::default())?;
                    let stamps = self.timer.render("composite");
                    let key = (key, true);
                    record_composite(&mut encoder, targets, key, &pipeline, &group, stamps);
                    self.timer.resolve(&mut encoder);
                    anyhow::Ok((encoder.finish(), route))
                }
            }
        });
        self.composite = composite;
        self.split = split;
        if let Some(error) = error {
            let message = error_chain(&error);
            if message.contains("doesn't match") {
                return Err(TargetError::OtherDevice(message).into());
            }
            return Err(TargetError::Refused {
                color: key.color,
                depth: key.depth,
                samples: key.samples,
                message,
            }
            .into());
        }
        let (commands, taken) = recorded?;
        self.last_road = Some(taken);
        self.submit(commands);
        self.errors.check()
    }

    /// [`Renderer::render_into`], then wait for the GPU and return the
    /// frame's timings, the passes into the caller's views included
    /// (`composite colour`, `composite depth` or `composite`; a texture copy
    /// has no pass to stamp). What `examples/composite_cost.rs` sets against
    /// [`Renderer::render_frame`].
    pub fn render_into_timed(
        &mut self,
        camera: &Camera,
        targets: &TargetViews<'_>,
    ) -> anyhow::Result<crate::FrameTimings> {
        let start = std::time::Instant::now();
        self.render_into(camera, targets)?;
        crate::gpu::wait_device(&self.shared().device, &self.errors)?;
        let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        let (gpu_ms, passes) = self.timer.read(&self.shared().device, &self.errors)?;
        Ok(crate::FrameTimings {
            gpu_ms,
            cpu_ms,
            record_ms: 0.0,
            passes,
            untimed_passes: self.timer.untimed(),
        })
    }

    /// The road the last [`Renderer::render_into`] took (`None` before the
    /// first). Where it says [`ColorRoute::Direct`] or
    /// [`DepthRoute::Direct`], the method drew that into your view itself and
    /// Strata's own target does not hold the frame: [`Renderer::read_color`],
    /// [`Renderer::read_depth`] and [`Renderer::record_copy_into`] refuse
    /// until the next [`Renderer::render_frame`].
    pub fn last_road(&self) -> Option<CompositeRoute> {
        self.last_road
    }

    /// An error unless Strata's own colour target holds the last frame.
    pub(crate) fn shared_color_current(&self) -> anyhow::Result<()> {
        if self.color_target_current {
            return Ok(());
        }
        anyhow::bail!(
            "the frame last drawn ({}) stored its colour straight into the caller's texture (`render_into`), not into Strata's colour target: read it there, or draw the frame with `render_frame`",
            self.method_name()
        )
    }
}

impl Renderer {
    /// Record only the copy of the frame last drawn (by
    /// [`Renderer::render_frame`], or by [`Renderer::render_into`] where it
    /// left the frame in Strata's targets: see [`Renderer::last_road`]) into
    /// the caller's views, in the caller's encoder: to show one frame in
    /// more targets, or to time a copy road (`timestamp_writes`;
    /// `examples/composite_cost.rs` reports it beside what `render_into`
    /// adds).
    /// The same checks and the same road as `render_into`
    /// ([`CompositeRoute`]; on the split road the stamps are written by an
    /// empty compute pass before and one after it); wgpu errors reach the
    /// device's error sink. Returns the road taken.
    pub fn record_copy_into(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &TargetViews<'_>,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> anyhow::Result<CompositeRoute> {
        let key = key_of(targets, (self.shared().width, self.shared().height))?;
        let route = self.composite_route(targets, key, false);
        // A compute method's depth is read from its image on every road
        // but the depth copy.
        let reads_shared_depth = match route {
            CompositeRoute::Split { depth, .. } => depth == DepthRoute::Copy,
            CompositeRoute::Pass => self.active_depth_image().is_none(),
        };
        self.shared_color_current()?;
        if reads_shared_depth && !self.depth_target_current {
            anyhow::bail!(
                "the frame last drawn ({}) left its depth in the method's own image, not in the shared depth target this copy reads: draw it with `render_into`, or call `set_depth_attachment(true)` before `render_frame`",
                self.method_name()
            );
        }
        if let CompositeRoute::Split { color, depth } = route {
            let stamp = |encoder: &mut wgpu::CommandEncoder, start: bool| {
                let Some(w) = &timestamp_writes else { return };
                let index = match start {
                    true => w.beginning_of_pass_write_index,
                    false => w.end_of_pass_write_index,
                };
                encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("composite stamp"),
                    timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                        query_set: w.query_set,
                        beginning_of_pass_write_index: index.filter(|_| !start),
                        end_of_pass_write_index: index.filter(|_| start),
                    }),
                });
            };
            stamp(encoder, true);
            let mut split = std::mem::take(&mut self.split);
            let recorded = split.record(
                encoder,
                self.shared(),
                targets,
                (color, depth),
                self.active_depth_image(),
                None,
            );
            self.split = split;
            recorded?;
            stamp(encoder, false);
            return Ok(route);
        }
        let device = self.shared().device.clone();
        let mut composite = std::mem::take(&mut self.composite);
        let pipeline = composite.pipeline(&device, key, true);
        let image = self.active_depth_image().cloned();
        let group = composite.group(self.shared(), image.as_ref());
        self.composite = composite;
        let key = (key, true);
        record_composite(encoder, targets, key, &pipeline?, &group, timestamp_writes);
        Ok(route)
    }

    /// The road into `targets`: of a frame still to draw
    /// ([`Renderer::render_into`], `fresh_frame`) or of the last frame's copy.
    fn composite_route(
        &self,
        targets: &TargetViews<'_>,
        key: crate::composite::Key,
        fresh_frame: bool,
    ) -> CompositeRoute {
        let caps = &self.shared().caps;
        route(
            targets,
            key,
            RouteInputs {
                compute: caps.compute,
                depth_copies: caps.depth_copies,
                depth_image: self.active_depth_image().is_some(),
                fresh_frame,
                color_by_attachment: self.active_method().draws_color_by_attachment(),
            },
        )
    }
}

/// An error's causes on one line: wgpu's own message is a multi-line dump
/// ("Validation Error / Caused by: ..."); its source chain says the same.
fn error_chain(error: &wgpu::Error) -> String {
    let mut parts = Vec::new();
    let mut source = std::error::Error::source(error);
    while let Some(s) = source {
        parts.push(s.to_string());
        source = s.source();
    }
    match parts.is_empty() {
        true => error.to_string().lines().collect::<Vec<_>>().join(" "),
        false => parts.join(": "),
    }
}
