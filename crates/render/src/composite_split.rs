//! The cheap road into the caller's targets behind
//! [`Renderer::render_into`](crate::Renderer::render_into): colour and depth
//! each take their cheapest way, instead of one full-screen pass writing
//! both ([`crate::composite`]).
//!
//! Why: on the H100 every way of writing a texture through the graphics
//! path moves about 13 G pixels a second (a texture copy of a 1280x800
//! target and a full-screen depth pass each take ~0.08 ms), while a compute
//! dispatch storing colour into the caller's texture takes 0.02 ms
//! (`examples/composite_parts.rs`, `bench/composite-h100/`). So:
//! - **A view of Strata's own format** (`Rgba8Unorm`, `Depth32Float`, one
//!   sample, one level) takes the frame itself on a fresh frame
//!   (`render_into`): the render passes attach it, a compute shading stores
//!   its colour into it (`STORAGE_BINDING`). Nothing is added to the frame
//!   but a compute method's depth pass (`bench/composite-h100/direct/`).
//! - **Colour** is stored by a compute dispatch when the caller's colour
//!   texture allows storage (`STORAGE_BINDING`, `Rgba8Unorm` or
//!   `Rgba16Float`, one sample, viewed in its own format), else copied when
//!   it is Strata's format with `COPY_DST`.
//! - **Depth** of a method that keeps it in an `R32Float` image (the compute
//!   marches) is written by a depth-only pass from that image straight into
//!   the caller's depth view, any depth format, skipping the blit into
//!   Strata's own depth target; other methods' depth is copied when the
//!   caller's is `Depth32Float` with `COPY_DST`.
//!
//! Any other target pair takes the full-screen pass. Every road stores the
//! same bytes (`tests/embed.rs`).

use crate::composite::{Key, TargetViews};
use wgpu::TextureFormat as F;

/// How the frame's colour reaches the caller's colour texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorRoute {
    /// A compute dispatch stores each pixel (`linear`: decoded from sRGB,
    /// for a float target).
    Storage {
        /// Whether the target holds linear light (`Rgba16Float`).
        linear: bool,
    },
    /// A texture copy (the caller's texture is Strata's format).
    Copy,
    /// A full-screen pass writing colour alone (any colour format), after a
    /// frame that drew its depth straight into the caller's texture
    /// ([`DepthRoute::Direct`]; [`crate::Renderer::render_into`] only).
    Pass,
    /// No extra pass: the method drew each pixel straight into the caller's
    /// `Rgba8Unorm` texture, its render passes attaching it or its compute
    /// shading storing into it (`STORAGE_BINDING`);
    /// [`crate::Renderer::render_into`] only.
    Direct,
}

/// How the frame's depth reaches the caller's depth texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthRoute {
    /// A depth-only pass from the method's `R32Float` depth image.
    FromImage,
    /// A texture copy from Strata's depth target.
    Copy,
    /// No extra pass: a rasterising method's render passes drew depth
    /// straight into the caller's `Depth32Float` texture
    /// ([`crate::Renderer::render_into`] only).
    Direct,
}

/// Which road [`Renderer::render_into`](crate::Renderer::render_into) takes
/// for a target pair (what [`Renderer::record_copy_into`](crate::Renderer::record_copy_into)
/// returns).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompositeRoute {
    /// Colour and depth each by its own way.
    Split {
        /// Colour's way.
        color: ColorRoute,
        /// Depth's way.
        depth: DepthRoute,
    },
    /// One full-screen pass writes both (every format pair and sample count).
    Pass,
}

impl std::fmt::Display for CompositeRoute {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CompositeRoute::Pass => write!(f, "full-screen pass"),
            CompositeRoute::Split { color, depth } => {
                let color = match color {
                    ColorRoute::Storage { .. } => "colour by compute",
                    ColorRoute::Copy => "colour by copy",
                    ColorRoute::Direct => "colour drawn by the method itself",
                    ColorRoute::Pass => "colour by a colour-only full-screen pass",
                };
                let depth = match depth {
                    DepthRoute::FromImage => "depth by a depth-only pass from the method's image",
                    DepthRoute::Copy => "depth by copy",
                    DepthRoute::Direct => "depth drawn by the method itself",
                };
                write!(f, "{color}, {depth}")
            }
        }
    }
}

/// What the choice of road depends on besides the targets.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RouteInputs {
    /// The adapter runs compute shaders.
    pub compute: bool,
    /// The adapter copies depth textures.
    pub depth_copies: bool,
    /// The active method keeps its depth in an `R32Float` image.
    pub depth_image: bool,
    /// The road is for a frame still to draw (`render_into`), which the
    /// method may draw straight into the targets; not for a copy of the
    /// last one (`record_copy_into`).
    pub fresh_frame: bool,
    /// The active method draws colour through render passes (else a compute
    /// pass stores it: `Method::draws_color_by_attachment`).
    pub color_by_attachment: bool,
}

