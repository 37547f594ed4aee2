//! The methods: one module each, behind one trait.
//!
//! # Adding a method
//! 1. Write `src/methods/<name>.rs` with a struct implementing [`Method`] and a
//!    `pub fn create(shared: &Shared, level: &Level, settings: &MethodSettings)
//!    -> anyhow::Result<Box<dyn Method>>` that validates its own settings field
//!    (clear error on 0 etc.) and builds its pipelines.
//! 2. Put its WGSL in `shaders/<name>.wgsl`, starting with
//!    `#include "frame.wgsl"`, `"surface.wgsl"`, `"shading.wgsl"` (and
//!    `"ray_core.wgsl"`, `"fullscreen.wgsl"` as needed); add the file to
//!    `shaders::SOURCES` and `shaders::ENTRY_SHADERS` (the naga test validates it).
//! 3. Add one entry to [`METHODS`] below: the only place a name maps to code,
//!    with the [`Capability`]s beyond WebGL2's baseline the method uses
//!    (compute, storage textures, storage buffers per stage), so an adapter
//!    without them refuses it before any GPU work.
//!
//! # The contract
//! - Group 0 of every pipeline is the shared frame ([`Shared::frame_layout`],
//!   bind [`Shared::frame_group`]); build layouts with [`Shared::pipeline_layout`].
//!   Your own bindings go in groups 1 and up.
//! - Draw into [`Shared::color_view`] ([`crate::COLOR_FORMAT`]) and
//!   [`Shared::depth_view`] ([`crate::DEPTH_FORMAT`], depth 0 near .. 1 far
//!   from `Camera::view_proj`, `Less` test). Your first pass that touches them
//!   must clear them: colour to [`crate::frame::sky_clear`], depth to 1.0.
//!   Every pixel ends with a colour and a depth (sky = 1.0).
//! - Shade every surface point with `shade(p, ray_dir)` from `shading.wgsl`
//!   (the mesh: `shade_with_normal`), so palette, light, cave ambient,
//!   shadow and fog are the same in every method.
//! - Every pass you begin takes its timestamp writes from
//!   `frame.timer.render("label")` / `.compute("label")`, so the frame's GPU
//!   time is the sum over passes.
//! - `apply_edit` runs after the shared terrain texture has been updated;
//!   methods that only read the texture need not override it.
//! - `retained_bytes` counts only what the method allocates beyond [`Shared`].
//! - `update_settings` takes what it can in place (the viewer's sliders);
//!   the default asks for a rebuild.
//! - A method that binds the shared targets, or sizes anything by them, in
//!   `create` must redo that in `resize` (the viewer follows its window).

mod build_bindings;
mod common;
#[doc(hidden)]
pub mod forward;
#[doc(hidden)]
pub mod mesh;
mod mesh_pool;
#[doc(hidden)]
pub mod painted;
#[doc(hidden)]
pub mod ray;
#[doc(hidden)]
pub mod ray_compute;
#[doc(hidden)]
pub mod ray_exact;
#[doc(hidden)]
pub mod ray_exact_build;
#[doc(hidden)]
pub mod scattered;
mod scattered_grid;
mod slice_tiles;
#[doc(hidden)]
pub mod sliced;
mod sliced_refine;
#[doc(hidden)]
pub mod voxel;
#[doc(hidden)]
pub mod voxel_build;

/// The integration tests' helpers (adapter skip, metric loops, distance
/// comparisons), shared by the methods' unit tests; `strata_render::` paths
/// there resolve through the `extern crate self` alias in lib.rs.
#[cfg(test)]
#[path = "../../tests/common/mod.rs"]
pub(crate) mod test_common;

use crate::caps::{Capabilities, Capability, Refusal};
use crate::frame::Shared;
use crate::timing::PassTimer;
use serde::{Deserialize, Serialize};
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};

