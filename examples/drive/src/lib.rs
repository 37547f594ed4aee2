//! A program to copy from: Strata's terrain in your own wgpu program. Your
//! device and queue go to Strata ([`Gpu::from_device`]); each frame Strata
//! draws the terrain into *your* colour and depth views
//! ([`Renderer::render_into`]), then your own vehicle (own pipeline, own
//! vertex buffer) is drawn into the same views and composes with the terrain
//! by the ordinary depth test. The vehicle drives on the terrain collider
//! (`strata_collide`), which follows the crater dug at start through the
//! renderer's edit listener.
//!
//! The window (`main.rs`) and the headless mode / test share [`Drive`], so
//! the test covers what the window shows.

pub mod scene;
pub mod vehicle;

use glam::Vec3;
use std::sync::{Arc, Mutex};
use strata_camera::Camera;
use strata_collide::TerrainCollider;
use strata_render::{Gpu, MethodSettings, Renderer, TargetViews, TerrainColors};
use vehicle::Vehicle;

/// The headless mode's targets: the formats a window's surface usually has.
pub const HEADLESS_COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Bgra8UnormSrgb;
/// The depth format of the window and the headless mode: Strata's own, so
/// a rasterising method draws the terrain's depth straight into it and
/// `render_into` adds only a colour pass into a surface format it cannot
/// draw (`composite_split::DepthRoute::Direct`; any other depth format takes
/// the full-screen pass that writes both).
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The terrain, its collider, your vehicle and the camera.
pub struct Drive {
    /// Strata's renderer, on your device.
    pub renderer: Renderer,
    /// The terrain collider, kept in step with every edit by the renderer.
    pub collider: Arc<Mutex<TerrainCollider>>,
    /// Your object.
    vehicle: Vehicle,
    /// The scene's camera at the current size.
    pub camera: Camera,
}

impl Drive {
    /// Build the scene for method `method` drawing into `color` views and
    /// [`DEPTH`] views of `size`, and dig the crater.
    pub fn new(
        gpu: &Gpu,
        method: &str,
        color: wgpu::TextureFormat,
        size: (u32, u32),
    ) -> anyhow::Result<Self> {
        Self::with_shadows(gpu, method, color, size, true)
    }

    /// [`Drive::new`], with or without the shadow map (a 1024² pass per
    /// frame: the test turns it off to stay fast on a CPU rasteriser).
    pub fn with_shadows(
        gpu: &Gpu,
        method: &str,
        color: wgpu::TextureFormat,
        size: (u32, u32),
        shadows: bool,
    ) -> anyhow::Result<Self> {
        let mut level = scene::level()?;
        let settings = MethodSettings {
            shadows,
            ..Default::default()
        };
        let colors = TerrainColors::test_ramps();
        let mut renderer = Renderer::new(gpu, &level, &colors, method, &settings, size.0, size.1)?;

        // The collider (exact to the texel model, 4 bytes a texel) follows
        // every edit the renderer applies, in the same call.
        let collider = Arc::new(Mutex::new(TerrainCollider::new(&level)));
        let follower = Arc::clone(&collider);
        renderer.set_edit_listener(Some(Box::new(move |level, rects| {
            if let Ok(mut c) = follower.lock() {
                c.apply_edit(level, rects);
            }
        })));

        // Dig the crater at start: GPU data and collider change together.
        let dirty = strata_level::edit::crater(&mut level, &scene::crater_site());
        renderer.apply_edit(&level, &dirty)?;
        // `mesh` refits the crater's chunks on worker threads; the scene
        // starts with the crater in place, so wait for them here (once, at
        // start) rather than let the first frames draw the old triangles.
        renderer.settle_edits()?;

        Ok(Drive {
            renderer,
            collider,
            vehicle: Vehicle::new(&gpu.device, color, DEPTH),
            camera: scene::camera(size.0, size.1)?,
        })
    }

    /// Follow a new target size (a resized window).
    pub fn resize(&mut self, size: (u32, u32)) -> anyhow::Result<()> {
        self.renderer.resize(size.0, size.1)?;
        self.camera = scene::camera(size.0, size.1)?;
        Ok(())
    }

    /// The vehicle's centre at road position `t` (0..1): resting on the
    /// ground the collider finds under it (under the slab: the cave floor;
    /// in the crater: its new floor).
    pub fn vehicle_centre(&self, t: f32) -> Vec3 {
        let x = scene::road_x(t);
        let ground = self
            .collider
            .lock()
            .ok()
            .and_then(|c| {
                c.cast_ray(
                    [f64::from(x), f64::from(scene::ROAD_Y), scene::CAST_FROM],
                    [0.0, 0.0, -1.0],
                    400.0,
                )
            })
            .map_or(f32::from(scene::GROUND), |hit| hit.point[2] as f32);
        Vec3::new(x, scene::ROAD_Y, ground + scene::VEHICLE_HALF.z)
    }

    /// One frame into your views: the terrain ([`Renderer::render_into`]),
    /// then the vehicle at road position `t` unless `t` is `None`. Returns
    /// the vehicle's centre.
    pub fn draw(
        &mut self,
        t: Option<f32>,
        color: &wgpu::TextureView,
        color_view_format: Option<wgpu::TextureFormat>,
        depth: &wgpu::TextureView,
    ) -> anyhow::Result<Option<Vec3>> {
        let targets = TargetViews {
            color,
            color_view_format,
            depth,
        };
        self.renderer.render_into(&self.camera, &targets)?;
        let Some(t) = t else { return Ok(None) };
        let centre = self.vehicle_centre(t);
        let shared = self.renderer.shared();
        self.vehicle.draw(
            &shared.device,
            &shared.queue,
            self.camera.view_proj(),
            centre,
            color,
            depth,
        );
        Ok(Some(centre))
    }
}

/// Colour and depth textures standing in for a window (headless mode, tests).
pub struct Offscreen {
    /// [`HEADLESS_COLOR`], copyable to the CPU.
    pub color: wgpu::Texture,
    /// Its view.
    pub color_view: wgpu::TextureView,
    /// [`DEPTH`].
    pub depth_view: wgpu::TextureView,
}

/// A 2D render target of `size` (yours: Strata draws into its view).
pub fn target(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl Offscreen {
    /// Targets of `size` on `device`.
    pub fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        let texture = |format, usage| target(device, "offscreen", size, format, usage);
        use wgpu::TextureUsages as U;
        let color = texture(HEADLESS_COLOR, U::RENDER_ATTACHMENT | U::COPY_SRC);
        let depth = texture(DEPTH, U::RENDER_ATTACHMENT);
        Offscreen {
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            color,
        }
    }

    /// The colour target as RGBA bytes, top row first.
    pub fn read_rgba(&self, gpu: &Gpu) -> anyhow::Result<Vec<u8>> {
        let mut bytes = strata_render::gpu::read_texture(
            &gpu.device,
            &gpu.queue,
            &gpu.errors,
            &self.color,
            wgpu::TextureAspect::All,
        )?;
        for px in bytes.chunks_exact_mut(4) {
            px.swap(0, 2);
        }
        Ok(bytes)
    }
}

/// Your device and queue on the default adapter (or one able to present to
/// `surface`), handed to Strata.
pub fn open_gpu(
    instance: wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
) -> anyhow::Result<Gpu> {
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        compatible_surface: surface,
        ..Default::default()
    }))
    .map_err(|e| {
        anyhow::anyhow!(
            "no GPU adapter ({e}); on a machine without one install mesa-vulkan-drivers (lavapipe)"
        )
    })?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("my engine"),
        required_features: adapter.features(),
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;
    Gpu::from_device(instance, adapter, device, queue)
}
