//! Pipeline and pass plumbing that several methods share, so that the
//! method files hold only what makes each method different.

use super::contract::Frame;
use crate::frame::{
    COLOR_FORMAT, DEPTH_FORMAT, Shared, sky_clear, storage_texture_entry, texture_entry,
    uniform_layout_entry,
};

/// Depth written with `compare`: `Less` for geometry, `Always` for passes
/// that compute every pixel's depth themselves (marches, the depth copy).
fn depth_write(compare: wgpu::CompareFunction) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// Depth attached but neither tested nor written: a pass that colours what
/// an earlier pass of the frame put in depth.
fn depth_kept() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        depth_write_enabled: Some(false),
        depth_compare: Some(wgpu::CompareFunction::Always),
        ..depth_write(wgpu::CompareFunction::Always)
    }
}

/// A render pipeline of one vertex and one fragment entry of `module`, no
/// vertex buffers (the vertex shaders derive their corners from indices) and
/// no culling (the forward shaders pick the faces themselves).
fn render_pipeline(
    shared: &Shared,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entries: (&str, &str),
    depth: wgpu::DepthStencilState,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    shared
        .device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(entries.0),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(entries.1),
                compilation_options: Default::default(),
                targets,
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// A depth-tested (`Less`) geometry pipeline over the frame group and
/// `layout`, drawing into the shared colour and depth targets.
pub(crate) fn forward_pipeline(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::BindGroupLayout,
    entries: (&str, &str),
) -> anyhow::Result<wgpu::RenderPipeline> {
    forward_pipeline_into(shared, label, shader, layout, entries, COLOR_FORMAT)
}

/// [`forward_pipeline`] drawing into one colour target of `format` (a
/// method's private image) instead of the shared colour target.
pub(crate) fn forward_pipeline_into(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::BindGroupLayout,
    entries: (&str, &str),
    format: wgpu::TextureFormat,
) -> anyhow::Result<wgpu::RenderPipeline> {
    let module = shared.shader(shader)?;
    Ok(render_pipeline(
        shared,
        label,
        &shared.pipeline_layout(label, &[layout]),
        &module,
        entries,
        depth_write(wgpu::CompareFunction::Less),
        &[Some(format.into())],
    ))
}

/// A full-screen march: one triangle (`vs_fullscreen`) whose fragment entry
/// writes every pixel's colour and depth (`Always`: the march decides).
pub(crate) fn fullscreen_pipeline(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    fragment_entry: &str,
) -> anyhow::Result<wgpu::RenderPipeline> {
    fullscreen_pipeline_with(
        shared,
        (label, shader, layout, fragment_entry),
        depth_write(wgpu::CompareFunction::Always),
    )
}

/// A full-screen pass that writes its fragments' colour and depth only where
/// they lie before what the depth target holds (`Less`): a pass that adds
/// nearer surfaces to a drawn frame.
pub(crate) fn fullscreen_pipeline_depth_tested(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    fragment_entry: &str,
) -> anyhow::Result<wgpu::RenderPipeline> {
    fullscreen_pipeline_with(
        shared,
        (label, shader, layout, fragment_entry),
        depth_write(wgpu::CompareFunction::Less),
    )
}

/// A full-screen pass that writes colour only, over the depth an earlier
/// pass of the frame wrote (attached, not tested, not written): a deferred
/// frame's shading.
pub(crate) fn fullscreen_pipeline_colour_only(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    fragment_entry: &str,
) -> anyhow::Result<wgpu::RenderPipeline> {
    fullscreen_pipeline_with(
        shared,
        (label, shader, layout, fragment_entry),
        depth_kept(),
    )
}

/// A full-screen triangle's pipeline (label, shader, layout, fragment entry)
/// into the shared colour format, over the depth target as `depth` says.
fn fullscreen_pipeline_with(
    shared: &Shared,
    (label, shader, layout, fragment_entry): (&str, &str, &wgpu::PipelineLayout, &str),
    depth: wgpu::DepthStencilState,
) -> anyhow::Result<wgpu::RenderPipeline> {
    let module = shared.shader(shader)?;
    Ok(render_pipeline(
        shared,
        label,
        layout,
        &module,
        ("vs_fullscreen", fragment_entry),
        depth,
        &[Some(COLOR_FORMAT.into())],
    ))
}

/// A compute pipeline of one entry of `shader`.
pub(crate) fn compute_pipeline(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    entry: &str,
) -> anyhow::Result<wgpu::ComputePipeline> {
    compute_pipeline_with_constants(shared, label, shader, layout, entry, &[])
}

/// [`compute_pipeline`] with values for the shader's `override` constants.
pub(crate) fn compute_pipeline_with_constants(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    entry: &str,
    constants: &[(&str, f64)],
) -> anyhow::Result<wgpu::ComputePipeline> {
    let module = shared.shader(shader)?;
    Ok(shared
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            cache: None,
        }))
}

