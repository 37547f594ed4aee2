//! `painted` (§3.4): every ground sample of the camera's footprint becomes a
//! bar [0, low] and, for a dual column, a bar [mid, high]. One instanced draw,
//! no vertex buffer: the vertex shader derives each corner from the instance
//! index (the sample, front to back: `forward.wgsl`) and the vertex index
//! (bar, face, corner), and emits only the faces that face the eye.

use super::forward::{self, FootprintParams};
use super::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{COLOR_FORMAT, DEPTH_FORMAT, Shared, sky_clear, uniform_layout_entry};
use strata_camera::Camera;
use strata_level::Level;

/// Vertices per sample: two bars of three faces of two triangles.
const VERTICES_PER_SAMPLE: u32 = 36;

pub struct Painted {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    /// Samples the next `record` draws (written by `prepare`).
    samples: u32,
}

/// A depth-tested, write-enabled state with the shared `Less` test.
pub(crate) fn depth_state() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The footprint uniform, its bind group layout and group.
pub(crate) fn footprint_binding(
    shared: &Shared,
    label: &str,
) -> (wgpu::Buffer, wgpu::BindGroupLayout, wgpu::BindGroup) {
    let params = shared.uniform_buffer(label, bytemuck::bytes_of(&FootprintParams::default()));
    let device = &shared.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[uniform_layout_entry(0)],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        }],
    });
    (params, layout, group)
}

/// A pipeline of one vertex and one fragment entry of `shader`, no vertex
/// buffers, no culling (the vertex shader picks the faces itself).
pub(crate) fn forward_pipeline(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::BindGroupLayout,
    entries: (&str, &str),
) -> anyhow::Result<wgpu::RenderPipeline> {
    let module = shared.shader(shader)?;
    Ok(shared
        .device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&shared.pipeline_layout(label, &[layout])),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(entries.0),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth_state()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(entries.1),
                compilation_options: Default::default(),
                targets: &[Some(COLOR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        }))
}

/// Begin the method's one pass, clearing colour to sky and depth to far.
pub(crate) fn begin_pass<'e>(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
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
        timestamp_writes: frame.timer.render(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

pub fn create(
    shared: &Shared,
    _level: &Level,
    _settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let (params, layout, group) = footprint_binding(shared, "painted");
    let pipeline = forward_pipeline(
        shared,
        "painted",
        "painted.wgsl",
        &layout,
        ("vs_painted", "fs_painted"),
    )?;
    Ok(Box::new(Painted {
        pipeline,
        group,
        params,
        samples: 0,
    }))
}

impl Method for Painted {
    fn name(&self) -> &'static str {
        "painted"
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        let f = forward::footprint(camera, Some("painted"));
        self.samples = f.count[0];
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&f));
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = begin_pass(shared, frame, encoder, "painted");
        if self.samples == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.draw(0..VERTICES_PER_SAMPLE, 0..self.samples);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The 48-byte footprint uniform; no per-column geometry.
        RetainedBytes {
            gpu: forward::PARAMS_BYTES,
            cpu: 0,
        }
    }
}
