//! `ray-exact`'s deferred frame, on frames that cast the shadow map: the
//! march lists the shadow blocks its hits read, the shadow pass casts only
//! those, then a pass shades (`ray_exact_deferred.wgsl`; the why and the
//! numbers are in the parent module's docs).

use super::bindings::Levels;
use super::bindings::{
    beam_binding, beam_layout_entry, buffer_entry, core_bindings, core_entries, exact_pipeline,
};
use crate::frame::{Shared, storage_texture_entry};
use crate::methods::common::DepthCopy;
use crate::options::ExactOptions;

/// The compute variant's frame on frames that cast the shadow map
/// (`ray_exact_deferred.wgsl`): march (each pixel's hit column and `t` into
/// `hits`, the shadow blocks its shading reads stamped), then the exact
/// shadow pass over the stamped blocks only, then shading. The other frames
/// (map reused, shadows off) march and shade in one pass.
///
/// The hits go from march to shading in one storage buffer, not in two
/// images (`ray_exact_deferred.wgsl` says what the H100 measured).
pub(super) struct Deferred {
    pub(super) march: wgpu::ComputePipeline,
    pub(super) shade: wgpu::ComputePipeline,
    pub(super) layout: wgpu::BindGroupLayout,
    /// The march's group.
    pub(super) group: wgpu::BindGroup,
    /// The shading pass's: the march's with [`Deferred::stand_in`] in the
    /// stamps' place. It reads no stamp, and the stamps' buffer holds its
    /// indirect dispatch, which one dispatch may not also bind as storage.
    pub(super) shade_group: wgpu::BindGroup,
    /// A word of storage bound as the shading pass's stamps (WebGPU also
    /// refuses one buffer bound writable at two bindings of a dispatch).
    stand_in: wgpu::Buffer,
    /// Each pixel's hit: its column relative to the eye's tile and its `t`
    /// (`hits` in `ray_exact_deferred.wgsl`, [`HIT_BYTES`] a pixel).
    pub(super) hits: wgpu::Buffer,
    /// The hits of a frame of the targets' size fit the device
    /// ([`hits_fit`]); else every frame takes the one-pass route.
    pub(super) fits: bool,
}

/// Side of the shadow map's stamped blocks, texels (`MARK_BLOCK` in
/// `ray_exact_deferred.wgsl`).
pub(super) const MARK_BLOCK: u32 = 8;

/// The deferred frame's record of the shadow blocks its pixels sample: the
/// shadow pass's indirect dispatch (one workgroup per listed block) and a
/// stamp per block in one buffer (one storage binding fewer: paged terrain's
/// frame binds eight, WebGPU's default limit), and the list of blocks
/// stamped this frame.
pub(super) struct ShadowMarks {
    /// Words 0-2: the indirect dispatch (x the number of listed blocks);
    /// from word [`MARK_STAMPS`]: block k's stamp; after the stamps, the
    /// shading pass's indirect dispatch (x the number of listed tiles), a
    /// word of padding and a stamp per pixel tile.
    pub(super) stamps: wgpu::Buffer,
    /// The listed blocks, their tags ([`super::keep::ShadowKeep`]), then the listed
    /// pixel tiles.
    pub(super) list: wgpu::Buffer,
    blocks: u32,
    /// Pixel tiles the list has room for.
    pub(super) tiles: u32,
}

/// The first stamp's word in [`ShadowMarks::stamps`] (`MARK_STAMPS` in
/// `ray_exact_deferred.wgsl`), after the dispatch's three.
pub(super) const MARK_STAMPS: u32 = 4;

/// 8x8-pixel tiles of the shared targets (the shading pass's unit).
pub(super) fn pixel_tiles(shared: &Shared) -> u32 {
    shared.width.div_ceil(8) * shared.height.div_ceil(8)
}

