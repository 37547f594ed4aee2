//! `sliced:N/refine` (issue 16, item 5): the plain slices find, per pixel,
//! the nearest slice whose point on the pixel's ray is solid, and one
//! full-screen pass then finds the exact surface crossing on that ray up to
//! the slice point (`shaders/sliced_refine.wgsl`); the surface, not the slice
//! plane, writes depth and colour.
//!
//! Why two passes: refining inside the slice fragment writes `frag_depth`,
//! which turns early depth testing off, so every fragment of every slice ran
//! the search and most were overwritten (8x the plain slicer on the H100).
//! Here the slice pass keeps early depth (no depth writes from the shader, no
//! shading) and writes only the winning slice's rank into a private R32Uint
//! image; the search runs once per covered pixel.

use super::common::fullscreen_pipeline;
use super::{Frame, RetainedBytes};
use crate::frame::{Shared, texture_entry, uniform_layout_entry};

/// Format of the slice marks: rank + 1 of the kept slice, 0 = none. An
/// integer format renders everywhere (WebGL2 included), unlike R32Float.
pub const MARK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The marks image and the refine pass that reads it.
pub struct Refine {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    marks: Marks,
}

/// The marks image at the shared targets' size, and the refine pass's group.
struct Marks {
    view: wgpu::TextureView,
    group: wgpu::BindGroup,
    bytes: u64,
}

impl Marks {
    fn new(shared: &Shared, layout: &wgpu::BindGroupLayout, params: &wgpu::Buffer) -> Self {
        let device = &shared.device;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("sliced marks"),
            size: wgpu::Extent3d {
                width: shared.width,
                height: shared.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: MARK_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sliced refine"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
            ],
        });
        Marks {
            view,
            group,
            bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
        }
    }
}

impl Refine {
    /// `params`: the slicer's footprint uniform (slice count, search budget).
    pub fn new(shared: &Shared, params: &wgpu::Buffer) -> anyhow::Result<Self> {
        let layout = shared
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sliced refine"),
                entries: &[
                    uniform_layout_entry(0),
                    texture_entry(
                        1,
                        wgpu::TextureSampleType::Uint,
                        wgpu::TextureViewDimension::D2,
                    ),
                ],
            });
        let pipeline = fullscreen_pipeline(
            shared,
            "sliced refine",
            "sliced_refine.wgsl",
            &shared.pipeline_layout("sliced refine", &[&layout]),
            "fs_sliced_refine",
        )?;
        let marks = Marks::new(shared, &layout, params);
        Ok(Refine {
            layout,
            pipeline,
            marks,
        })
    }

    /// A marks image at the shared targets' new size.
    pub fn resize(&mut self, shared: &Shared, params: &wgpu::Buffer) {
        self.marks = Marks::new(shared, &self.layout, params);
    }

    /// The slice pass's colour target: the marks, cleared to 0 (no slice).
    pub fn marks_attachment(&self) -> wgpu::RenderPassColorAttachment<'_> {
        wgpu::RenderPassColorAttachment {
            view: &self.marks.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        }
    }

    /// Record the refine pass: sky where no slice was kept (colour cleared,
    /// the slice pass's depth kept), the exact crossing elsewhere.
    pub fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sliced refine"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &shared.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(crate::frame::sky_clear()),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &shared.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: frame.timer.render("sliced refine"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.marks.group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// The marks image (4 bytes a pixel).
    pub fn retained_bytes(&self) -> RetainedBytes {
        RetainedBytes {
            gpu: self.marks.bytes,
            cpu: 0,
        }
    }
}