/// The road for `targets` (already checked by [`crate::composite::key_of`]).
pub(crate) fn route(targets: &TargetViews<'_>, key: Key, inputs: RouteInputs) -> CompositeRoute {
    let (color, depth) = (targets.color.texture(), targets.depth.texture());
    let whole = |t: &wgpu::Texture| t.mip_level_count() == 1 && t.depth_or_array_layers() == 1;
    let has = |t: &wgpu::Texture, u| t.usage().contains(u);
    if key.samples != 1 || !whole(color) || !whole(depth) {
        return CompositeRoute::Pass;
    }
    let own_format = targets
        .color_view_format
        .is_none_or(|f| f == color.format());
    // A target of Strata's own format takes the frame itself: a render
    // pass attaches it, or a compute shading stores into it.
    let color_direct_usage = match inputs.color_by_attachment {
        true => wgpu::TextureUsages::RENDER_ATTACHMENT,
        false => wgpu::TextureUsages::STORAGE_BINDING,
    };
    let color_route = match color.format() {
        f if inputs.fresh_frame
            && own_format
            && f == crate::frame::COLOR_FORMAT
            && (inputs.color_by_attachment || inputs.compute)
            && has(color, color_direct_usage) =>
        {
            Some(ColorRoute::Direct)
        }
        F::Rgba8Unorm | F::Rgba16Float
            if inputs.compute && own_format && has(color, wgpu::TextureUsages::STORAGE_BINDING) =>
        {
            Some(ColorRoute::Storage {
                linear: color.format() == F::Rgba16Float,
            })
        }
        f if f.remove_srgb_suffix() == crate::frame::COLOR_FORMAT
            && has(color, wgpu::TextureUsages::COPY_DST) =>
        {
            Some(ColorRoute::Copy)
        }
        _ => None,
    };
    let depth_route = if inputs.fresh_frame
        && !inputs.depth_image
        && depth.format() == crate::frame::DEPTH_FORMAT
        && has(depth, wgpu::TextureUsages::RENDER_ATTACHMENT)
    {
        // A rasterising method draws depth straight into it.
        Some(DepthRoute::Direct)
    } else if inputs.depth_image {
        Some(DepthRoute::FromImage)
    } else if inputs.depth_copies
        && depth.format() == crate::frame::DEPTH_FORMAT
        && has(depth, wgpu::TextureUsages::COPY_DST)
    {
        Some(DepthRoute::Copy)
    } else {
        None
    };
    match (color_route, depth_route) {
        // Where depth copies are missing (wgpu's GL backend), a frame whose
        // last command is the colour dispatch read back wrong on llvmpipe
        // (`tests/embed.rs`, by thousands of half-float steps, not every
        // run): there such a frame keeps the full-screen pass.
        (Some(ColorRoute::Storage { .. }), Some(DepthRoute::Direct)) if !inputs.depth_copies => {
            CompositeRoute::Pass
        }
        (Some(color), Some(depth)) => CompositeRoute::Split { color, depth },
        // The frame draws depth into the caller's texture: only colour is
        // left, for one colour-only pass in any format (0.101 ms against
        // the full pass's 0.149 at 1280x800 on the H100).
        (None, Some(DepthRoute::Direct)) => CompositeRoute::Split {
            color: ColorRoute::Pass,
            depth: DepthRoute::Direct,
        },
        _ => CompositeRoute::Pass,
    }
}

/// Pipelines and bind groups of the split road, made on first use.
#[derive(Default)]
pub(crate) struct SplitCache {
    color: Vec<(wgpu::TextureFormat, bool, ColorPipeline)>,
    decode: Option<wgpu::Buffer>,
    /// The last colour bind group: (Strata's colour texture, the caller's view).
    color_group: Option<(wgpu::Texture, wgpu::TextureView, wgpu::BindGroup)>,
    depth_layout: Option<wgpu::BindGroupLayout>,
    depth: Vec<(wgpu::TextureFormat, wgpu::RenderPipeline)>,
    /// The last depth bind group: (the method's depth image, its group).
    depth_group: Option<(wgpu::Texture, wgpu::BindGroup)>,
}

