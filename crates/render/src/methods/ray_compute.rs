//! `ray-compute`: the `ray` march as a compute dispatch (one invocation per
//! pixel) over the same WGSL core. Colour goes straight into the shared colour
//! target through a storage view; depth goes into an R32Float storage texture
//! that a tiny full-screen pass copies into the shared depth target (a depth
//! texture can be neither a storage texture nor a copy destination from a
//! colour one). Both passes are timed; the copy is part of the method's cost.

use super::ray::ray_params;
use super::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{
    DEPTH_FORMAT, Shared, storage_texture_entry, texture_entry, uniform_layout_entry,
};
use strata_level::Level;

pub struct RayCompute {
    march: wgpu::ComputePipeline,
    march_group: wgpu::BindGroup,
    blit: wgpu::RenderPipeline,
    blit_group: wgpu::BindGroup,
    depth_bytes: u64,
}

pub fn create(
    shared: &Shared,
    _level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let params = ray_params(shared, settings)?;
    let device = &shared.device;
    let depth = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("ray-compute depth"),
        size: wgpu::Extent3d {
            width: shared.width,
            height: shared.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let depth_view = depth.create_view(&Default::default());

    let march_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("ray-compute"),
        entries: &[
            uniform_layout_entry(0),
            storage_texture_entry(1, crate::frame::COLOR_FORMAT),
            storage_texture_entry(2, wgpu::TextureFormat::R32Float),
        ],
    });
    let march_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray-compute"),
        layout: &march_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&shared.color_view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&depth_view),
            },
        ],
    });
    let module = shared.shader("ray_compute.wgsl")?;
    let march = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("ray-compute"),
        layout: Some(&shared.pipeline_layout("ray-compute", &[&march_layout])),
        module: &module,
        entry_point: Some("cs_ray"),
        compilation_options: Default::default(),
        cache: None,
    });

    let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("depth blit"),
        entries: &[texture_entry(
            0,
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2,
        )],
    });
    let blit_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("depth blit"),
        layout: &blit_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(&depth_view),
        }],
    });
    let blit_module = shared.shader("depth_blit.wgsl")?;
    let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("depth blit"),
        layout: Some(
            &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("depth blit"),
                bind_group_layouts: &[Some(&blit_layout)],
                immediate_size: 0,
            }),
        ),
        vertex: wgpu::VertexState {
            module: &blit_module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &blit_module,
            entry_point: Some("fs_depth_blit"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    });
    Ok(Box::new(RayCompute {
        march,
        march_group,
        blit,
        blit_group,
        depth_bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
    }))
}

impl Method for RayCompute {
    fn name(&self) -> &'static str {
        "ray-compute"
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("ray-compute march"),
                timestamp_writes: frame.timer.compute("ray-compute march"),
            });
            pass.set_pipeline(&self.march);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.march_group, &[]);
            pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("ray-compute depth copy"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &shared.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: frame.timer.render("ray-compute depth copy"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.blit);
        pass.set_bind_group(0, &self.blit_group, &[]);
        pass.draw(0..3, 0..1);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The R32Float depth image plus the 16-byte uniform.
        RetainedBytes {
            gpu: self.depth_bytes + 16,
            cpu: 0,
        }
    }
}
