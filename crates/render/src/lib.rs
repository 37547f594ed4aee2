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
//!
//! # Embedding in your own engine
//! - Your device: [`Gpu::from_device`]`(instance, adapter, device, queue)`
//!   instead of [`Gpu::headless`]; Strata records and submits on your queue.
//! - Your targets: [`Renderer::render_into`]`(&camera, &TargetViews::new(&color, &depth))`
//!   draws the active method's frame into your colour view (one of
//!   [`COLOR_TARGET_FORMATS`], e.g. the surface's `Bgra8UnormSrgb`) and your
//!   depth view (one of [`DEPTH_TARGET_FORMATS`]), of any sample count the
//!   two share, and submits without waiting. Then draw your own objects into
//!   the same views with `LoadOp::Load`, depth compare `Less` and the same
//!   `camera.view_proj()`: they compose with the terrain by the ordinary depth
//!   test. A format, sample count, size or device it cannot draw into is a
//!   [`TargetError`] naming it. `examples/drive` (a winit window) does it all.
//! - Or Strata's own targets: after [`Renderer::render_frame`] the terrain's
//!   colour and depth are in [`Renderer::shared`]`().color_view`
//!   ([`COLOR_FORMAT`]) and `.depth_view` ([`DEPTH_FORMAT`], one sample);
//!   draw into those the same way (`tests/compose.rs`). Call
//!   [`Renderer::set_depth_attachment`]`(true)` first: by default the compute
//!   marches keep the frame's depth in an image of their own and skip the
//!   copy into `depth_view`.
//! - Edits: [`Renderer::apply_edit`] updates the GPU data; a CPU follower
//!   (`strata_collide::TerrainCollider`) registered with
//!   [`Renderer::set_edit_listener`] changes in the same call.
//!
//! # Depth convention
//! Depth is the depth-buffer value under [`strata_camera::Camera::view_proj`]:
//! world units, z up, right-handed; a perspective projection onto wgpu's clip
//! space, **0 at the near plane (`camera.near`, default 1) .. 1 at the far
//! plane (`camera.far`, default 600)**, not reversed, so compare `Less`; the
//! sky is **1.0**. [`strata_camera::Camera::depth_to_view_z`] linearises it.
//! Colours are sRGB-encoded 8-bit values (`Rgba8Unorm` holds them as they are).
//!
//! # Stability
//! Stable (the embedding API): [`Gpu`] (`headless`, `open`, `from_device`,
//! `wait`), [`Renderer`] (`new`, `render_frame`, `render_into`,
//! `record_copy_into`, `resize`, `apply_edit`, `set_edit_listener`,
//! `read_color`, `read_depth`), [`TargetViews`], [`TargetError`],
//! [`COLOR_TARGET_FORMATS`], [`DEPTH_TARGET_FORMATS`], [`TerrainColors`],
//! [`MethodSettings`], [`FrameTimings`], [`COLOR_FORMAT`], [`DEPTH_FORMAT`],
//! `Shared::{color_view, depth_view, device, queue, width, height}`.
//!
//! Internal, may change: each method's module under [`methods`] (and the
//! [`Method`] trait's hooks), `Shared`'s other fields, the measuring hooks
//! ([`Renderer::hold_busy`], `measure`, `set_shadow_reuse`, `shared_handle`,
//! `insert_method`), and the modules hidden from these docs (`report`,
//! `terrain`, `shaders`, `shadow`, `depth_read`, `self_check`,
//! `build_guard`), which are public only for the CLI, the bench and viewer
//! crates and the tests.

#![warn(missing_docs)]

// Lets the in-crate tests share `tests/common` (which names this crate).
#[cfg(test)]
extern crate self as strata_render;

pub mod adapter;
#[doc(hidden)]
pub mod build_guard;
pub mod caps;
pub mod composite;
pub mod composite_split;
#[doc(hidden)]
pub mod depth_read;
pub mod embed;
pub mod frame;
#[doc(hidden)]
pub mod fullscreen;
#[cfg(all(unix, not(target_vendor = "apple"), not(target_arch = "wasm32")))]
pub mod gl_context;
pub mod gpu;
pub mod methods;
pub mod options;
pub mod paged;
pub mod renderer;
#[doc(hidden)]
pub mod report;
#[doc(hidden)]
pub mod self_check;
#[doc(hidden)]
pub mod shaders;
#[doc(hidden)]
pub mod shadow;
#[doc(hidden)]
pub mod terrain;
pub mod timing;

pub use adapter::{AdapterChoice, BackendChoice};
pub use caps::{Capabilities, Capability, Refusal};
pub use composite::{COLOR_TARGET_FORMATS, DEPTH_TARGET_FORMATS, TargetError, TargetViews};
pub use frame::{COLOR_FORMAT, DEPTH_FORMAT, SHADOW_SIZE, Shared, TerrainColors};
pub use gpu::{AdapterReport, Gpu};
pub use methods::{Method, MethodEntry, MethodSettings, RetainedBytes};
pub use options::RenderOptions;
pub use renderer::Renderer;
pub use timing::{FrameTimings, Stats};
