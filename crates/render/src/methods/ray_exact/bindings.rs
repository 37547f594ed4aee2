//! The bindings and pipelines `ray-exact`'s passes share: the march, the
//! deferred frame's passes and the exact shadow map all read the pyramid and
//! the march's parameters the same way.

use super::pyramid::GpuMaxMip;
use crate::frame::Shared;
use crate::methods::common::DepthCopy;
use crate::options::ExactOptions;

pub(super) fn buffer_entry(
    binding: u32,
    stages: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: stages,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Layout entries 0..=2 of group 1: parameters, pyramid, statistics.
pub(super) fn core_entries(stages: wgpu::ShaderStages) -> Vec<wgpu::BindGroupLayoutEntry> {
    vec![
        buffer_entry(0, stages, wgpu::BufferBindingType::Uniform),
        buffer_entry(
            1,
            stages,
            wgpu::BufferBindingType::Storage { read_only: true },
        ),
        buffer_entry(
            2,
            stages,
            wgpu::BufferBindingType::Storage { read_only: false },
        ),
    ]
}

pub(super) fn core_bindings<'a>(
    params: &'a wgpu::Buffer,
    pyramid: &'a GpuMaxMip,
    stats: &'a wgpu::Buffer,
) -> Vec<wgpu::BindGroupEntry<'a>> {
    vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 1,
            resource: pyramid.buffer.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: stats.as_entire_binding(),
        },
    ]
}

pub(super) fn march_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    pyramid: &GpuMaxMip,
    stats: &wgpu::Buffer,
    depth: Option<&DepthCopy>,
) -> wgpu::BindGroup {
    let mut entries = core_bindings(params, pyramid, stats);
    if let Some(depth) = depth {
        entries.extend(depth.bindings(shared, 3));
    }
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray-exact"),
        layout,
        entries: &entries,
    })
}

/// A compute pipeline of the exact core with its traversal constants.
pub(super) fn exact_pipeline(
    shared: &Shared,
    label: &str,
    shader: &str,
    layout: &wgpu::PipelineLayout,
    entry: &str,
    options: ExactOptions,
) -> anyhow::Result<wgpu::ComputePipeline> {
    super::super::common::compute_pipeline_with_constants(
        shared,
        label,
        shader,
        layout,
        entry,
        &[
            ("EXACT_CLIMB", f64::from(options.climb)),
            ("EXACT_LOG_RATIO", f64::from(options.log_ratio)),
        ],
    )
}