impl ShadowMarks {
    /// For `blocks` shadow blocks and `tiles` pixel tiles.
    pub(super) fn new(device: &wgpu::Device, blocks: u32, tiles: u32) -> Self {
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        };
        ShadowMarks {
            stamps: buffer(
                "ray-exact shadow stamps",
                (u64::from(MARK_STAMPS + blocks + 4) + u64::from(tiles)) * 4,
                wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            ),
            // The list, three words of tag per block (`shadow_keep.wgsl`),
            // then the tiles.
            // (Written by the CPU too: the cover's blocks, `cover.rs`.)
            list: buffer(
                "ray-exact shadow blocks",
                (u64::from(blocks) * 4 + u64::from(tiles)) * 4,
                wgpu::BufferUsages::COPY_DST,
            ),
            blocks,
            tiles,
        }
    }

    /// Byte offset of the shading pass's indirect dispatch in `stamps`.
    pub(super) fn shade_dispatch(&self) -> u64 {
        u64::from(MARK_STAMPS + self.blocks) * 4
    }

    pub(super) fn bytes(&self) -> u64 {
        self.stamps.size() + self.list.size()
    }

    /// Clear the tags of the texture's slot blocks `slots` (sorted), so that
    /// no frame keeps what they hold (`shadow_keep.wgsl`: three words a slot
    /// after the list; a zero key matches none). One write per run of
    /// consecutive slots.
    pub(super) fn clear_tags(&self, queue: &wgpu::Queue, slots: &[u32]) {
        let mut i = 0;
        while i < slots.len() {
            let mut n = 1;
            while i + n < slots.len() && slots[i + n] == slots[i] + n as u32 {
                n += 1;
            }
            let word = u64::from(self.blocks + 3 * slots[i]);
            queue.write_buffer(&self.list, word * 4, &vec![0u8; 12 * n]);
            i += n;
        }
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
            storage_texture_entry(4, wgpu::TextureFormat::R32Float),
        ]);
        for binding in 5..=7 {
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
        let hits = hits_buffer(shared);
        let stand_in = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ray-exact shading's stamps stand-in"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let buffers = (params, levels, stats, marks);
        let group = |stamps| Self::group(shared, &layout, buffers, depth, &hits, beam, stamps);
        Ok(Deferred {
            fits: hits_fit(shared),
            march,
            shade,
            group: group(&marks.stamps),
            shade_group: group(&stand_in),
            stand_in,
            layout,
            hits,
        })
    }

    /// Both groups again, over the current hits and `marks`.
    pub(super) fn rebind(
        &mut self,
        shared: &Shared,
        buffers: (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
        depth: &DepthCopy,
        beam: Option<&wgpu::Buffer>,
    ) {
        let stamps = &buffers.3.stamps;
        let (layout, hits) = (&self.layout, &self.hits);
        self.group = Self::group(shared, layout, buffers, depth, hits, beam, stamps);
        let stand_in = &self.stand_in;
        self.shade_group = Self::group(shared, layout, buffers, depth, hits, beam, stand_in);
    }

    #[allow(clippy::too_many_arguments)]
    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        (params, levels, stats, marks): (&wgpu::Buffer, &Levels, &wgpu::Buffer, &ShadowMarks),
        depth: &DepthCopy,
        hits: &wgpu::Buffer,
        beam: Option<&wgpu::Buffer>,
        stamps: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let mut entries = core_bindings(params, levels, stats);
        entries.extend(depth.bindings(shared, 3));
        entries.push(wgpu::BindGroupEntry {
            binding: 5,
            resource: hits.as_entire_binding(),
        });
        for (binding, buffer) in [(6, stamps), (7, &marks.list)] {
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

/// Bytes of the deferred frame's hits a pixel: the packed column and `t`.
pub(super) const HIT_BYTES: u64 = 8;

/// Whether the hits of a frame of the targets' size fit one storage
/// binding of the device. Past it (under WebGPU's default 128 MiB binding, a
/// frame of more than 16.7 million pixels) the method marches and shades in
/// one pass after casting the view's whole shadow cover, as on frames that
/// reuse the map: the same picture, without the deferred frame's savings.
pub(super) fn hits_fit(shared: &Shared) -> bool {
    hits_fit_in(shared.width, shared.height, &shared.device.limits())
}

/// [`hits_fit`] for a frame of `width` x `height` under `limits`.
pub(super) fn hits_fit_in(width: u32, height: u32, limits: &wgpu::Limits) -> bool {
    let bytes = u64::from(width) * u64::from(height) * HIT_BYTES;
    bytes <= limits.max_storage_buffer_binding_size && bytes <= limits.max_buffer_size
}

/// The deferred frame's per-pixel hits at the targets' size (a placeholder
/// of one pixel where they do not fit: [`hits_fit`]).
pub(super) fn hits_buffer(shared: &Shared) -> wgpu::Buffer {
    let pixels = if hits_fit(shared) {
        u64::from(shared.width) * u64::from(shared.height)
    } else {
        1
    };
    shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ray-exact hits"),
        size: pixels * HIT_BYTES,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    })
}
