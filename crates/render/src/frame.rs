//! The shared frame resources every method reads: terrain texture, camera and
//! light uniforms, palette + terrain colour ranges, the shadow map, and the
//! colour + depth targets. Bind group 0 of every method's pipelines is
//! [`Shared::frame_layout`]; `shaders/frame.wgsl` declares it.

use crate::caps::{Capabilities, Capability, ShadowPassKind};
use crate::options::RenderOptions;
use crate::terrain::TerrainTexture;
use bytemuck::{Pod, Zeroable};
use strata_camera::Camera;
use strata_camera::light::MAX_COVER_EDGES;
use strata_level::{Level, World};

/// Colour target format: 8-bit RGBA, written raw to `color.png`.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth target format: the depth-buffer values `depth.f32` holds.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Side of the shared shadow map, texels, and the sky colour: shared with the
/// CPU colour reference.
pub use strata_camera::light::{SHADOW_SIZE, SKY};

/// The sky as a clear colour, for the first pass of object-order methods.
pub fn sky_clear() -> wgpu::Color {
    wgpu::Color {
        r: f64::from(SKY[0]),
        g: f64::from(SKY[1]),
        b: f64::from(SKY[2]),
        a: 1.0,
    }
}

/// Palette and per-type colour ranges (the world's `Begin/End Colors`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TerrainColors {
    /// The world's 256-entry RGB palette.
    pub palette: [[u8; 3]; 256],
    /// First palette index of each terrain type's colour ramp.
    pub begin: [u8; 8],
    /// Last palette index of each terrain type's colour ramp.
    pub end: [u8; 8],
}

impl TerrainColors {
    /// The world's palette and colour ranges.
    pub fn from_world(world: &World) -> Self {
        TerrainColors {
            palette: world.palette.colors,
            begin: world.config.begin_colors,
            end: world.config.end_colors,
        }
    }

    /// A stand-in for tests: eight hues, 32 entries each, dark to bright.
    pub fn test_ramps() -> Self {
        const HUES: [[f32; 3]; 8] = [
            [0.2, 0.4, 0.9],
            [0.5, 0.8, 0.3],
            [0.8, 0.7, 0.4],
            [0.6, 0.5, 0.4],
            [0.9, 0.4, 0.3],
            [0.7, 0.7, 0.7],
            [0.4, 0.7, 0.7],
            [0.8, 0.5, 0.8],
        ];
        let mut palette = [[0u8; 3]; 256];
        for (i, c) in palette.iter_mut().enumerate() {
            let hue = HUES[i / 32];
            let k = 0.35 + 0.65 * (i % 32) as f32 / 31.0;
            *c = hue.map(|h| (h * k * 255.0) as u8);
        }
        TerrainColors {
            palette,
            begin: std::array::from_fn(|t| (t * 32) as u8),
            end: std::array::from_fn(|t| (t * 32 + 31) as u8),
        }
    }
}

/// Twin of `Globals` in `frame.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Globals {
    /// `Camera::view_proj`, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// Eye position (xyz, world units); w: focal length, pixels.
    pub eye: [f32; 4],
    /// Unit view direction (xyz); w: near plane.
    pub forward: [f32; 4],
    /// Unit screen-right direction (xyz); w: far plane.
    pub right: [f32; 4],
    /// Unit screen-up direction (xyz).
    pub up: [f32; 4],
    /// Width, height (pixels) and their reciprocals.
    pub screen: [f32; 4],
    /// Unit direction of the light (xyz); w: 1 with shadows on, else 0.
    pub light_dir: [f32; 4],
    /// Shadow map: world origin (xyz); w: texel size.
    pub shadow_origin: [f32; 4],
    /// Shadow map: u axis (xyz); w: its side in texels.
    pub shadow_u: [f32; 4],
    /// Shadow map: v axis (xyz); w: depth bias.
    pub shadow_v: [f32; 4],
    /// Sky colour, 0..1 RGBA (sRGB-encoded values).
    pub sky: [f32; 4],
    /// Level width, height, log2 of the rows per texture layer, mid rule (1: original).
    pub level: [u32; 4],
    /// x: how many of `shadow_cover` apply (0: every shadow texel is cast).
    pub shadow_cover_count: [u32; 4],
    /// The shadow texels this frame casts ([`ShadowCover`]): half-planes
    /// `(nx, ny, d, 0)` in texel coordinates.
    ///
    /// [`ShadowCover`]: strata_camera::light::ShadowCover
    pub shadow_cover: [[f32; 4]; MAX_COVER_EDGES],
    /// Shadow map: the lattice's anchor on its plane (xyz,
    /// `ShadowFrame::anchor`); w: `ShadowFrame::lod_texel`.
    pub shadow_anchor: [f32; 4],
    /// Shadow map: texel (0, 0)'s lattice index (xy, `ShadowFrame::lattice`).
    pub shadow_lattice: [i32; 4],
}