/// A bind group of one uniform buffer at binding 0, with its layout.
pub(crate) fn uniform_binding(
    shared: &Shared,
    label: &str,
    buffer: &wgpu::Buffer,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let device = &shared.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[uniform_layout_entry(0)],
    });
    let group = crate::frame::bind_group(device, label, &layout, &[buffer.as_entire_binding()]);
    (layout, group)
}

/// A `u16` index buffer holding `indices` (the fixed corner patterns of the
/// instanced object-order draws).
pub(crate) fn index_buffer(shared: &Shared, label: &str, indices: &[u16]) -> wgpu::Buffer {
    let buffer = shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of_val(indices) as u64,
        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    shared
        .queue
        .write_buffer(&buffer, 0, bytemuck::cast_slice(indices));
    buffer
}

/// The frame's depth target (the shared one, or the caller's:
/// [`Frame::targets`]), cleared to far (the contract: the first pass that
/// touches it clears it).
fn depth_attachment<'a>(
    shared: &'a Shared,
    frame: &Frame<'a>,
) -> wgpu::RenderPassDepthStencilAttachment<'a> {
    depth_attachment_with(shared, frame, wgpu::LoadOp::Clear(1.0))
}

/// The frame's depth target, loaded by `load`.
fn depth_attachment_with<'a>(
    shared: &'a Shared,
    frame: &Frame<'a>,
    load: wgpu::LoadOp<f32>,
) -> wgpu::RenderPassDepthStencilAttachment<'a> {
    wgpu::RenderPassDepthStencilAttachment {
        view: frame.targets.depth.unwrap_or(&shared.depth_view),
        depth_ops: Some(wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// Begin a timed pass over the shared targets, clearing colour to sky and
/// depth to far.
pub(crate) fn begin_pass<'e>(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
) -> wgpu::RenderPass<'e> {
    begin_pass_with_depth(shared, frame, encoder, label, wgpu::LoadOp::Clear(1.0))
}

/// [`begin_pass`] with the shared depth target loaded by `depth` (a pass
/// after one that drew depth keeps it with `LoadOp::Load`).
pub(crate) fn begin_pass_with_depth<'e>(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    depth: wgpu::LoadOp<f32>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: frame.targets.color.unwrap_or(&shared.color_view),
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(sky_clear()),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(depth_attachment_with(shared, frame, depth)),
        timestamp_writes: frame.timer.render(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A pass over what earlier passes of the frame drew: colour and depth
/// both loaded.
pub(crate) fn begin_pass_over<'e>(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: frame.targets.color.unwrap_or(&shared.color_view),
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(depth_attachment_with(shared, frame, wgpu::LoadOp::Load)),
        timestamp_writes: frame.timer.render(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// [`begin_pass`] into `color` (a method's private image, cleared by the
/// caller's load op) and the shared depth target, cleared to far.
pub(crate) fn begin_pass_into<'e>(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    color: wgpu::RenderPassColorAttachment<'_>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(color)],
        depth_stencil_attachment: Some(depth_attachment(shared, frame)),
        timestamp_writes: frame.timer.render(label),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Record a full-screen march: one pass, frame group 0, `group` at 1.
pub(crate) fn draw_fullscreen(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
) {
    draw_fullscreen_with_depth(
        shared,
        frame,
        encoder,
        label,
        pipeline,
        group,
        wgpu::LoadOp::Clear(1.0),
    );
}

/// [`draw_fullscreen`] with the shared depth target loaded by `depth`.
pub(crate) fn draw_fullscreen_with_depth(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
    depth: wgpu::LoadOp<f32>,
) {
    let mut pass = begin_pass_with_depth(shared, frame, encoder, label, depth);
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &shared.frame_group, &[]);
    pass.set_bind_group(1, group, &[]);
    pass.draw(0..3, 0..1);
}