/// One settings struct for all methods; each reads its own field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodSettings {
    /// `ray`, `ray-compute`: forward samples per ray (the paper's 128).
    pub ray_steps: u32,
    /// `voxel*`: occupancy voxel size in texels (x, y, z); the paper's (4, 8, 2).
    pub voxel_size: [u32; 3],
    /// `voxel*`: traversal step budget (the paper's 100).
    pub voxel_steps: u32,
    /// `sliced`: horizontal slices (the paper's 512).
    pub slices: u32,
    /// `sliced`: the slices decide coverage, then one full-screen pass puts
    /// each covered pixel's exact surface crossing, searched along its ray
    /// up to the nearest kept slice, in depth and colour. Off: the paper's
    /// plain slicer.
    #[serde(default)]
    pub sliced_refine: bool,
    /// `scattered`: footprint grid density (x, y, z); the paper's (4, 4, 4).
    pub scatter_density: [f32; 3],
    /// `mesh`: fit quality q in [0, 1]; max error 2^(4(1 - q)) (0.5 → 4).
    pub mesh_quality: f32,
    /// `mesh`: fit constrained to the single/double outline (`mesh:0.5o`).
    #[serde(default)]
    pub mesh_outline: bool,
    /// `mesh`: each chunk takes the coarsest LOD whose max error, projected
    /// to the screen at the chunk's distance, is at most this many pixels.
    #[serde(default = "default_lod_pixels")]
    pub mesh_lod_pixels: f32,
    /// `mesh`, a diagnostic: shade with the height-field gradient normal of
    /// the column the pixel takes its colour from (as every other method
    /// does) in place of the triangle's flat normal, to measure the flat
    /// normal's share of the mesh's colour error (`mesh:0.5/gradient`).
    #[serde(default)]
    pub mesh_gradient_normal: bool,
    /// The shared shadow map (`--no-shadows` turns it off).
    pub shadows: bool,
}

impl Default for MethodSettings {
    fn default() -> Self {
        MethodSettings {
            ray_steps: 128,
            voxel_size: [4, 8, 2],
            voxel_steps: 100,
            slices: 512,
            sliced_refine: false,
            scatter_density: [4.0, 4.0, 4.0],
            mesh_quality: 0.5,
            mesh_outline: false,
            mesh_lod_pixels: default_lod_pixels(),
            mesh_gradient_normal: false,
            shadows: true,
        }
    }
}

/// The mesh's LOD tolerance in pixels (issue 17: at most 1).
fn default_lod_pixels() -> f32 {
    1.0
}

/// Memory a method keeps beyond the shared resources.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RetainedBytes {
    /// Bytes of GPU buffers and textures.
    pub gpu: u64,
    /// Bytes of CPU-side data.
    pub cpu: u64,
}

/// What a method gets while recording one frame.
pub struct Frame<'a> {
    /// The frame's camera.
    pub camera: &'a Camera,
    /// Timestamp writes for each pass.
    pub timer: &'a PassTimer,
    /// Frames rendered before this one by this renderer.
    pub index: u64,
    /// Whether the shared depth target must hold this frame's depth. Methods
    /// that rasterise write it anyway; those whose depth lands in an image of
    /// their own ([`Method::depth_image`]) copy it there only when this is
    /// set (`Renderer::set_depth_attachment`, `render_into`).
    pub depth_attachment: bool,
}

/// One way of drawing the terrain. `Send`, so a method can be built on a
/// background thread (the viewer's first use of `mesh`) and handed over.
pub trait Method: Send {
    /// The name the factory knows it by.
    fn name(&self) -> &'static str;

    /// The level changed inside `rects` (already uploaded to the shared
    /// terrain texture); update derived data.
    fn apply_edit(
        &mut self,
        _shared: &Shared,
        _level: &Level,
        _rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        Ok(())
    }

    /// The shared targets were recreated at `shared.width` x `shared.height`:
    /// rebuild what was sized for or bound to the old ones (methods that only
    /// attach the targets when recording need nothing).
    fn resize(&mut self, _shared: &Shared) -> anyhow::Result<()> {
        Ok(())
    }

