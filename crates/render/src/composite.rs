//! The composite pass behind [`crate::Renderer::render_into`]: the
//! caller's targets ([`TargetViews`]), the formats it draws into, why it
//! refuses a target ([`TargetError`]), and the full-screen pass that writes
//! the frame's colour and depth into them (one pipeline per format pair and
//! sample count, kept in a cache on the renderer). See `embed.rs` for the
//! depth convention.

use wgpu::TextureFormat as F;

/// The caller's targets for [`Renderer::render_into`](crate::Renderer::render_into): a colour view and a
/// depth view of one size, which must be the renderer's size (the camera's).
#[derive(Clone, Copy, Debug)]
pub struct TargetViews<'a> {
    /// Receives the terrain's colour, every pixel (the sky included). Its
    /// texture's format must be one of [`COLOR_TARGET_FORMATS`] and its usage
    /// include `RENDER_ATTACHMENT`.
    pub color: &'a wgpu::TextureView,
    /// The colour view's format where it differs from its texture's (an
    /// `...Srgb` view of a surface texture made with `view_formats`); `None`:
    /// the texture's format.
    pub color_view_format: Option<wgpu::TextureFormat>,
    /// Receives the terrain's depth (see the module's depth convention). Its
    /// texture's format must be one of [`DEPTH_TARGET_FORMATS`], its sample
    /// count the colour texture's; a stencil aspect is left as it was.
    pub depth: &'a wgpu::TextureView,
}

impl<'a> TargetViews<'a> {
    /// Views whose formats are their textures' formats.
    pub fn new(color: &'a wgpu::TextureView, depth: &'a wgpu::TextureView) -> Self {
        TargetViews {
            color,
            color_view_format: None,
            depth,
        }
    }
}

/// Colour formats [`Renderer::render_into`](crate::Renderer::render_into) draws into. Strata's colours are
/// sRGB-encoded bytes: the UNORM formats receive those bytes as they are, the
/// `...Srgb` formats end up storing the same bytes (the pass decodes, the
/// target encodes), the float formats receive linear values.
pub const COLOR_TARGET_FORMATS: &[wgpu::TextureFormat] = &[
    F::Rgba8Unorm,
    F::Rgba8UnormSrgb,
    F::Bgra8Unorm,
    F::Bgra8UnormSrgb,
    F::Rgb10a2Unorm,
    F::Rgba16Float,
];

/// Depth formats [`Renderer::render_into`](crate::Renderer::render_into) draws into (`Depth32FloatStencil8`
/// where the device has that feature).
pub const DEPTH_TARGET_FORMATS: &[wgpu::TextureFormat] = &[
    F::Depth32Float,
    F::Depth24Plus,
    F::Depth24PlusStencil8,
    F::Depth32FloatStencil8,
    F::Depth16Unorm,
];

/// Why [`Renderer::render_into`](crate::Renderer::render_into) refused the caller's targets (nothing was
/// drawn).
#[derive(Clone, Debug, thiserror::Error, PartialEq, Eq)]
pub enum TargetError {
    /// The colour target's format is not in [`COLOR_TARGET_FORMATS`].
    #[error(
        "colour target format {0:?} cannot receive Strata's terrain; render_into draws into {list}",
        list = format_list(COLOR_TARGET_FORMATS)
    )]
    ColorFormat(wgpu::TextureFormat),
    /// The depth target's format is not in [`DEPTH_TARGET_FORMATS`].
    #[error(
        "depth target format {0:?} cannot receive Strata's depth; render_into draws into {list}",
        list = format_list(DEPTH_TARGET_FORMATS)
    )]
    DepthFormat(wgpu::TextureFormat),
    /// Colour and depth targets of different sample counts.
    #[error(
        "colour target has sample count {color} but depth target {depth}: they must be equal (1, 2, 4, 8 or 16)"
    )]
    SampleCount {
        /// The colour texture's sample count.
        color: u32,
        /// The depth texture's sample count.
        depth: u32,
    },
    /// A target whose size is not the renderer's.
    #[error(
        "{target} target is {}x{} but the renderer draws {}x{} (Renderer::resize to follow a window)",
        size.0, size.1, renderer.0, renderer.1
    )]
    Size {
        /// `"colour"` or `"depth"`.
        target: &'static str,
        /// Its width and height, pixels.
        size: (u32, u32),
        /// The renderer's width and height, pixels.
        renderer: (u32, u32),
    },
    /// A target texture made without `RENDER_ATTACHMENT` usage, or not 2D.
    #[error(
        "{target} target ({usage:?}, {dimension:?}) must be a 2D texture with RENDER_ATTACHMENT usage"
    )]
    Usage {
        /// `"colour"` or `"depth"`.
        target: &'static str,
        /// Its usage flags.
        usage: wgpu::TextureUsages,
        /// Its dimension.
        dimension: wgpu::TextureDimension,
    },
    /// A view made on a device other than the renderer's.
    #[error(
        "a target view belongs to another device than the renderer's: build the Gpu with Gpu::from_device on the device that made the targets ({0})"
    )]
    OtherDevice(String),
    /// The device refused the composite for another reason.
    #[error(
        "drawing into the caller's targets ({color:?} colour, {depth:?} depth, {samples} samples) failed: {message}"
    )]
    Refused {
        /// The colour view's format.
        color: wgpu::TextureFormat,
        /// The depth format.
        depth: wgpu::TextureFormat,
        /// The sample count.
        samples: u32,
        /// wgpu's error.
        message: String,
    },
}

