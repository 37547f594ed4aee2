//! The wgpu renderer: the terrain on the GPU in one layout, the shared frame
//! (camera, palette, light, cave ambient, fog, a 1024² shadow map), and one
//! module per method behind [`methods::Method`].
//!
//! ```no_run
//! # fn main() -> anyhow::Result<()> {
//! # let world: strata_level::World = unimplemented!();
//! # let camera: strata_camera::Camera = unimplemented!();
//! use strata_render::{Gpu, Renderer, TerrainColors, MethodSettings};
//! let gpu = Gpu::headless()?;
//! let mut r = Renderer::new(&gpu, &world.level, &TerrainColors::from_world(&world),
//!                           "ray", &MethodSettings::default(), 320, 200)?;
//! let timings = r.render_frame(&camera)?;   // gpu_ms (per-pass sum), cpu_ms
//! let depth = r.read_depth()?;              // depth-buffer values, 1.0 = sky
//! # Ok(()) }
//! ```

//! # Embedding in your own engine
//! - Your device: [`Gpu::from_device`]`(instance, adapter, device, queue)`
//!   instead of [`Gpu::headless`]; Strata records and submits on your queue.
//! - Composing: after [`Renderer::render_frame`] the terrain's colour and
//!   depth are in [`Renderer::shared`]`().color_view` ([`COLOR_FORMAT`]) and
//!   `.depth_view` ([`DEPTH_FORMAT`]: 0 near .. 1 far, 1 = sky, one sample)
//!   under `Camera::view_proj`, for every method. Draw your own objects into
//!   them with `LoadOp::Load`, depth compare `Less` and the same
//!   `view_proj`; they compose with the terrain by the ordinary depth test
//!   (`tests/compose.rs` does it for every method), then copy the colour to
//!   your surface. Pipelines for those targets must use these two formats
//!   and a sample count of 1 (wgpu's validation names any other).
//! - Edits: [`Renderer::apply_edit`] updates the GPU data; a CPU follower
//!   (`strata_collide::TerrainCollider`) registered with
//!   [`Renderer::set_edit_listener`] changes in the same call.
//!
//! Stable: [`Gpu`] (`headless`, `from_device`), [`Renderer`] (`new`,
//! `render_frame`, `apply_edit`, `set_edit_listener`, `read_color`,
//! `read_depth`, `shared().color_view/depth_view`), [`TerrainColors`],
//! [`MethodSettings`], [`COLOR_FORMAT`], [`DEPTH_FORMAT`]. Everything else
//! (the method modules, `Shared`'s other fields) may change.

// Lets the in-crate tests share `tests/common` (which names this crate).
#[cfg(test)]
extern crate self as strata_render;

pub mod build_guard;
pub mod caps;
pub mod depth_read;
pub mod embed;
pub mod frame;
pub(crate) mod fullscreen;
pub mod gpu;
pub mod methods;
pub mod renderer;
pub mod report;
pub mod self_check;
pub mod shaders;
pub mod shadow;
pub mod terrain;
pub mod timing;

pub use caps::{Capabilities, Capability, Refusal};
pub use embed::{COLOR_TARGET_FORMATS, DEPTH_TARGET_FORMATS, TargetError, TargetViews};
pub use frame::{COLOR_FORMAT, DEPTH_FORMAT, SHADOW_SIZE, Shared, TerrainColors};
pub use gpu::{AdapterChoice, AdapterReport, BackendChoice, Gpu};
pub use methods::{Method, MethodSettings, RetainedBytes};
pub use renderer::Renderer;
pub use timing::{FrameTimings, Stats};
