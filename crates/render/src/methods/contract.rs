//! What every method shares with the renderer: the settings, the [`Method`]
//! trait and what it gets per frame, and the sliced build. The methods and
//! the registry ([`super::METHODS`]) both import this; it imports neither.

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
    /// `sliced`: each slice fragment whose point is air walks its own gap
    /// along a grazing ray, as issue 36 first did, in place of plain
    /// `sliced`'s one walk per pixel after the slices (the refined slicer:
    /// its marks walk on every frame); for A/B (`sliced:512/fragwalk`).
    #[serde(default)]
    pub sliced_fragment_walk: bool,
    /// `sliced`: shade every kept slice fragment in the slice pass, as the
    /// paper's slicer does, in place of plain `sliced`'s marks and one
    /// shading a pixel after them; for A/B (`sliced:512/forward`).
    #[serde(default)]
    pub sliced_forward_shading: bool,
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
    /// `mesh`: colour each fragment in the raster pass (the path of adapters
    /// without compute) rather than the deferred frame's one compute pass
    /// over the covered pixels; for A/B measurements (`mesh:0.5/fragment`).
    #[serde(default)]
    pub mesh_fragment: bool,
    /// `mesh`: every sample at its texel's centre, as before issue 36
    /// (`mesh:0.5/centres`, for A/B); by default a sample beside a wall on
    /// one side moves half a texel to it, so walls stand on texel boundaries.
    #[serde(default)]
    pub mesh_texel_centres: bool,
    /// The shared shadow map (`--no-shadows` turns it off).
    pub shadows: bool,
    /// `ray`, `voxel`: each camera ray's march begins where its 8x8-pixel
    /// tile's beam may first meet the ground (a compute pre-pass over a
    /// max-height pyramid; `ray` also ends a rising ray above the map's
    /// highest top): the same image in fewer steps; `sliced`'s per-pixel
    /// walks (the gap and refine passes) begin there too. Off
    /// (`ray:128/nobeam`, `voxel:4,8,2/100/nobeam`, `sliced:512/nobeam`):
    /// from the near plane as before, for A/B timing.
    #[serde(default = "default_march_beam")]
    pub march_beam: bool,
}

impl Default for MethodSettings {
    fn default() -> Self {
        MethodSettings {
            ray_steps: 128,
            voxel_size: [4, 8, 2],
            voxel_steps: 100,
            slices: 512,
            sliced_refine: false,
            sliced_fragment_walk: false,
            sliced_forward_shading: false,
            scatter_density: [4.0, 4.0, 4.0],
            mesh_quality: 0.5,
            mesh_outline: false,
            mesh_lod_pixels: default_lod_pixels(),
            mesh_gradient_normal: false,
            mesh_fragment: false,
            mesh_texel_centres: false,
            shadows: true,
            march_beam: true,
        }
    }
}

fn default_march_beam() -> bool {
    true
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
    /// The caller's views the render passes draw into in place of the
    /// shared targets (an embedding frame whose formats match them).
    pub targets: FrameTargets<'a>,
}

/// The caller's views an embedding frame's render passes attach in place of
/// the shared colour and depth targets (`Renderer::render_into` when the
/// formats are Strata's own: `COLOR_FORMAT`, `DEPTH_FORMAT`, one sample).
#[derive(Clone, Copy, Default)]
pub struct FrameTargets<'a> {
    /// In place of the shared colour target.
    pub color: Option<&'a wgpu::TextureView>,
    /// In place of the shared depth target.
    pub depth: Option<&'a wgpu::TextureView>,
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

    /// Finish the derived data of every edit handed to
    /// [`apply_edit`](Method::apply_edit) so far (waiting for work it left in
    /// flight), so that the next frame shows them all. For checks against a
    /// fresh build; a game's frame never calls it. Default: nothing is left
    /// in flight.
    fn settle_edits(&mut self, _shared: &Shared) -> anyhow::Result<()> {
        Ok(())
    }

    /// How many of the latest [`apply_edit`](Method::apply_edit) calls the
    /// frame prepared last did not yet show in full (work still in flight).
    /// Default 0: an edit is drawn by the next frame.
    fn pending_edits(&self) -> u64 {
        0
    }

    /// The shared targets were recreated at `shared.width` x `shared.height`:
    /// rebuild what was sized for or bound to the old ones (methods that only
    /// attach the targets when recording need nothing).
    fn resize(&mut self, _shared: &Shared) -> anyhow::Result<()> {
        Ok(())
    }

    /// Embedding ([`Renderer::render_into`](crate::Renderer::render_into)):
    /// make the next frames' shading store colour straight into `view` (the
    /// caller's `Rgba8Unorm` texture with `STORAGE_BINDING`, of the shared
    /// targets' size) in place of the shared colour target, or again into
    /// the shared target (`None`). Returns whether the frames' colour now
    /// goes where asked: the compute methods can (their shading is a
    /// storage write), the default only takes `None`.
    fn store_color_into(
        &mut self,
        _shared: &Shared,
        view: Option<&wgpu::TextureView>,
    ) -> anyhow::Result<bool> {
        Ok(view.is_none())
    }

    /// Whether this method's frames draw their colour through render passes
    /// into the shared colour target (every rasterising method; what an
    /// embedding frame may point at the caller's texture instead). The
    /// compute methods store colour from a compute pass and say no.
    fn draws_color_by_attachment(&self) -> bool {
        true
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
    /// renderer (`shadow.wgsl`). A method that fills it calls
    /// `Shared::shadow_map_written` (methods that keep texels across frames
    /// read the count).
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

    /// The frame recorded last was submitted and the GPU is done with it
    /// (`Renderer::render_frame`): read back what it recorded for the CPU.
    fn frame_done(&mut self, _shared: &Shared) -> anyhow::Result<()> {
        Ok(())
    }

    /// The paged terrain this method draws, if any (`crate::paged`).
    fn paged_terrain(&mut self) -> Option<&mut crate::paged::PagedTerrain> {
        None
    }

    /// The paged terrain's source changed inside `chunks` (pages; an edit
    /// written to its store): refresh what derives from them, so the next
    /// frame shows the edit. The default refreshes the paged terrain alone.
    fn refresh_pages(&mut self, shared: &Shared, chunks: &[u32]) -> anyhow::Result<()> {
        match self.paged_terrain() {
            Some(paged) => paged.refresh(shared, chunks),
            None => anyhow::bail!("this renderer draws a whole world: use apply_edit"),
        }
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
/// a build runs whole on a thread of its own ([`create`](super::create)).
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