fn format_list(formats: &[wgpu::TextureFormat]) -> String {
    let names: Vec<String> = formats.iter().map(|f| format!("{f:?}")).collect();
    names.join(", ")
}

/// What one composite pipeline was built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Key {
    pub(crate) color: wgpu::TextureFormat,
    pub(crate) depth: wgpu::TextureFormat,
    pub(crate) samples: u32,
}

/// The checked description of a caller's targets.
pub(crate) fn key_of(targets: &TargetViews<'_>, size: (u32, u32)) -> Result<Key, TargetError> {
    let (color, depth) = (targets.color.texture(), targets.depth.texture());
    for (target, texture) in [("colour", color), ("depth", depth)] {
        if !texture
            .usage()
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
            || texture.dimension() != wgpu::TextureDimension::D2
        {
            return Err(TargetError::Usage {
                target,
                usage: texture.usage(),
                dimension: texture.dimension(),
            });
        }
    }
    let color_format = targets.color_view_format.unwrap_or(color.format());
    if !COLOR_TARGET_FORMATS.contains(&color_format) {
        return Err(TargetError::ColorFormat(color_format));
    }
    if !DEPTH_TARGET_FORMATS.contains(&depth.format()) {
        return Err(TargetError::DepthFormat(depth.format()));
    }
    for (target, texture) in [("colour", color), ("depth", depth)] {
        if (texture.width(), texture.height()) != size {
            return Err(TargetError::Size {
                target,
                size: (texture.width(), texture.height()),
                renderer: size,
            });
        }
    }
    if color.sample_count() != depth.sample_count() {
        return Err(TargetError::SampleCount {
            color: color.sample_count(),
            depth: depth.sample_count(),
        });
    }
    Ok(Key {
        color: color_format,
        depth: depth.format(),
        samples: color.sample_count(),
    })
}

#[derive(Default)]
pub(crate) struct CompositeCache {
    layout: Option<wgpu::BindGroupLayout>,
    sampler: Option<wgpu::Sampler>,
    /// The sRGB decode table (`composite.wgsl`'s `srgb_to_linear`).
    decode: Option<wgpu::Buffer>,
    module: Option<wgpu::ShaderModule>,
    /// Per key and whether the pass writes depth too.
    pipelines: Vec<((Key, bool), wgpu::RenderPipeline)>,
    /// The bind group and the colour and depth textures it was made for (a
    /// resize replaces the shared targets; a compute method's depth image
    /// stands in for the depth target).
    group: Option<(wgpu::Texture, wgpu::Texture, wgpu::BindGroup)>,
}

