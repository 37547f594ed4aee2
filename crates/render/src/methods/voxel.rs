//! `voxel` and `voxel-compute`: the voxel-accelerated ray march (paper §3.2).
//! A hierarchical DDA over the occupancy pyramid ([`voxel_build`]) skips
//! known-empty space; leaf voxels are sampled with the exact two-interval
//! test. `voxel` is a full-screen fragment pass, `voxel-compute` one compute
//! invocation per pixel plus the core's depth copy; both shade with the
//! shared `shade` and write the same depth as `ray`.
//!
//! [`voxel_build`]: super::voxel_build

use super::voxel_build::{DEFAULT_BUDGET_TEXELS, GpuPyramid};
use super::{Frame, Method, MethodSettings, RetainedBytes};
use crate::frame::{
    COLOR_FORMAT, DEPTH_FORMAT, Shared, sky_clear, storage_texture_entry, texture_entry,
};
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_occupancy::VoxelSize;

/// Levels the traversal's uniform table holds (`VOXEL_MAX_LEVELS` in WGSL).
const MAX_LEVELS: usize = 16;
/// Most exact samples inside one leaf voxel's ray segment.
const LEAF_SAMPLES: u32 = 32;

/// Twin of `VoxelParams` in `voxel_occupancy.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct VoxelParams {
    config: [u32; 4],
    voxel: [u32; 4],
    levels: [[u32; 8]; MAX_LEVELS],
}

/// The compute variant's extra parts: its depth image and the copy into the shared depth.
struct ComputeParts {
    march: wgpu::ComputePipeline,
    blit: wgpu::RenderPipeline,
    blit_group: wgpu::BindGroup,
    depth_bytes: u64,
}

pub struct Voxel {
    name: &'static str,
    pyramid: GpuPyramid,
    group: wgpu::BindGroup,
    fragment: Option<wgpu::RenderPipeline>,
    compute: Option<ComputeParts>,
}

impl Voxel {
    /// The GPU pyramid (tests compare it with the CPU build).
    pub fn pyramid(&self) -> &GpuPyramid {
        &self.pyramid
    }
}

/// Check the voxel settings: grid and step budget.
fn voxel_size(settings: &MethodSettings) -> anyhow::Result<VoxelSize> {
    if settings.voxel_steps == 0 {
        anyhow::bail!("voxel steps must be at least 1 (got 0)");
    }
    let [x, y, z] = settings.voxel_size;
    Ok(VoxelSize { x, y, z })
}

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    Ok(Box::new(build(
        shared,
        level,
        settings,
        false,
        DEFAULT_BUDGET_TEXELS,
    )?))
}

pub fn create_compute(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    Ok(Box::new(build(
        shared,
        level,
        settings,
        true,
        DEFAULT_BUDGET_TEXELS,
    )?))
}