/// Twin of `ShadingParams` in `frame.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct ShadingParams {
    /// Palette as 0..1 RGBA.
    pub palette: [[f32; 4]; 256],
    /// Per terrain type: first and last palette index.
    pub ranges: [[u32; 4]; 8],
}

impl ShadingParams {
    /// The uniform for `colors`.
    pub fn new(colors: &TerrainColors) -> Self {
        ShadingParams {
            palette: colors.palette.map(|c| {
                let [r, g, b] = c.map(|v| f32::from(v) / 255.0);
                [r, g, b, 1.0]
            }),
            ranges: std::array::from_fn(|t| {
                [u32::from(colors.begin[t]), u32::from(colors.end[t]), 0, 0]
            }),
        }
    }
}

/// What the globals need of a level: its size and mid rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelShape {
    /// Level width, texels.
    pub width: u32,
    /// Level height, texels.
    pub height: u32,
    /// How the level's mid byte is read.
    pub mid_rule: strata_level::MidRule,
}

impl LevelShape {
    /// The shape of `level`.
    pub fn of(level: &Level) -> Self {
        LevelShape {
            width: level.width(),
            height: level.height(),
            mid_rule: level.mid_rule,
        }
    }
}

fn v4(v: glam::Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl Globals {
    /// Camera, light and level parameters of one frame.
    pub fn new(
        camera: &Camera,
        level: &LevelShape,
        shadow: &strata_camera::light::ShadowFrame,
    ) -> Self {
        let b = camera.basis();
        let (w, h) = (camera.width as f32, camera.height as f32);
        let mid_add = match level.mid_rule {
            strata_level::MidRule::Original => 1,
            strata_level::MidRule::VangeRs => 0,
        };
        let layer_rows = level.height.min(crate::terrain::MAX_LAYER_ROWS);
        Globals {
            view_proj: camera.view_proj().to_cols_array_2d(),
            eye: v4(camera.position, camera.focal_px),
            forward: v4(b.forward, camera.near),
            right: v4(b.right, camera.far),
            up: v4(b.up, 0.0),
            screen: [w, h, 1.0 / w, 1.0 / h],
            light_dir: v4(shadow.light, if shadow.enabled { 1.0 } else { 0.0 }),
            shadow_origin: v4(shadow.origin, shadow.texel),
            shadow_u: v4(shadow.u, SHADOW_SIZE as f32),
            shadow_v: v4(shadow.v, shadow.bias),
            sky: [SKY[0], SKY[1], SKY[2], 1.0],
            level: [
                level.width,
                level.height,
                layer_rows.trailing_zeros(),
                mid_add,
            ],
            shadow_cover_count: [shadow.cover.count, 0, 0, 0],
            shadow_cover: shadow.cover.planes.map(|[nx, ny, d]| [nx, ny, d, 0.0]),
            shadow_anchor: v4(shadow.anchor, shadow.lod_texel),
            shadow_lattice: [shadow.lattice[0], shadow.lattice[1], 0, 0],
        }
    }
}

/// A single-level 2D texture and its default view.
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    (texture, view)
}

/// A bind group of `resources` at bindings 0, 1, 2, … in order.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: resource.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The colour and depth targets every method draws into.
struct Targets {
    color: wgpu::Texture,
    color_view: wgpu::TextureView,
    depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
}

impl Targets {
    fn new(
        device: &wgpu::Device,
        caps: &Capabilities,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Self> {
        let max = device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            anyhow::bail!(
                "render size {width}x{height} is outside this adapter's 1..={max} pixels per side"
            );
        }
        use wgpu::TextureUsages as U;
        // Compute methods write colour as a storage texture; depth is copied
        // out directly where the adapter can (else `depth_read` samples it).
        let storage = if caps.storage_textures {
            U::STORAGE_BINDING
        } else {
            U::empty()
        };
        let depth_copy = if caps.depth_copies {
            U::COPY_SRC
        } else {
            U::empty()
        };
        let (color, color_view) = texture_2d(
            device,
            "color",
            (width, height),
            COLOR_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | storage,
        );
        let (depth, depth_view) = texture_2d(
            device,
            "depth",
            (width, height),
            DEPTH_FORMAT,
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | depth_copy,
        );
        Ok(Targets {
            color,
            color_view,
            depth,
            depth_view,
        })
    }
}

