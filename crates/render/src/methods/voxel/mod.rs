//! `voxel` and `voxel-compute`: the voxel-accelerated ray march (paper §3.2).
//! A hierarchical DDA over the occupancy pyramid ([`pyramid`]) skips
//! known-empty space; leaf voxels are sampled with the exact two-interval
//! test. `voxel` is a full-screen fragment pass, `voxel-compute` one compute
//! invocation per pixel plus the core's depth copy; both shade with the
//! shared `shade` and write the same depth as `ray`.
//!
//! `voxel` (the fragment pass) begins each ray's traversal at the leaf that
//! holds its 8x8-pixel tile's beam start (`methods/march_beam.rs`) where the
//! adapter runs compute and lets fragments read storage: the same leaves
//! sampled over the same intervals, in fewer steps (issue 36 item 2;
//! `voxel:…/nobeam` traverses as before).
//!
//! [`pyramid`]: pyramid

use super::common::{
    DepthCopy, compute_pipeline, dispatch_per_pixel, draw_fullscreen, fullscreen_pipeline,
};
mod knobs;
pub mod pyramid;
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use super::march_beam::MarchBeam;
use crate::frame::Shared;
pub use knobs::{KNOBS, SWEEP};
use pyramid::{DEFAULT_BUDGET_TEXELS, GpuPyramid};
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_occupancy::VoxelSize;

/// Levels the traversal's uniform table holds (`VOXEL_MAX_LEVELS` in WGSL).
const MAX_LEVELS: usize = 16;

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
    depth: DepthCopy,
}

pub struct Voxel {
    name: &'static str,
    pyramid: GpuPyramid,
    /// The grid the pyramid was built for (a new one needs a rebuild).
    voxel_size: [u32; 3],
    params: wgpu::Buffer,
    group_layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    fragment: Option<wgpu::RenderPipeline>,
    compute: Option<ComputeParts>,
    /// The fragment pass's tile starts (none: `/nobeam`, the compute
    /// variant, or no compute / fragment storage).
    beam: Option<MarchBeam>,
    /// `settings.march_beam` at creation (a change rebuilds `voxel`).
    march_beam: bool,
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
            // Unused since a leaf's piece of the ray is walked texel by
            // texel (`voxel_leaf`): it was the most samples in one leaf.
            0,
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
    let depth = compute
        .then(|| DepthCopy::new(shared, "voxel-compute", "voxel depth blit"))
        .transpose()?;
    if compute {
        entries.extend(DepthCopy::layout_entries(2));
    }
    let beam = if !compute && settings.march_beam && MarchBeam::available(shared, level) {
        entries.push(MarchBeam::layout_entry());
        Some(MarchBeam::new(shared, level, "voxel beam")?)
    } else {
        None
    };
    let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("voxel"),
        entries: &entries,
    });
    let group = voxel_group(
        shared,
        &group_layout,
        (&params, &pyramid),
        depth.as_ref(),
        beam.as_ref(),
    );
    let pipeline_layout = shared.pipeline_layout("voxel", &[&group_layout]);

    let (fragment, compute_parts, name) = match depth {
        None => {
            let (shader, entry) = if beam.is_some() {
                ("voxel_beam.wgsl", "fs_voxel_beam")
            } else {
                ("voxel.wgsl", "fs_voxel")
            };
            let pipeline = fullscreen_pipeline(shared, "voxel", shader, &pipeline_layout, entry)?;
            (Some(pipeline), None, "voxel")
        }
        Some(depth) => {
            let march = compute_pipeline(
                shared,
                "voxel-compute",
                "voxel_compute.wgsl",
                &pipeline_layout,
                "cs_voxel",
            )?;
            (None, Some(ComputeParts { march, depth }), "voxel-compute")
        }
    };
    Ok(Voxel {
        name,
        pyramid,
        voxel_size: settings.voxel_size,
        params,
        group_layout,
        group,
        fragment,
        compute: compute_parts,
        beam,
        march_beam: settings.march_beam,
    })
}