/// Build either variant with a given per-frame build budget (texels).
pub fn build(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
    compute: bool,
    budget_texels: u64,
) -> anyhow::Result<Voxel> {
    let voxel = voxel_size(settings)?;
    let pyramid = GpuPyramid::new(shared, level, voxel, budget_texels)?;
    let layout = &pyramid.layout;
    if layout.levels.len() > MAX_LEVELS {
        anyhow::bail!(
            "voxel grid ({voxel}) on a {}x{} map needs {} pyramid levels; at most {MAX_LEVELS} are supported",
            level.width(),
            level.height(),
            layout.levels.len()
        );
    }
    let mut params = VoxelParams {
        config: [
            settings.voxel_steps,
            layout.levels.len() as u32,
            LEAF_SAMPLES,
            0,
        ],
        voxel: [voxel.x, voxel.y, voxel.z, 0],
        levels: [[0; 8]; MAX_LEVELS],
    };
    for (slot, row) in params
        .levels
        .iter_mut()
        .zip(layout.level_table().chunks_exact(8))
    {
        slot.copy_from_slice(row);
    }
    let params = shared.uniform_buffer("voxel params", bytemuck::bytes_of(&params));
    let device = &shared.device;

    let mut entries = vec![
        wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 1,
            visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
    ];
    let depth = compute.then(|| {
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("voxel-compute depth"),
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
        t.create_view(&Default::default())
    });
    if compute {
        entries.push(storage_texture_entry(2, COLOR_FORMAT));
        entries.push(storage_texture_entry(3, wgpu::TextureFormat::R32Float));
    }
    let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("voxel"),
        entries: &entries,
    });
    let mut bindings = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: pyramid.buffer.as_entire_binding(),
        },
    ];
    if let Some(depth) = &depth {
        bindings.push(wgpu::BindGroupEntry {
            binding: 2,
            resource: wgpu::BindingResource::TextureView(&shared.color_view),
        });
        bindings.push(wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::TextureView(depth),
        });
    }
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("voxel"),
        layout: &group_layout,
        entries: &bindings,
    });
    let pipeline_layout = shared.pipeline_layout("voxel", &[&group_layout]);

    let (fragment, compute_parts, name) = match depth {
        None => {
            let module = shared.shader("voxel.wgsl")?;
            let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("voxel"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(depth_always()),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_voxel"),
                    compilation_options: Default::default(),
                    targets: &[Some(COLOR_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
            (Some(pipeline), None, "voxel")
        }
        Some(depth_view) => {
            let module = shared.shader("voxel_compute.wgsl")?;
            let march = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("voxel-compute"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("cs_voxel"),
                compilation_options: Default::default(),
                cache: None,
            });
            let (blit, blit_group) = depth_blit(shared, &depth_view)?;
            let parts = ComputeParts {
                march,
                blit,
                blit_group,
                depth_bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
            };
            (None, Some(parts), "voxel-compute")
        }
    };
    Ok(Voxel {
        name,
        pyramid,
        group,
        fragment,
        compute: compute_parts,
    })
}

fn depth_always() -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Always),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The core's `fs_depth_blit` over this method's R32Float depth image.
fn depth_blit(
    shared: &Shared,
    depth: &wgpu::TextureView,
) -> anyhow::Result<(wgpu::RenderPipeline, wgpu::BindGroup)> {
    let device = &shared.device;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("voxel depth blit"),
        entries: &[texture_entry(
            0,
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2,
        )],
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("voxel depth blit"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::TextureView(depth),
        }],
    });
    let module = shared.shader("depth_blit.wgsl")?;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("voxel depth blit"),
        layout: Some(
            &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("voxel depth blit"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            }),
        ),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(depth_always()),
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
    Ok((pipeline, group))
}

impl Method for Voxel {
    fn name(&self) -> &'static str {
        self.name
    }

    fn apply_edit(
        &mut self,
        _shared: &Shared,
        _level: &Level,
        rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        self.pyramid.enqueue(rects)
    }

    fn prepare(&mut self, shared: &Shared, _camera: &Camera) -> anyhow::Result<()> {
        self.pyramid.prepare(shared);
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if self.pyramid.has_work() {
            self.pyramid
                .record(encoder, frame.timer.compute("voxel occupancy update"));
        }
        if let Some(pipeline) = &self.fragment {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("voxel"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &shared.color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(sky_clear()),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(depth_attachment(shared)),
                timestamp_writes: frame.timer.render("voxel"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.group, &[]);
            pass.draw(0..3, 0..1);
            return;
        }
        let Some(c) = &self.compute else { return };
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("voxel-compute march"),
                timestamp_writes: frame.timer.compute("voxel-compute march"),
            });
            pass.set_pipeline(&c.march);
            pass.set_bind_group(0, &shared.frame_group, &[]);
            pass.set_bind_group(1, &self.group, &[]);
            pass.dispatch_workgroups(shared.width.div_ceil(8), shared.height.div_ceil(8), 1);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("voxel-compute depth copy"),
            color_attachments: &[],
            depth_stencil_attachment: Some(depth_attachment(shared)),
            timestamp_writes: frame.timer.render("voxel-compute depth copy"),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&c.blit);
        pass.set_bind_group(0, &c.blit_group, &[]);
        pass.draw(0..3, 0..1);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        let params = std::mem::size_of::<VoxelParams>() as u64;
        let depth = self.compute.as_ref().map_or(0, |c| c.depth_bytes);
        RetainedBytes {
            gpu: self.pyramid.gpu_bytes() + params + depth,
            // The layout table and the edit queue: a few hundred bytes.
            cpu: 0,
        }
    }
}

fn depth_attachment(shared: &Shared) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view: &shared.depth_view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

#[cfg(test)]
#[path = "voxel_tests.rs"]
mod tests;