impl CompositeCache {
    fn layout(&mut self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let texture = |binding| crate::frame::fragment_texture_entry(binding, false);
        self.layout
            .get_or_insert_with(|| {
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("composite"),
                    entries: &[
                        texture(0),
                        texture(1),
                        wgpu::BindGroupLayoutEntry {
                            binding: 2,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering),
                            count: None,
                        },
                        wgpu::BindGroupLayoutEntry {
                            binding: 3,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Buffer {
                                ty: wgpu::BufferBindingType::Uniform,
                                has_dynamic_offset: false,
                                min_binding_size: None,
                            },
                            count: None,
                        },
                    ],
                })
            })
            .clone()
    }

    /// The pass's bind group: Strata's colour target, and its depth target
    /// or `depth_image` (a compute method's `R32Float` depth image, which
    /// holds the same depth-buffer values: read in place, it spares the
    /// blit into the depth target, 0.076 ms at 1280x800 on the H100).
    pub(crate) fn group(
        &mut self,
        shared: &crate::frame::Shared,
        depth_image: Option<&wgpu::Texture>,
    ) -> wgpu::BindGroup {
        let depth = depth_image.unwrap_or(&shared.depth);
        if let Some((color, depth_in, group)) = &self.group
            && *color == shared.color
            && depth_in == depth
        {
            return group.clone();
        }
        let image_view = depth_image.map(|t| t.create_view(&Default::default()));
        let layout = self.layout(&shared.device);
        let sampler = self
            .sampler
            .get_or_insert_with(|| {
                shared.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("composite"),
                    ..Default::default()
                })
            })
            .clone();
        let decode = self
            .decode
            .get_or_insert_with(|| {
                use wgpu::util::DeviceExt;
                shared
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("srgb decode"),
                        contents: bytemuck::cast_slice(&srgb_decode_table()),
                        usage: wgpu::BufferUsages::UNIFORM,
                    })
            })
            .clone();
        let group = crate::frame::bind_group(
            &shared.device,
            "composite",
            &layout,
            &[
                wgpu::BindingResource::TextureView(&shared.color_view),
                wgpu::BindingResource::TextureView(
                    image_view.as_ref().unwrap_or(&shared.depth_view),
                ),
                wgpu::BindingResource::Sampler(&sampler),
                decode.as_entire_binding(),
            ],
        );
        self.group = Some((shared.color.clone(), depth.clone(), group.clone()));
        group
    }

    /// The pass for `key`, writing colour and depth, or (`with_depth`
    /// false) colour alone: its depth is drawn straight into the caller's
    /// texture by the frame (`ColorRoute::Pass`).
    pub(crate) fn pipeline(
        &mut self,
        device: &wgpu::Device,
        key: Key,
        with_depth: bool,
    ) -> anyhow::Result<wgpu::RenderPipeline> {
        if let Some((_, p)) = self.pipelines.iter().find(|(k, _)| *k == (key, with_depth)) {
            return Ok(p.clone());
        }
        let module = match &self.module {
            Some(m) => m.clone(),
            None => {
                let m = crate::shaders::create_module(device, "composite.wgsl")?;
                self.module = Some(m.clone());
                m
            }
        };
        let layout = self.layout(device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("composite"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        // Targets that encode on write or hold linear light get decoded colour.
        let linear = key.color.is_srgb() || key.color == F::Rgba16Float;
        let fs = match (linear, with_depth) {
            (true, true) => "fs_composite_linear",
            (false, true) => "fs_composite",
            (true, false) => "fs_composite_color_linear",
            (false, false) => "fs_composite_color",
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("composite"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: with_depth.then(|| wgpu::DepthStencilState {
                format: key.depth,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: key.samples,
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(key.color.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        self.pipelines.push(((key, with_depth), pipeline.clone()));
        Ok(pipeline)
    }
}

/// Linear light of each sRGB-encoded byte (IEC 61966-2-1).
pub(crate) fn srgb_decode_table() -> [f32; 256] {
    std::array::from_fn(|k| {
        let c = k as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// Record the composite pass: the shared frame into the caller's views
/// (with `with_depth` false into the colour view alone, by a pipeline made
/// so).
pub(crate) fn record_composite(
    encoder: &mut wgpu::CommandEncoder,
    targets: &TargetViews<'_>,
    (key, with_depth): (Key, bool),
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) {
    // Every pixel is written, so neither view's old contents are loaded or
    // cleared; a stencil aspect is kept for the caller.
    let stencil_ops = key.depth.has_stencil_aspect().then_some(wgpu::Operations {
        load: wgpu::LoadOp::Load,
        store: wgpu::StoreOp::Store,
    });
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("composite"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: targets.color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: every_pixel_written(),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: with_depth.then_some(wgpu::RenderPassDepthStencilAttachment {
            view: targets.depth,
            depth_ops: Some(wgpu::Operations {
                load: every_pixel_written(),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops,
        }),
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.draw(0..3, 0..1);
}

/// The load op of an attachment that a full-screen pass then writes at every
/// pixel: its old contents are neither read nor cleared. On the H100 a
/// clear costs as much as the pass's own writes (a 1280x800 colour + depth
/// composite: 0.300 ms with clears, 0.157 ms without;
/// `examples/composite_parts.rs`). WebGPU has no such op: there wgpu clears.
pub(crate) fn every_pixel_written<V>() -> wgpu::LoadOp<V> {
    // SAFETY: the attachment's undefined contents are never read: the
    // full-screen triangle covers every pixel, with no discard and depth
    // compare `Always`, so each pixel is written before the pass ends.
    wgpu::LoadOp::DontCare(unsafe { wgpu::LoadOpDontCare::enabled() })
}