/// Record a compute march, one invocation per pixel in 8×8 workgroups
/// (the compute shaders' `@workgroup_size`): frame group 0, `group` at 1.
pub(crate) fn dispatch_per_pixel(
    shared: &Shared,
    frame: &Frame<'_>,
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
) {
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: frame.timer.compute(label),
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &shared.frame_group, &[]);
    pass.set_bind_group(1, group, &[]);
    pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
}

/// The compute variants' depth path: a compute shader cannot write a depth
/// texture, so the march writes an R32Float storage image (the frame's depth:
/// [`Method::depth_image`], which `Renderer::read_depth` reads) and, on frames
/// that need the shared depth target ([`Frame::depth_attachment`]), a
/// full-screen pass (`depth_blit.wgsl`) copies it there.
///
/// [`Method::depth_image`]: super::Method::depth_image
pub(crate) struct DepthCopy {
    label: String,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    bytes: u64,
    blit: wgpu::RenderPipeline,
    /// The depth-only alternative to `blit`: one point per pixel
    /// (`ray_exact_depth.wgsl`), built on request ([`DepthCopy::with_points`]).
    points: Option<wgpu::RenderPipeline>,
    layout: wgpu::BindGroupLayout,
    blit_group: wgpu::BindGroup,
    /// Where the march stores colour instead of the shared colour target:
    /// the caller's storage texture of an embedding frame
    /// ([`Method::store_color_into`](super::Method::store_color_into)).
    color_out: Option<wgpu::TextureView>,
}

/// The R32Float storage image of the shared targets' size, and the copy
/// pass's bind group reading it.
fn depth_image(
    shared: &Shared,
    label: &str,
    layout: &wgpu::BindGroupLayout,
) -> (wgpu::Texture, wgpu::TextureView, wgpu::BindGroup) {
    // COPY_SRC: `Renderer::read_depth` reads the frame's depth from here.
    let (depth, view) = shared.target_texture(
        label,
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
    );
    let group = crate::frame::bind_group(
        &shared.device,
        label,
        layout,
        &[wgpu::BindingResource::TextureView(&view)],
    );
    (depth, view, group)
}

