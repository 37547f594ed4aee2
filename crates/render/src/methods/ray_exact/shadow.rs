//! `ray-exact`'s shadow-map pass (`ray_exact_shadow.wgsl`): the shared map
//! filled by the same exact march along the light, either every texel of the
//! view's cover or, in the deferred frame, the 8x8 blocks its march listed
//! (one workgroup each, an indirect dispatch), tagging each block it casts
//! so that later frames keep it (`shadow_keep.wgsl`).

use super::bindings::{Levels, buffer_entry, core_bindings, core_entries, exact_pipeline};
use super::deferred::ShadowMarks;
use crate::frame::{SHADOW_SIZE, Shared, storage_texture_entry};
use crate::methods::contract::Frame;
use crate::options::ExactOptions;

/// The exact shadow-map pass: group 0 without the shadow map (it is written
/// here), group 1 the core's bindings, the map as storage and the listed
/// blocks with their tags.
pub(super) struct ExactShadow {
    /// Every texel of the view's cover.
    pipeline: wgpu::ComputePipeline,
    /// The deferred frame's listed blocks (indirect).
    blocks: wgpu::ComputePipeline,
    frame_group: wgpu::BindGroup,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
}

impl ExactShadow {
    pub(super) fn new(
        shared: &Shared,
        buffers: (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
        options: ExactOptions,
    ) -> anyhow::Result<Self> {
        let levels = buffers.1;
        let device = &shared.device;
        let (frame_layout, frame_group) =
            crate::shadow::frame_without_shadow_map(shared, "ray-exact shadow frame");
        let mut entries = core_entries(wgpu::ShaderStages::COMPUTE, levels.is_paged());
        entries.push(storage_texture_entry(3, wgpu::TextureFormat::R32Float));
        // The listed blocks, and their tags to write (`shadow_keep.wgsl`).
        entries.push(buffer_entry(
            4,
            wgpu::ShaderStages::COMPUTE,
            wgpu::BufferBindingType::Storage { read_only: false },
        ));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ray-exact shadow"),
            entries: &entries,
        });
        let group = Self::group(shared, &layout, buffers);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ray-exact shadow"),
            bind_group_layouts: &[Some(&frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str| {
            exact_pipeline(
                shared,
                "ray-exact shadow",
                levels,
                "ray_exact_shadow.wgsl",
                &pipeline_layout,
                entry,
                options,
            )
        };
        Ok(ExactShadow {
            pipeline: pipeline("cs_exact_shadow")?,
            blocks: pipeline("cs_exact_shadow_blocks")?,
            frame_group,
            layout,
            group,
        })
    }

    /// Group 1 again, over new marks (a resize that outgrew the tile list).
    pub(super) fn rebind(
        &mut self,
        shared: &Shared,
        buffers: (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
    ) {
        self.group = Self::group(shared, &self.layout, buffers);
    }

    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        (params, levels, stats, marks): (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
    ) -> wgpu::BindGroup {
        let mut bindings = core_bindings(params, levels, stats);
        bindings.push(wgpu::BindGroupEntry {
            binding: 3,
            resource: wgpu::BindingResource::TextureView(&shared.shadow_view),
        });
        bindings.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: marks.list.as_entire_binding(),
        });
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ray-exact shadow"),
            layout,
            entries: &bindings,
        })
    }

    /// Cast every texel of the view's cover.
    pub(super) fn record_cover(&self, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = self.begin(frame, encoder, "shadow");
        pass.set_pipeline(&self.pipeline);
        pass.dispatch_workgroups(SHADOW_SIZE.div_ceil(8), SHADOW_SIZE.div_ceil(8), 1);
    }

    /// Cast the blocks the deferred frame's march listed in `marks`.
    pub(super) fn record_listed(
        &self,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        marks: &ShadowMarks,
    ) {
        let mut pass = self.begin(frame, encoder, "shadow");
        pass.set_pipeline(&self.blocks);
        pass.dispatch_workgroups_indirect(&marks.stamps, 0);
    }

    /// Cast the first `count` blocks of the list (written by the CPU: the
    /// view's cover, `cover.rs`), ahead of the march. Labelled a build: it
    /// fills a cache the later frames of a still view need no pass for, and
    /// the harness warms a method up until its frames stop building.
    pub(super) fn record_blocks(
        &self,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        count: u32,
    ) {
        let mut pass = self.begin(frame, encoder, "shadow cover build");
        pass.set_pipeline(&self.blocks);
        pass.dispatch_workgroups(count, 1, 1);
    }

    fn begin<'e>(
        &self,
        frame: &Frame<'_>,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
    ) -> wgpu::ComputePass<'e> {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: frame.timer.compute(label),
        });
        pass.set_bind_group(0, &self.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass
    }
}