/// The resources shared by all methods, and the helpers methods build with.
pub struct Shared {
    /// The device everything is built on (the caller's, with `Gpu::from_device`).
    pub device: wgpu::Device,
    /// The queue frames are submitted on.
    pub queue: wgpu::Queue,
    /// Render target width, pixels.
    pub width: u32,
    /// Render target height, pixels.
    pub height: u32,
    /// The level on the GPU (internal layout).
    pub terrain: TerrainTexture,
    /// The per-frame [`Globals`] uniform.
    pub globals: wgpu::Buffer,
    /// The [`ShadingParams`] uniform.
    pub shading: wgpu::Buffer,
    /// The shared shadow map ([`SHADOW_SIZE`]²).
    pub shadow_map: wgpu::Texture,
    /// Its view.
    pub shadow_view: wgpu::TextureView,
    /// How many frames have written `shadow_map` ([`Shared::shadow_map_written`]):
    /// a method that keeps texels it cast in an earlier frame (`ray-exact`)
    /// sees from it whether anyone wrote the map since.
    shadow_writes: std::sync::atomic::AtomicU64,
    /// Strata's colour target ([`COLOR_FORMAT`], `width` x `height`).
    pub color: wgpu::Texture,
    /// Its view: stable, for drawing your objects over a `render_frame`.
    pub color_view: wgpu::TextureView,
    /// Strata's depth target ([`DEPTH_FORMAT`]; see the crate's depth convention).
    pub depth: wgpu::Texture,
    /// Its view: stable, for drawing your objects over a `render_frame`.
    pub depth_view: wgpu::TextureView,
    /// Bind group 0 of every method pipeline (`frame.wgsl`).
    pub frame_layout: wgpu::BindGroupLayout,
    /// The bind group for `frame_layout`.
    pub frame_group: wgpu::BindGroup,
    /// What the adapter can do: methods check it before building.
    pub caps: Capabilities,
    /// How far slow method builds have come (for a viewer's progress bar).
    pub progress: BuildProgress,
    /// The caller's measuring switches and test hooks (the renderer copies
    /// [`crate::Gpu::options`] here).
    pub options: RenderOptions,
}

/// Fractions done of method builds in flight, by method name: a build that
/// takes long (the mesh fit) reports here; anyone holding the shared frame
/// may read it, from any thread.
#[derive(Default)]
pub struct BuildProgress(std::sync::Mutex<Vec<(String, f32)>>);

impl BuildProgress {
    /// Method `name`'s build is `fraction` (0..=1) done.
    pub fn report(&self, name: &str, fraction: f32) {
        if let Ok(mut all) = self.0.lock() {
            match all.iter_mut().find(|(n, _)| n == name) {
                Some(entry) => entry.1 = fraction,
                None => all.push((name.to_string(), fraction)),
            }
        }
    }

    /// The last fraction method `name` reported, if its build reports.
    pub fn get(&self, name: &str) -> Option<f32> {
        let all = self.0.lock().ok()?;
        all.iter().find(|(n, _)| n == name).map(|e| e.1)
    }

    /// Forget `name` (its build ended).
    pub fn clear(&self, name: &str) {
        if let Ok(mut all) = self.0.lock() {
            all.retain(|(n, _)| n != name);
        }
    }
}

