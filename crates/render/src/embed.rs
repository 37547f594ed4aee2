//! Embedding: draw the terrain into the caller's own colour and depth views
//! ([`Renderer::render_into`]), so the caller's rasterised objects, drawn
//! afterwards with the ordinary depth test, compose with it.
//!
//! How: the active method renders into Strata's own targets as in
//! [`Renderer::render_frame`], then one full-screen pass in the same command
//! buffer writes that frame's colour and depth (`frag_depth`) into the
//! caller's views. One pass serves every format pair and sample count (a
//! texture copy would serve only Strata's own formats at one sample, and GL
//! has no depth copies), so there is a single path to test. A multisampled
//! target receives each pixel's colour and depth in all its samples (the
//! terrain is drawn at one sample per pixel; your objects get the MSAA).
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
use crate::gpu::catching;
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
        let device = self.shared().device.clone();
        // Errors from here on concern the caller's views (a foreign device,
        // a view wgpu refuses): caught here to name them, not left to the
        // device's error sink (in a browser they reach the sink).
        let mut composite = std::mem::take(&mut self.composite);
        let (recorded, error) = catching(&device, wgpu::ErrorFilter::Validation, || {
            let pipeline = composite.pipeline(&device, key)?;
            let group = composite.group(self.shared());
            // The composite reads the shared depth target: fill it.
            let mut encoder = self.record_frame_with(camera, true)?;
            record_composite(&mut encoder, targets, key, &pipeline, &group, None);
            anyhow::Ok(encoder.finish())
        });
        self.composite = composite;
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
        self.submit(recorded?);
        self.errors.check()
    }
}

impl Renderer {
    /// Record only the copy of the frame last drawn (by
    /// [`Renderer::render_frame`] or [`Renderer::render_into`]) into the
    /// caller's views, in the caller's encoder: to show one frame in more
    /// targets, or to time the copy (`timestamp_writes`; what
    /// `examples/composite_cost.rs` measures). The same checks as
    /// `render_into`; wgpu errors reach the device's error sink.
    pub fn record_copy_into(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &TargetViews<'_>,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> anyhow::Result<()> {
        let key = key_of(targets, (self.shared().width, self.shared().height))?;
        if !self.depth_target_current {
            anyhow::bail!(
                "the frame last drawn ({}) left its depth in the method's own image, not in the shared depth target this copy reads: draw it with `render_into`, or call `set_depth_attachment(true)` before `render_frame`",
                self.method_name()
            );
        }
        let device = self.shared().device.clone();
        let mut composite = std::mem::take(&mut self.composite);
        let pipeline = composite.pipeline(&device, key);
        let group = composite.group(self.shared());
        self.composite = composite;
        record_composite(encoder, targets, key, &pipeline?, &group, timestamp_writes);
        Ok(())
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