/// Parameters, the pyramid and, for the compute variant, its outputs; for
/// the fragment pass with the beam, its starts.
fn voxel_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    (params, pyramid): (&wgpu::Buffer, &GpuPyramid),
    depth: Option<&DepthCopy>,
    beam: Option<&MarchBeam>,
) -> wgpu::BindGroup {
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
    if let Some(depth) = depth {
        bindings.extend(depth.bindings(shared, 2));
    }
    bindings.extend(beam.map(MarchBeam::binding));
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("voxel"),
        layout,
        entries: &bindings,
    })
}

impl Voxel {
    /// The compute variant's group again, over its current depth image and
    /// colour output (after a resize or a new colour output).
    fn rebind_compute(&mut self, shared: &Shared) {
        if let Some(c) = &self.compute {
            self.group = voxel_group(
                shared,
                &self.group_layout,
                (&self.params, &self.pyramid),
                Some(&c.depth),
                None,
            );
        }
    }
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
        if let Some(beam) = &mut self.beam {
            beam.enqueue(rects);
        }
        self.pyramid.enqueue(rects)
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        voxel_size(settings)?;
        let beam_changed = self.fragment.is_some() && settings.march_beam != self.march_beam;
        if settings.voxel_size != self.voxel_size || beam_changed {
            return Ok(false);
        }
        // The step budget is `VoxelParams.config[0]`, the uniform's first word.
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&settings.voxel_steps));
        Ok(true)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        // The compute variant binds the targets, the fragment pass with the
        // beam its starts (one per tile of the targets).
        if let Some(c) = &mut self.compute {
            c.depth.resize(shared);
            self.rebind_compute(shared);
        }
        if let Some(beam) = &mut self.beam {
            beam.resize(shared);
            self.group = voxel_group(
                shared,
                &self.group_layout,
                (&self.params, &self.pyramid),
                None,
                Some(beam),
            );
        }
        Ok(())
    }

    fn draws_color_by_attachment(&self) -> bool {
        self.compute.is_none()
    }

    fn store_color_into(
        &mut self,
        shared: &Shared,
        view: Option<&wgpu::TextureView>,
    ) -> anyhow::Result<bool> {
        let Some(c) = &mut self.compute else {
            return Ok(view.is_none());
        };
        if c.depth.set_color_out(view) {
            self.rebind_compute(shared);
        }
        Ok(true)
    }

    fn prepare(&mut self, shared: &Shared, _camera: &Camera) -> anyhow::Result<()> {
        self.pyramid.prepare(shared);
        if let Some(beam) = &mut self.beam {
            beam.prepare(shared);
        }
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if self.pyramid.has_work() {
            self.pyramid
                .record(encoder, frame.timer.compute("voxel occupancy update"));
        }
        if let Some(beam) = &self.beam {
            beam.record(shared, frame, encoder);
        }
        if let Some(pipeline) = &self.fragment {
            draw_fullscreen(shared, frame, encoder, "voxel", pipeline, &self.group);
            return;
        }
        let Some(c) = &self.compute else { return };
        dispatch_per_pixel(
            shared,
            frame,
            encoder,
            "voxel-compute march",
            &c.march,
            &self.group,
        );
        c.depth
            .record(shared, frame, encoder, "voxel-compute depth copy");
    }

    fn retained_bytes(&self) -> RetainedBytes {
        let params = std::mem::size_of::<VoxelParams>() as u64;
        let depth = self.compute.as_ref().map_or(0, |c| c.depth.bytes());
        let beam = self.beam.as_ref().map_or(0, MarchBeam::gpu_bytes);
        RetainedBytes {
            gpu: self.pyramid.gpu_bytes() + params + depth + beam,
            // The layout table and the edit queue: a few hundred bytes.
            cpu: 0,
        }
    }

    fn depth_image(&self) -> Option<&wgpu::Texture> {
        self.compute.as_ref().map(|c| c.depth.texture())
    }
}

#[cfg(test)]
mod tests;
