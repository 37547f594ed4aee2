//! Plain `sliced`'s gap pass (`shaders/sliced_gaps.wgsl`): over the bands of
//! rows whose rays may cross the slices more than `rows::GAP_MIN` texels
//! apart, each pixel walks its ray to the first solid point and writes it
//! where it lies before the slice the depth buffer holds.
//!
//! Why a pass and not the slice fragments: walking each air fragment's gap
//! in the slice shader (`sliced:N/fragwalk`, as the first fix of issue 36's
//! item 4 did) runs one walk per slice a ray crosses before its hit, and the
//! walk's loop costs the slice shader occupancy on every fragment (H100:
//! 11.56 ms a frame against 8.09 without the walks). One walk per pixel, from
//! its tile's beam start where the adapter has compute
//! (`methods::march_beam`), covers every gap of the ray, long ones included.

use super::super::common::fullscreen_pipeline_depth_tested;
use super::super::contract::Frame;
use super::super::march_beam::MarchBeam;
use super::tiles::SliceTiles;
use crate::frame::{Shared, texture_entry, uniform_layout_entry};
use strata_level::{DirtyRect, Level};

pub struct Gaps {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    /// The tiles' starts (none without compute or fragment storage).
    beam: Option<MarchBeam>,
}

impl Gaps {
    pub fn new(
        shared: &Shared,
        level: &Level,
        params: &wgpu::Buffer,
        tiles: &SliceTiles,
    ) -> anyhow::Result<Self> {
        let beam = if MarchBeam::available(shared, level) {
            Some(MarchBeam::new(shared, level, "sliced gaps beam")?)
        } else {
            None
        };
        let mut entries = vec![
            uniform_layout_entry(0),
            uniform_layout_entry(1),
            texture_entry(
                3,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2,
            ),
        ];
        if beam.is_some() {
            entries.push(MarchBeam::layout_entry());
        }
        let layout = shared
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sliced gaps"),
                entries: &entries,
            });
        let (shader, entry) = if beam.is_some() {
            ("sliced_gaps_beam.wgsl", "fs_sliced_gaps_beam")
        } else {
            ("sliced_gaps.wgsl", "fs_sliced_gaps")
        };
        let pipeline = fullscreen_pipeline_depth_tested(
            shared,
            "sliced gaps",
            shader,
            &shared.pipeline_layout("sliced gaps", &[&layout]),
            entry,
        )?;
        let group = Self::group(shared, &layout, params, tiles, beam.as_ref());
        Ok(Gaps {
            layout,
            pipeline,
            group,
            beam,
        })
    }

    fn group(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        tiles: &SliceTiles,
        beam: Option<&MarchBeam>,
    ) -> wgpu::BindGroup {
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: tiles.params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(tiles.blocks_view()),
            },
        ];
        entries.extend(beam.map(MarchBeam::binding));
        shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sliced gaps"),
            layout,
            entries: &entries,
        })
    }

    /// Queue an edit's rectangles for the beam's pyramid.
    pub fn apply_edit(&mut self, rects: &[DirtyRect]) {
        if let Some(beam) = &mut self.beam {
            beam.enqueue(rects);
        }
    }

    /// This frame's pyramid updates (run by [`Gaps::record_beam`]).
    pub fn prepare(&mut self, shared: &Shared) {
        if let Some(beam) = &mut self.beam {
            beam.prepare(shared);
        }
    }

    /// Starts for the targets' new size.
    pub fn resize(&mut self, shared: &Shared, params: &wgpu::Buffer, tiles: &SliceTiles) {
        if let Some(beam) = &mut self.beam {
            beam.resize(shared);
        }
        self.group = Self::group(shared, &self.layout, params, tiles, self.beam.as_ref());
    }

    /// Before the slices' render pass: the pyramid's update on every frame
    /// that has one (a frame without walking rows that dropped it would
    /// leave the pyramid behind the edits; one that kept it queued would
    /// let the queue grow for as long as the view stays steep), and the
    /// beam pass where the frame `walks`.
    pub fn record_beam(
        &self,
        shared: &Shared,
        frame: &Frame<'_>,
        encoder: &mut wgpu::CommandEncoder,
        walks: bool,
    ) {
        if let Some(beam) = &self.beam {
            beam.record_pyramid_update(frame, encoder);
            if walks {
                beam.record_beam(shared, frame, encoder);
            }
        }
    }

    /// The walk over `rows` (a band of the target's rows), in the slices'
    /// pass after the slices.
    pub fn draw(
        &self,
        shared: &Shared,
        pass: &mut wgpu::RenderPass<'_>,
        rows: std::ops::Range<u32>,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(1, &self.group, &[]);
        pass.set_scissor_rect(0, rows.start, shared.width, rows.end - rows.start);
        pass.draw(0..3, 0..1);
    }

    pub fn gpu_bytes(&self) -> u64 {
        self.beam.as_ref().map_or(0, MarchBeam::gpu_bytes)
    }
}
