//! `ray`: the paper's height-field march (§3.1) as one full-screen fragment
//! pass over the shared WGSL core (`ray_core.wgsl::ray_pixel`).

use super::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{COLOR_FORMAT, DEPTH_FORMAT, Shared, sky_clear, uniform_layout_entry};
use strata_level::Level;

pub struct Ray {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
}

/// Check `--ray-steps` and build the method's uniform (`RayParams`).
pub(crate) fn ray_params(
    shared: &Shared,
    settings: &MethodSettings,
) -> anyhow::Result<wgpu::Buffer> {
    if settings.ray_steps == 0 {
        anyhow::bail!("ray steps must be at least 1 (got 0)");
    }
    Ok(shared.uniform_buffer(
        "ray params",
        bytemuck::cast_slice(&[settings.ray_steps, 0, 0, 0]),
    ))
}

pub fn create(
    shared: &Shared,
    _level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let params = ray_params(shared, settings)?;
    let device = &shared.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("ray"),
        entries: &[uniform_layout_entry(0)],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        }],
    });
    let module = shared.shader("ray.wgsl")?;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("ray"),
        layout: Some(&shared.pipeline_layout("ray", &[&layout])),
        vertex: wgpu::VertexState {
            module: &module,
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
            module: &module,
            entry_point: Some("fs_ray"),
            compilation_options: Default::default(),
            targets: &[Some(COLOR_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    Ok(Box::new(Ray { pipeline, group }))
}

impl Method for Ray {
    fn name(&self) -> &'static str {
        "ray"
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("ray"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &shared.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(sky_clear()),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &shared.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: frame.timer.render("ray"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.draw(0..3, 0..1);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // One 16-byte uniform; no auxiliary storage (the paper: none).
        RetainedBytes { gpu: 16, cpu: 0 }
    }
}
