//! `ray-exact`'s deferred frame, on frames that cast the shadow map: the
//! march lists the shadow blocks its hits read, the shadow pass casts only
//! those, then a pass shades (`ray_exact_deferred.wgsl`; the why and the
//! numbers are in the parent module's docs).

use super::bindings::Levels;
use super::bindings::{
    beam_binding, beam_layout_entry, buffer_entry, core_bindings, core_entries, exact_pipeline,
};
use crate::frame::{Shared, storage_texture_entry, storage_texture_entry_with, texture_2d};
use crate::methods::common::DepthCopy;
use crate::options::ExactOptions;
use wgpu::StorageTextureAccess::ReadWrite;

/// The compute variant's frame on frames that cast the shadow map
/// (`ray_exact_deferred.wgsl`): march (hit `t` into the depth image, hit
/// column into `hits`, the shadow blocks its shading reads stamped), then the
/// exact shadow pass over the stamped blocks only, then shading. The other
/// frames (map reused, shadows off) march and shade in one pass.
pub(super) struct Deferred {
    pub(super) march: wgpu::ComputePipeline,
    pub(super) shade: wgpu::ComputePipeline,
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) group: wgpu::BindGroup,
    /// R32Uint: each pixel's hit column relative to the eye's tile.
    pub(super) hits: wgpu::TextureView,
}

/// Side of the shadow map's stamped blocks, texels (`MARK_BLOCK` in
/// `ray_exact_deferred.wgsl`).
pub(super) const MARK_BLOCK: u32 = 8;

/// The deferred frame's record of the shadow blocks its pixels sample: a
/// stamp per block, the list of blocks stamped this frame, and the shadow
/// pass's indirect dispatch (one workgroup per listed block).
pub(super) struct ShadowMarks {
    stamps: wgpu::Buffer,
    pub(super) list: wgpu::Buffer,
    pub(super) dispatch: wgpu::Buffer,
}

impl ShadowMarks {
    pub(super) fn new(device: &wgpu::Device, blocks: u32) -> Self {
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        };
        let bytes = u64::from(blocks) * 4;
        ShadowMarks {
            stamps: buffer(
                "ray-exact shadow stamps",
                bytes,
                wgpu::BufferUsages::empty(),
            ),
            list: buffer(
                "ray-exact shadow blocks",
                bytes,
                wgpu::BufferUsages::empty(),
            ),
            dispatch: buffer(
                "ray-exact shadow dispatch",
                12,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            ),
        }
    }

    pub(super) fn bytes(&self) -> u64 {
        self.stamps.size() + self.list.size() + self.dispatch.size()
    }
}

impl Deferred {
    pub(super) fn new(
        shared: &Shared,
        (params, levels, stats, marks): (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
        depth: &DepthCopy,
        beam: Option<&wgpu::Buffer>,
        options: ExactOptions,
    ) -> anyhow::Result<Self> {
        let device = &shared.device;
        let mut entries = core_entries(wgpu::ShaderStages::COMPUTE, levels.is_paged());
        entries.extend([
            storage_texture_entry(3, crate::frame::COLOR_FORMAT),
            storage_texture_entry_with(4, wgpu::TextureFormat::R32Float, ReadWrite),
            storage_texture_entry_with(5, wgpu::TextureFormat::R32Uint, ReadWrite),
        ]);
        for binding in 6..=8 {
            entries.push(buffer_entry(
                binding,
                wgpu::ShaderStages::COMPUTE,
                wgpu::BufferBindingType::Storage { read_only: false },
            ));
        }
        entries.extend(beam.map(|_| beam_layout_entry()));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ray-exact deferred"),
            entries: &entries,
        });
        let pipeline_layout = shared.pipeline_layout("ray-exact deferred", &[&layout]);
        let pipeline = |label: &str, entry: &str| {
            exact_pipeline(
                shared,
                label,
                levels,
                "ray_exact_deferred.wgsl",
                &pipeline_layout,
                entry,
                options,
            )
        };
        let march = pipeline("ray-exact march", "cs_exact_march_hits")?;
        let shade = pipeline("ray-exact shade", "cs_exact_shade")?;
        let hits = hits_image(shared);
        let group = Self::group(
            shared,
            &layout,
            (params, levels, stats, marks),
            depth,
            &hits,
            beam,
        );
        Ok(Deferred {
            march,
            shade,
            layout,
            group,
            hits,
        })
    }

    pub(super) fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        (params, levels, stats, marks): (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
        depth: &DepthCopy,
        hits: &wgpu::TextureView,
        beam: Option<&wgpu::Buffer>,
    ) -> wgpu::BindGroup {
        let mut entries = core_bindings(params, levels, stats);
        entries.extend(depth.bindings(shared, 3));
        entries.push(wgpu::BindGroupEntry {
            binding: 5,
            resource: wgpu::BindingResource::TextureView(hits),
        });
        for (binding, buffer) in [(6, &marks.stamps), (7, &marks.list), (8, &marks.dispatch)] {
            entries.push(wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            });
        }
        entries.extend(beam.map(beam_binding));
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ray-exact deferred"),
            layout,
            entries: &entries,
        })
    }
}

/// The deferred frame's per-pixel hit columns: R32Uint at the targets' size.
pub(super) fn hits_image(shared: &Shared) -> wgpu::TextureView {
    let (_, view) = texture_2d(
        &shared.device,
        "ray-exact hits",
        (shared.width, shared.height),
        wgpu::TextureFormat::R32Uint,
        wgpu::TextureUsages::STORAGE_BINDING,
    );
    view
}
