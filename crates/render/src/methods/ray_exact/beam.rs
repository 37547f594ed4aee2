//! `ray-exact`'s beam pre-pass over the whole map (`ray_exact_beam.wgsl`,
//! issue 36 item 1): the least `t` at which any of an 8x8-pixel tile's
//! camera rays may meet a solid point (the argument that it never passes a
//! hit is in the shader), searched by one workgroup per tile, 64 slices at
//! a time (`BeamSearch::WidePass`, `cs_exact_beam_wide`), or by one
//! invocation per tile walking it (`BeamSearch::Serial`, `cs_exact_beam`);
//! the march starts each ray there. `BeamSearch::Wide` searches in the
//! march's own workgroup instead: no pass here. Same image, fewer
//! iterations: the counts (`strata exact-counts`, [`super::replay`]) are in
//! `bench/issue36-beam/`. [`crate::options::ExactOptions::beam`] off
//! (`STRATA_EXACT_BEAM=off`) skips the pass and the march does not read its
//! buffer. Paged terrain has none (its finer levels live per page).

use super::bindings::{
    Levels, beam_binding, beam_layout_entry, core_bindings, core_entries, exact_pipeline,
};
use crate::frame::Shared;
use crate::methods::contract::Frame;
use crate::options::{BeamSearch, ExactOptions};

/// Side of a tile in pixels (`BEAM_TILE`).
const TILE: u32 = super::replay::BEAM_TILE;

/// The pass and the tiles' starts it writes.
pub(super) struct Beam {
    /// `None` with the beam off or searched wide: the buffer is bound, never
    /// written or read.
    pipeline: Option<wgpu::ComputePipeline>,
    /// The wide pre-pass (a workgroup per tile), else the serial one.
    wide: bool,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    /// One f32 per tile of the targets.
    pub(super) buffer: wgpu::Buffer,
}

/// The starts' buffer for the shared targets' size.
fn starts_buffer(shared: &Shared) -> wgpu::Buffer {
    let tiles = u64::from(shared.width.div_ceil(TILE)) * u64::from(shared.height.div_ceil(TILE));
    shared.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ray-exact beam starts"),
        size: tiles.max(1) * 4,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    })
}

impl Beam {
    pub(super) fn new(
        shared: &Shared,
        (params, levels, stats): (&wgpu::Buffer, &Levels, &wgpu::Buffer),
        options: ExactOptions,
    ) -> anyhow::Result<Self> {
        let mut entries = core_entries(wgpu::ShaderStages::COMPUTE, false);
        entries.push(beam_layout_entry());
        let layout = shared
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("ray-exact beam"),
                entries: &entries,
            });
        // The wide search in the march's workgroups has no pre-pass.
        let entry = match options.beam_search {
            BeamSearch::Serial => Some("cs_exact_beam"),
            BeamSearch::WidePass => Some("cs_exact_beam_wide"),
            BeamSearch::Wide => None,
        };
        let pipeline = match entry {
            Some(entry) if options.beam => Some(exact_pipeline(
                shared,
                "ray-exact beam",
                levels,
                "ray_exact.wgsl",
                &shared.pipeline_layout("ray-exact beam", &[&layout]),
                entry,
                options,
            )?),
            _ => None,
        };
        let buffer = starts_buffer(shared);
        let group = Self::group(shared, &layout, (params, levels, stats), &buffer);
        Ok(Beam {
            pipeline,
            wide: options.beam_search.is_wide(),
            layout,
            group,
            buffer,
        })
    }

    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        (params, levels, stats): (&wgpu::Buffer, &Levels, &wgpu::Buffer),
        buffer: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let mut entries = core_bindings(params, levels, stats);
        entries.push(beam_binding(buffer));
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ray-exact beam"),
            layout,
            entries: &entries,
        })
    }

    /// A buffer for the targets' new size (rebind it in the march's groups).
    pub(super) fn resize(
        &mut self,
        shared: &Shared,
        buffers: (&wgpu::Buffer, &Levels, &wgpu::Buffer),
    ) {
        self.buffer = starts_buffer(shared);
        self.group = Self::group(shared, &self.layout, buffers, &self.buffer);
    }

    /// The pass, before the march (nothing with the beam off).
    pub(super) fn record(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        let label = "ray-exact beam";
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: frame.timer.compute(label),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        let tiles = (shared.width.div_ceil(TILE), shared.height.div_ceil(TILE));
        if self.wide {
            // A workgroup per tile.
            pass.dispatch_workgroups(tiles.0, tiles.1, 1);
        } else {
            // An invocation per tile.
            pass.dispatch_workgroups(tiles.0.div_ceil(8), tiles.1.div_ceil(8), 1);
        }
    }

    pub(super) fn bytes(&self) -> u64 {
        self.buffer.size()
    }
}