    /// Take new settings without a rebuild where the method can (a uniform,
    /// a count): `Ok(true)`. `Ok(false)` when a setting it reads needs a
    /// rebuild (the mesh's quality, the voxel size); an invalid value is an
    /// error and changes nothing.
    fn update_settings(
        &mut self,
        _shared: &Shared,
        _settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        Ok(false)
    }

    /// CPU work and uploads before recording a frame (the frame's globals are
    /// already written).
    fn prepare(&mut self, _shared: &Shared, _camera: &Camera) -> anyhow::Result<()> {
        Ok(())
    }

    /// Fill the shared shadow map (`Shared::shadow_view`) this frame, in
    /// place of the renderer's own pass, and say so with `true`. Called before
    /// `record` on frames that need a new map; the default leaves it to the
    /// renderer (`shadow.wgsl`).
    fn record_shadow_map(
        &self,
        _shared: &Shared,
        _frame: &Frame<'_>,
        _encoder: &mut wgpu::CommandEncoder,
    ) -> bool {
        false
    }

    /// Whether the shadow map this method fills ([`Method::record_shadow_map`])
    /// holds only the texels its own pixels sample, so that no other method
    /// (the viewer's other A/B side) may reuse it. Default: no.
    fn shadow_map_is_partial(&self) -> bool {
        false
    }

    /// Record this frame's passes.
    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder);

    /// GPU and CPU bytes owned beyond the shared resources.
    fn retained_bytes(&self) -> RetainedBytes;

    /// Where this method leaves the frame's depth when it is not the shared
    /// depth target: an `R32Float` texture (`COPY_SRC`) of depth-buffer
    /// values, every pixel written each frame (the compute marches). `None`
    /// (the default): the method draws depth into the shared target.
    fn depth_image(&self) -> Option<&wgpu::Texture> {
        None
    }
}

/// Builds a method.
pub type Constructor = fn(&Shared, &Level, &MethodSettings) -> anyhow::Result<Box<dyn Method>>;

/// Starts a method's build in slices ([`BuildSteps`]).
pub type StepsConstructor = fn(&MethodSettings) -> anyhow::Result<Box<dyn BuildSteps>>;

/// A method built a slice at a time on the calling thread: a browser page
/// has one thread, so it builds between frames and keeps drawing. Natively
/// a build runs whole on a thread of its own ([`create`]).
pub trait BuildSteps {
    /// Work for about `budget_ms` (at least one unit of work); the method
    /// once built. `level` must be the level of the first call.
    fn step(
        &mut self,
        shared: &Shared,
        level: &Level,
        budget_ms: f64,
    ) -> anyhow::Result<Option<Box<dyn Method>>>;
}

/// A method without a sliced build: built whole in its first step.
struct Whole {
    create: Constructor,
    settings: MethodSettings,
}

impl BuildSteps for Whole {
    fn step(
        &mut self,
        shared: &Shared,
        level: &Level,
        _: f64,
    ) -> anyhow::Result<Option<Box<dyn Method>>> {
        (self.create)(shared, level, &self.settings).map(Some)
    }
}

/// A method by name: how to build it and what it needs of the adapter.
pub struct MethodEntry {
    /// The name `Renderer::new` and `--method` take.
    pub name: &'static str,
    /// Builds it whole.
    pub create: Constructor,
    /// A build in slices, for methods whose CPU preparation takes long
    /// (built whole in one step when `None`).
    pub in_steps: Option<StepsConstructor>,
    /// Capabilities beyond WebGL2's baseline (a fragment pass reading the
    /// terrain texture) that its pipelines use.
    pub needs: &'static [Capability],
}

impl MethodEntry {
    /// `Err` naming what `caps` lacks for this method.
    pub fn check(&self, caps: &Capabilities) -> Result<(), Refusal> {
        let missing = caps.missing(self.needs);
        if missing.is_empty() {
            Ok(())
        } else {
            Err(Refusal {
                method: self.name.to_string(),
                missing,
            })
        }
    }
}