#[derive(Clone)]
struct ColorPipeline {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl SplitCache {
    fn color_pipeline(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        linear: bool,
    ) -> anyhow::Result<ColorPipeline> {
        if let Some((_, _, p)) = self
            .color
            .iter()
            .find(|(f, l, _)| *f == format && *l == linear)
        {
            return Ok(p.clone());
        }
        let mut text = crate::shaders::compose("composite_color.wgsl")?;
        if format == F::Rgba16Float {
            text = text.replace(
                "texture_storage_2d<rgba8unorm, write>",
                "texture_storage_2d<rgba16float, write>",
            );
        }
        let (module, error) = crate::gpu::catching(device, wgpu::ErrorFilter::Validation, || {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("composite colour"),
                source: wgpu::ShaderSource::Wgsl(text.into()),
            })
        });
        if let Some(error) = error {
            anyhow::bail!("shader `composite_color.wgsl` ({format:?}) failed to compile: {error}");
        }
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite colour"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: compute,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                crate::frame::storage_texture_entry(1, format),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: compute,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("composite colour"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("composite colour"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(if linear {
                "cs_color_linear"
            } else {
                "cs_color"
            }),
            compilation_options: Default::default(),
            cache: None,
        });
        let built = ColorPipeline { layout, pipeline };
        self.color.push((format, linear, built.clone()));
        Ok(built)
    }

    fn color_group(
        &mut self,
        shared: &crate::frame::Shared,
        target: &wgpu::TextureView,
        layout: &wgpu::BindGroupLayout,
    ) -> wgpu::BindGroup {
        if let Some((color, view, group)) = &self.color_group
            && *color == shared.color
            && view == target
        {
            return group.clone();
        }
        let decode = self
            .decode
            .get_or_insert_with(|| {
                use wgpu::util::DeviceExt;
                shared
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("srgb decode (storage)"),
                        contents: bytemuck::cast_slice(&crate::composite::srgb_decode_table()),
                        usage: wgpu::BufferUsages::STORAGE,
                    })
            })
            .clone();
        let group = crate::frame::bind_group(
            &shared.device,
            "composite colour",
            layout,
            &[
                wgpu::BindingResource::TextureView(&shared.color_view),
                wgpu::BindingResource::TextureView(target),
                decode.as_entire_binding(),
            ],
        );
        self.color_group = Some((shared.color.clone(), target.clone(), group.clone()));
        group
    }

    fn depth_layout(&mut self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        self.depth_layout
            .get_or_insert_with(|| {
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("composite depth"),
                    entries: &[crate::frame::fragment_texture_entry(0, false)],
                })
            })
            .clone()
    }

    fn depth_pipeline(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> anyhow::Result<wgpu::RenderPipeline> {
        if let Some((_, p)) = self.depth.iter().find(|(f, _)| *f == format) {
            return Ok(p.clone());
        }
        let module = crate::shaders::create_module(device, "depth_blit.wgsl")?;
        let layout = self.depth_layout(device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("composite depth"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("composite depth"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_depth_blit"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        self.depth.push((format, pipeline.clone()));
        Ok(pipeline)
    }

    fn depth_group(&mut self, device: &wgpu::Device, image: &wgpu::Texture) -> wgpu::BindGroup {
        if let Some((texture, group)) = &self.depth_group
            && texture == image
        {
            return group.clone();
        }
        let layout = self.depth_layout(device);
        let view = image.create_view(&Default::default());
        let group = crate::frame::bind_group(
            device,
            "composite depth",
            &layout,
            &[wgpu::BindingResource::TextureView(&view)],
        );
        self.depth_group = Some((image.clone(), group.clone()));
        group
    }

    /// Record the split road: colour then depth into the caller's views,
    /// Strata's frame already recorded in `encoder`. `depth_image`: the
    /// method's `R32Float` depth (required by [`DepthRoute::FromImage`]).
    pub(crate) fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        shared: &crate::frame::Shared,
        targets: &TargetViews<'_>,
        (color, depth): (ColorRoute, DepthRoute),
        depth_image: Option<&wgpu::Texture>,
        timer: Option<&crate::timing::PassTimer>,
    ) -> anyhow::Result<()> {
        let device = shared.device.clone();
        let size = wgpu::Extent3d {
            width: shared.width,
            height: shared.height,
            depth_or_array_layers: 1,
        };
        match color {
            ColorRoute::Storage { linear } => {
                let built =
                    self.color_pipeline(&device, targets.color.texture().format(), linear)?;
                let group = self.color_group(shared, targets.color, &built.layout);
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("composite colour"),
                    timestamp_writes: timer.and_then(|t| t.compute("composite colour")),
                });
                pass.set_pipeline(&built.pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
            }
            ColorRoute::Copy => encoder.copy_texture_to_texture(
                shared.color.as_image_copy(),
                targets.color.texture().as_image_copy(),
                size,
            ),
            // Drawn by the method, or by the composite's colour-only pass
            // (`CompositeCache`, recorded by the caller).
            ColorRoute::Direct | ColorRoute::Pass => {}
        }
        match depth {
            DepthRoute::Copy => encoder.copy_texture_to_texture(
                shared.depth.as_image_copy(),
                targets.depth.texture().as_image_copy(),
                size,
            ),
            DepthRoute::Direct => {}
            DepthRoute::FromImage => {
                let image = depth_image.ok_or_else(|| {
                    anyhow::anyhow!("the active method keeps no depth image to write depth from")
                })?;
                let format = targets.depth.texture().format();
                let pipeline = self.depth_pipeline(&device, format)?;
                let group = self.depth_group(&device, image);
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("composite depth"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: targets.depth,
                        depth_ops: Some(wgpu::Operations {
                            load: crate::composite::every_pixel_written(),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: format.has_stencil_aspect().then_some(wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        }),
                    }),
                    timestamp_writes: timer.and_then(|t| t.render("composite depth")),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.draw(0..3, 0..1);
            }
        }
        Ok(())
    }
}
