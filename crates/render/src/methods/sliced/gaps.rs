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
//!
//! Where the deferred shading's compute pass can load the slices' depth and
//! the walks have their beam, it walks the same rays itself
//! (`shade.rs`, `sliced_shade_walk.wgsl`) and this pass draws nothing: on
//! the H100 this pass took 0.9-1.8 ms on the graphics path.

use super::super::common::fullscreen_pipeline_depth_tested;
use super::super::contract::Frame;
use super::super::contract::MethodSettings;
use super::super::march_beam::MarchBeam;
use super::tiles::SliceTiles;
use super::{walk_beam, walk_group, walk_layout};
use crate::frame::Shared;
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
        settings: &MethodSettings,
        params: &wgpu::Buffer,
        tiles: &SliceTiles,
    ) -> anyhow::Result<Self> {
        let beam = walk_beam(shared, level, settings, "sliced gaps beam")?;
        let layout = walk_layout(&shared.device, "sliced gaps", beam.is_some(), &[]);
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
        let group = walk_group(
            &shared.device,
            ("sliced gaps", &layout),
            (params, tiles),
            beam.as_ref(),
            &[],
        );
        Ok(Gaps {
            layout,
            pipeline,
            group,
            beam,
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
        self.group = walk_group(
            &shared.device,
            ("sliced gaps", &self.layout),
            (params, tiles),
            self.beam.as_ref(),
            &[],
        );
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

    /// The tiles' starts the walks begin at (none: from the near plane).
    pub fn beam(&self) -> Option<&MarchBeam> {
        self.beam.as_ref()
    }

    pub fn gpu_bytes(&self) -> u64 {
        self.beam.as_ref().map_or(0, MarchBeam::gpu_bytes)
    }
}
