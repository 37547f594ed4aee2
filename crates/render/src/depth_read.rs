//! Depth read-back through a pass, for adapters without depth-texture copies
//! (wgpu's GL backend, WebGL2): the depth target is drawn into an
//! `Rgba8Unorm` colour target by `depth_read.wgsl` (the f32's four bytes, so
//! nothing is rounded; RGBA8 is the format every GL reads back: Chromium's
//! WebGL2 gave zeros for an `R32Uint` target), and that target is copied out.

use crate::caps::Capabilities;
use crate::frame::texture_2d;
use crate::gpu::ErrorSink;

/// The read-back pipeline (built once per renderer, on adapters that need it).
pub struct DepthReader {
    layout: wgpu::BindGroupLayout,
    /// Nearest: WebGL2 reads an unfilterable depth texture only through one.
    sampler: wgpu::Sampler,
    pipeline: wgpu::RenderPipeline,
}

impl DepthReader {
    /// `Ok(None)` where depth copies work and no pass is needed.
    pub fn new(device: &wgpu::Device, caps: &Capabilities) -> anyhow::Result<Option<Self>> {
        if caps.depth_copies {
            return Ok(None);
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth read"),
            entries: &[
                // Depth bound as unfilterable float (WebGPU allows it):
                // naga's GLSL output cannot textureLoad a depth texture.
                crate::frame::fragment_texture_entry(0, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering),
                    count: None,
                },
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("depth read"),
            ..Default::default()
        });
        let module = crate::shaders::create_module(device, "depth_read.wgsl")?;
        let pipeline = crate::fullscreen::pipeline(
            device,
            "depth read",
            &[&layout],
            &module,
            ("vs_fullscreen", "fs_depth_read"),
            wgpu::TextureFormat::Rgba8Unorm,
        );
        Ok(Some(DepthReader {
            layout,
            sampler,
            pipeline,
        }))
    }

    /// Copy `depth` (a `Depth32Float` texture) to the CPU as its f32 values,
    /// rows unpadded, top row first, as a direct copy would give them.
    pub fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        errors: &ErrorSink,
        depth: &wgpu::Texture,
    ) -> anyhow::Result<Vec<f32>> {
        let raw = self.start(device, queue, depth).wait(device, errors)?;
        Ok(bytemuck::pod_collect_to_vec(&raw))
    }

    /// Draw `depth` into the colour target and start its read-back without
    /// waiting (a browser's frame loop polls it); its bytes are `f32` depths.
    pub fn start(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        depth: &wgpu::Texture,
    ) -> crate::gpu::TextureReadback {
        let view = depth.create_view(&Default::default());
        let group = crate::frame::bind_group(
            device,
            "depth read",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(&view),
                wgpu::BindingResource::Sampler(&self.sampler),
            ],
        );
        let (target, target_view) = texture_2d(
            device,
            "depth read",
            (depth.width(), depth.height()),
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        crate::fullscreen::draw(
            &mut encoder,
            "depth read",
            &target_view,
            &self.pipeline,
            &[&group],
            None,
        );
        queue.submit([encoder.finish()]);
        crate::gpu::TextureReadback::start(device, queue, &target, wgpu::TextureAspect::All)
    }
}
