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

// Lets the in-crate tests share `tests/common` (which names this crate).
#[cfg(test)]
extern crate self as strata_render;

pub mod build_guard;
pub mod caps;
pub mod depth_read;
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
pub use frame::{COLOR_FORMAT, DEPTH_FORMAT, SHADOW_SIZE, Shared, TerrainColors};
pub use gpu::{AdapterChoice, AdapterReport, BackendChoice, Gpu};
pub use methods::{Method, MethodSettings, RetainedBytes};
pub use renderer::Renderer;
pub use timing::{FrameTimings, Stats};