/// The stages the shared bindings are visible to: the three WebGPU knows
/// (`ShaderStages::all()` adds wgpu's mesh and ray-tracing stages, which a
/// browser refuses).
const SHARED_STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: SHARED_STAGES,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A layout entry for a read-only texture of the given sample type and view dimension.
pub fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: SHARED_STAGES,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A layout entry for a 2D float texture a fragment shader reads
/// (`filterable` for a filtering sampler; depth is bound unfilterable).
pub fn fragment_texture_entry(binding: u32, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A layout entry for a write-only 2D storage texture (compute stage).
pub fn storage_texture_entry(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    storage_texture_entry_with(binding, format, wgpu::StorageTextureAccess::WriteOnly)
}

/// [`storage_texture_entry`] with the given access (the R32 formats allow
/// `ReadWrite` everywhere WebGPU runs).
pub fn storage_texture_entry_with(
    binding: u32,
    format: wgpu::TextureFormat,
    access: wgpu::StorageTextureAccess,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// A layout entry for a uniform buffer visible to all stages.
pub fn uniform_layout_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    uniform_entry(binding)
}

impl Shared {
    /// Note that a frame's commands write the shadow map; returns the new
    /// count of such frames. Every writer calls it once per frame it writes.
    pub fn shadow_map_written(&self) -> u64 {
        self.shadow_writes
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed)
            + 1
    }

    /// How many frames have written the shadow map.
    pub fn shadow_map_writes(&self) -> u64 {
        self.shadow_writes
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// A 2D texture (and its view) of the shared targets' size.
    pub fn target_texture(
        &self,
        label: &str,
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> (wgpu::Texture, wgpu::TextureView) {
        texture_2d(
            &self.device,
            label,
            (self.width, self.height),
            format,
            usage,
        )
    }
}

impl Shared {
    pub(crate) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        caps: &Capabilities,
        level: &Level,
        colors: &TerrainColors,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Self> {
        let terrain = TerrainTexture::new(device, queue, level)?;
        Self::with_terrain(device, queue, caps, terrain, colors, width, height)
    }

    /// The shared frame over a terrain texture made elsewhere (the page
    /// atlas of `crate::paged`).
    pub(crate) fn with_terrain(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        caps: &Capabilities,
        terrain: TerrainTexture,
        colors: &TerrainColors,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Self> {
        let shadow_usage = match caps.shadow_pass() {
            Some(ShadowPassKind::Compute) => wgpu::TextureUsages::STORAGE_BINDING,
            Some(ShadowPassKind::Fragment) => wgpu::TextureUsages::RENDER_ATTACHMENT,
            None => anyhow::bail!(
                "the shared shadow map needs {} or {}, which this adapter lacks",
                Capability::ComputeShaders,
                Capability::Float32Targets
            ),
        };
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let shading = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shading"),
            size: std::mem::size_of::<ShadingParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&shading, 0, bytemuck::bytes_of(&ShadingParams::new(colors)));
        let (shadow_map, shadow_view) = texture_2d(
            device,
            "shadow map",
            (SHADOW_SIZE, SHADOW_SIZE),
            wgpu::TextureFormat::R32Float,
            // COPY_SRC: tests read the map back to hold it to its CPU twin.
            shadow_usage | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        );
        let Targets {
            color,
            color_view,
            depth,
            depth_view,
        } = Targets::new(device, caps, width, height)?;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[
                uniform_entry(0),
                uniform_entry(1),
                texture_entry(
                    2,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D2Array,
                ),
                texture_entry(
                    3,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: shading.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&terrain.view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&shadow_view),
                },
            ],
        });
        Ok(Shared {
            device: device.clone(),
            queue: queue.clone(),
            width,
            height,
            terrain,
            globals,
            shading,
            shadow_map,
            shadow_view,
            shadow_writes: std::sync::atomic::AtomicU64::new(0),
            color,
            color_view,
            depth,
            depth_view,
            frame_layout,
            frame_group,
            caps: caps.clone(),
            progress: BuildProgress::default(),
            options: RenderOptions::default(),
        })
    }

    /// Recreate the colour and depth targets at a new size (their content is
    /// lost). Methods that bound or sized anything for the old ones must then
    /// be told ([`crate::Method::resize`]); [`crate::Renderer::resize`] does both.
    pub(crate) fn resize_targets(&mut self, width: u32, height: u32) -> anyhow::Result<()> {
        let Targets {
            color,
            color_view,
            depth,
            depth_view,
        } = Targets::new(&self.device, &self.caps, width, height)?;
        (self.color, self.color_view, self.depth, self.depth_view) =
            (color, color_view, depth, depth_view);
        (self.width, self.height) = (width, height);
        Ok(())
    }

    /// Compose and compile one of `shaders/*.wgsl`.
    pub fn shader(&self, name: &str) -> anyhow::Result<wgpu::ShaderModule> {
        crate::shaders::create_module(&self.device, name)
    }

    /// A pipeline layout whose group 0 is the frame and groups 1.. are the method's.
    pub fn pipeline_layout(
        &self,
        label: &str,
        method_groups: &[&wgpu::BindGroupLayout],
    ) -> wgpu::PipelineLayout {
        let mut groups = vec![Some(&self.frame_layout)];
        groups.extend(method_groups.iter().map(|g| Some(*g)));
        self.device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &groups,
                immediate_size: 0,
            })
    }

    /// A uniform buffer initialised with `data`.
    pub fn uniform_buffer(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: data.len() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&buffer, 0, data);
        buffer
    }

    /// Bytes of the shared GPU resources (not charged to any method).
    pub fn gpu_bytes(&self) -> u64 {
        let px = u64::from(self.width) * u64::from(self.height);
        self.terrain.layout.bytes()
            + std::mem::size_of::<Globals>() as u64
            + std::mem::size_of::<ShadingParams>() as u64
            + u64::from(SHADOW_SIZE * SHADOW_SIZE) * 4
            + px * 8
    }
}
