//! Depth read-back through a pass, for adapters without depth-texture copies
//! (wgpu's GL backend, WebGL2): the depth target is drawn into an `R32Uint`
//! colour target by `depth_read.wgsl` (the f32's bits, so nothing is rounded;
//! 32-bit unsigned targets are renderable everywhere, `R32Float` is not on GL),
//! and that target is copied out.

use crate::caps::Capabilities;
use crate::frame::texture_2d;
use crate::gpu::ErrorSink;

/// The read-back pipeline (built once per renderer, on adapters that need it).
pub struct DepthReader {
    layout: wgpu::BindGroupLayout,
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
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    // Depth bound as unfilterable float (WebGPU allows it):
                    // naga's GLSL output cannot textureLoad a depth texture.
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth read"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shaders::create_module(device, "depth_read.wgsl")?;
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth read"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_depth_read"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(Some(DepthReader { layout, pipeline }))
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
        let view = depth.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth read"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            }],
        });
        let (target, target_view) = texture_2d(
            device,
            "depth read",
            (depth.width(), depth.height()),
            wgpu::TextureFormat::R32Uint,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("depth read"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        let raw =
            crate::gpu::read_texture(device, queue, errors, &target, wgpu::TextureAspect::All)?;
        Ok(bytemuck::cast_slice::<u8, f32>(&raw).to_vec())
    }
}