use Capability::{ComputeShaders, FragmentStorage, StorageTextures, VertexStorage};

/// Every method: the only place a name maps to code.
pub const METHODS: &[MethodEntry] = &[
    MethodEntry {
        name: "ray",
        create: ray::create,
        in_steps: None,
        needs: &[],
    },
    MethodEntry {
        name: "ray-compute",
        create: ray_compute::create,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
    },
    MethodEntry {
        name: "ray-exact",
        // The pyramid is built and edited by compute passes; the march is a
        // compute dispatch writing storage images.
        create: ray_exact::create,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
    },
    MethodEntry {
        name: "ray-exact-fragment",
        create: ray_exact::create_fragment,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
    },
    MethodEntry {
        name: "voxel",
        // The occupancy pyramid is built and edited by compute passes.
        create: voxel::create,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
    },
    MethodEntry {
        name: "voxel-compute",
        create: voxel::create_compute,
        in_steps: None,
        needs: &[ComputeShaders, StorageTextures],
    },
    MethodEntry {
        name: "painted",
        create: painted::create,
        in_steps: None,
        needs: &[],
    },
    MethodEntry {
        name: "sliced",
        create: sliced::create,
        in_steps: None,
        needs: &[],
    },
    MethodEntry {
        name: "mesh",
        // Vertices fetch their chunk's placement from a storage buffer.
        create: mesh::create,
        in_steps: Some(mesh::build_in_steps),
        needs: &[VertexStorage],
    },
    MethodEntry {
        name: "scattered",
        // Compute scatters into an atomic screen buffer; a fragment pass resolves it.
        create: scattered::create,
        in_steps: None,
        needs: &[ComputeShaders, FragmentStorage],
    },
];

/// The names [`create`] accepts.
pub fn names() -> Vec<&'static str> {
    METHODS.iter().map(|m| m.name).collect()
}

/// The method called `name`, or an error listing the known ones.
pub fn entry(name: &str) -> anyhow::Result<&'static MethodEntry> {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .ok_or_else(|| anyhow::anyhow!("unknown method `{name}`; known: {}", names().join(", ")))
}

/// Whether method `name` runs on an adapter with `caps`: `Err` with the
/// reason (an unknown name, or the capabilities it lacks).
pub fn check_support(name: &str, caps: &Capabilities) -> anyhow::Result<()> {
    entry(name)?.check(caps)?;
    Ok(())
}

/// The methods an adapter with `caps` can run.
pub fn supported(caps: &Capabilities) -> Vec<&'static str> {
    METHODS
        .iter()
        .filter(|m| m.check(caps).is_ok())
        .map(|m| m.name)
        .collect()
}

/// Build the method called `name`; refused before any GPU work when the
/// shared frame's adapter lacks what it needs. A GPU error during the build
/// (out of memory, a refused allocation) is an error naming the method and
/// the sizes ([`crate::build_guard`]).
pub fn create(
    name: &str,
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let entry = entry(name)?;
    entry.check(&shared.caps)?;
    let target = crate::build_guard::BuildTarget {
        method: entry.name,
        width: shared.width,
        height: shared.height,
        level,
    };
    crate::build_guard::guarded(&shared.device, &target, || {
        (entry.create)(shared, level, settings)
    })
}

/// Start building the method called `name` in slices ([`BuildSteps`]);
/// refused at once, like [`create`], when the adapter lacks what it needs.
pub fn create_in_steps(
    name: &str,
    caps: &Capabilities,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn BuildSteps>> {
    let entry = entry(name)?;
    entry.check(caps)?;
    match entry.in_steps {
        Some(start) => start(settings),
        None => Ok(Box::new(Whole {
            create: entry.create,
            settings: settings.clone(),
        })),
    }
}