impl DepthCopy {
    /// The storage image (labelled `"{method} depth"`) and its copy pass
    /// (labelled `blit_label`).
    pub(crate) fn new(shared: &Shared, method: &str, blit_label: &str) -> anyhow::Result<Self> {
        let device = &shared.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(blit_label),
            entries: &[texture_entry(
                0,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let label = format!("{method} depth");
        let (texture, view, blit_group) = depth_image(shared, &label, &layout);
        let module = shared.shader("depth_blit.wgsl")?;
        // No frame group: the copy reads only the storage image.
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(blit_label),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let blit = render_pipeline(
            shared,
            blit_label,
            &pipeline_layout,
            &module,
            ("vs_fullscreen", "fs_depth_blit"),
            depth_write(wgpu::CompareFunction::Always),
            &[],
        );
        Ok(Self {
            label,
            texture,
            view,
            bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
            blit,
            points: None,
            layout,
            blit_group,
            color_out: None,
        })
    }

    /// Also build the point-per-pixel depth pass ([`DepthCopy::record_points`]):
    /// a depth-only pipeline, no fragment shader.
    pub(crate) fn with_points(mut self, shared: &Shared) -> anyhow::Result<Self> {
        let device = &shared.device;
        let module = shared.shader("ray_exact_depth.wgsl")?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth points"),
            bind_group_layouts: &[Some(&self.layout)],
            immediate_size: 0,
        });
        self.points = Some(
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("depth points"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_depth_point"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::PointList,
                    ..Default::default()
                },
                depth_stencil: Some(depth_write(wgpu::CompareFunction::Always)),
                multisample: Default::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            }),
        );
        Ok(self)
    }

    /// A new storage image at the shared targets' new size; the caller
    /// rebinds [`DepthCopy::bindings`].
    pub(crate) fn resize(&mut self, shared: &Shared) {
        (self.texture, self.view, self.blit_group) = depth_image(shared, &self.label, &self.layout);
        self.bytes = u64::from(shared.width) * u64::from(shared.height) * 4;
        // A caller's texture of the old size no longer fits.
        self.color_out = None;
    }

    /// Store the march's colour into `view` (an `Rgba8Unorm` storage view of
    /// the targets' size; `None`: the shared colour target) from the next
    /// bind group made with [`DepthCopy::bindings`]. Returns whether that
    /// changes the bindings (the caller then rebuilds its groups).
    pub(crate) fn set_color_out(&mut self, view: Option<&wgpu::TextureView>) -> bool {
        if self.color_out.as_ref() == view {
            return false;
        }
        self.color_out = view.cloned();
        true
    }

    /// Layout entries for the march's outputs: the colour target (the
    /// shared one, or the caller's: [`DepthCopy::set_color_out`]) at
    /// `first`, this depth image at `first + 1` (both storage textures).
    pub(crate) fn layout_entries(first: u32) -> [wgpu::BindGroupLayoutEntry; 2] {
        [
            storage_texture_entry(first, COLOR_FORMAT),
            storage_texture_entry(first + 1, wgpu::TextureFormat::R32Float),
        ]
    }

    /// The bindings matching [`DepthCopy::layout_entries`].
    pub(crate) fn bindings<'a>(
        &'a self,
        shared: &'a Shared,
        first: u32,
    ) -> [wgpu::BindGroupEntry<'a>; 2] {
        [
            wgpu::BindGroupEntry {
                binding: first,
                resource: wgpu::BindingResource::TextureView(
                    self.color_out.as_ref().unwrap_or(&shared.color_view),
                ),
            },
            wgpu::BindGroupEntry {
                binding: first + 1,
                resource: wgpu::BindingResource::TextureView(&self.view),
            },
        ]
    }

    /// The storage image: this frame's depth-buffer values, every pixel.
    pub(crate) fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// Bytes of the storage image (4 per pixel).
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Record the timed copy pass. It loads the old depth rather than
    /// clearing it: the pass writes every pixel (compare `Always`), so the
    /// image is the same, and on the H100 the clear was half of the pass
    /// (0.149 ms cleared, 0.076 loaded, `bench/ray-exact.md`).
    pub(crate) fn record(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
    ) {
        self.record_with(shared, frame, encoder, label, false);
    }

    /// The blit with its choice open (for measuring): `clear` false loads
    /// the old depth instead of clearing it (the same image: the blit writes
    /// every pixel, compare `Always`).
    pub(crate) fn record_blit(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        clear: bool,
    ) {
        if !frame.depth_attachment {
            return;
        }
        let mut attachment = depth_attachment(shared, frame);
        if !clear {
            attachment.depth_ops = Some(wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            });
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(attachment),
            timestamp_writes: frame.timer.render(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.blit);
        pass.set_bind_group(0, &self.blit_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// [`DepthCopy::record`], by points where `points` and they were built.
    pub(crate) fn record_with(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        points: bool,
    ) {
        if frame.depth_attachment {
            self.copy_into_target(shared, frame, encoder, label, points);
        }
    }

    /// The copy into the frame's depth target whether or not the frame asks
    /// for it: for a method whose depth target is its frame's depth (the
    /// depth image holds only what a compute pass changed it to).
    pub(crate) fn copy_into_target(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        points: bool,
    ) {
        let mut attachment = depth_attachment(shared, frame);
        attachment.depth_ops = Some(wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(attachment),
            timestamp_writes: frame.timer.render(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        match (&self.points, points) {
            (Some(pipeline), true) => {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &self.blit_group, &[]);
                pass.draw(0..shared.width * shared.height, 0..1);
            }
            _ => {
                pass.set_pipeline(&self.blit);
                pass.set_bind_group(0, &self.blit_group, &[]);
                pass.draw(0..3, 0..1);
            }
        }
    }
}
