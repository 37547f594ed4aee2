//! `sliced:N/refine` (issue 16, item 5): the plain slices find, per pixel,
//! the nearest slice whose point on the pixel's ray is solid, and one
//! full-screen pass then finds the exact surface crossing on that ray up to
//! the slice point (`shaders/sliced_refine.wgsl`); the surface, not the slice
//! plane, writes depth and colour.
//!
//! Why two passes: refining inside the slice fragment writes `frag_depth`,
//! which turns early depth testing off, so every fragment of every slice ran
//! the search and most were overwritten (8x the plain slicer on the H100).
//! Here the slice pass keeps early depth (no depth writes from the shader, no
//! shading) and writes only the winning slice's rank into a private R32Uint
//! image; the search runs once per covered pixel.

use super::super::common::{draw_fullscreen_with_depth, fullscreen_pipeline};
use super::super::contract::MethodSettings;
use super::super::contract::{Frame, RetainedBytes};
use super::super::march_beam::MarchBeam;
use super::tiles::SliceTiles;
use super::{walk_beam, walk_group, walk_layout};
use crate::frame::Shared;
use strata_level::{DirtyRect, Level};

/// The marks' binding in the refine pass's group (`slice_marks`).
const MARKS_BINDING: u32 = 4;

/// Format of the slice marks: rank + 1 of the kept slice, 0 = none. An
/// integer format renders everywhere (WebGL2 included), unlike R32Float.
pub const MARK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// The marks image and the refine pass that reads it.
pub struct Refine {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    marks: Marks,
    /// The tiles' starts the search begins at (none without compute or
    /// fragment storage: from the near plane).
    beam: Option<MarchBeam>,
}

/// The marks image at the shared targets' size, and the refine pass's group.
struct Marks {
    view: wgpu::TextureView,
    group: wgpu::BindGroup,
    bytes: u64,
}

impl Marks {
    fn new(
        shared: &Shared,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        tiles: &SliceTiles,
        beam: Option<&MarchBeam>,
    ) -> Self {
        let (_, view) = shared.target_texture(
            "sliced marks",
            MARK_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let group = walk_group(
            &shared.device,
            ("sliced refine", layout),
            (params, tiles),
            beam,
            &[(MARKS_BINDING, &view)],
        );
        Marks {
            view,
            group,
            bytes: u64::from(shared.width) * u64::from(shared.height) * 4,
        }
    }
}

impl Refine {
    /// `params`: the slicer's footprint uniform (slice count, gap walks);
    /// `tiles`: its block maxima, which let the search step over air; the
    /// search begins at its tile's beam start where the adapter runs the
    /// beam (`methods::march_beam`).
    pub fn new(
        shared: &Shared,
        level: &Level,
        settings: &MethodSettings,
        params: &wgpu::Buffer,
        tiles: &SliceTiles,
    ) -> anyhow::Result<Self> {
        let beam = walk_beam(shared, level, settings, "sliced refine beam")?;
        let layout = walk_layout(
            &shared.device,
            "sliced refine",
            beam.is_some(),
            &[MARKS_BINDING],
        );
        let (shader, entry) = if beam.is_some() {
            ("sliced_refine_beam.wgsl", "fs_sliced_refine_beam")
        } else {
            ("sliced_refine.wgsl", "fs_sliced_refine")
        };
        let pipeline = fullscreen_pipeline(
            shared,
            "sliced refine",
            shader,
            &shared.pipeline_layout("sliced refine", &[&layout]),
            entry,
        )?;
        let marks = Marks::new(shared, &layout, params, tiles, beam.as_ref());
        Ok(Refine {
            layout,
            pipeline,
            marks,
            beam,
        })
    }

    /// A marks image (and beam starts) at the shared targets' new size.
    pub fn resize(&mut self, shared: &Shared, params: &wgpu::Buffer, tiles: &SliceTiles) {
        if let Some(beam) = &mut self.beam {
            beam.resize(shared);
        }
        self.marks = Marks::new(shared, &self.layout, params, tiles, self.beam.as_ref());
    }

    /// Queue an edit's rectangles for the beam's pyramid.
    pub fn apply_edit(&mut self, rects: &[DirtyRect]) {
        if let Some(beam) = &mut self.beam {
            beam.enqueue(rects);
        }
    }

    /// This frame's pyramid updates (run by [`Refine::record`]).
    pub fn prepare(&mut self, shared: &Shared) {
        if let Some(beam) = &mut self.beam {
            beam.prepare(shared);
        }
    }

    /// The slice pass's colour target: the marks, cleared to 0 (no slice).
    pub fn marks_attachment(&self) -> wgpu::RenderPassColorAttachment<'_> {
        wgpu::RenderPassColorAttachment {
            view: &self.marks.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        }
    }

    /// Record the refine pass: sky where no slice was kept (colour cleared,
    /// the slice pass's depth kept), the exact crossing elsewhere.
    pub fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if let Some(beam) = &self.beam {
            beam.record(shared, frame, encoder);
        }
        // Sky where no slice was kept; the slice pass's depth stays.
        draw_fullscreen_with_depth(
            shared,
            frame,
            encoder,
            "sliced refine",
            &self.pipeline,
            &self.marks.group,
            wgpu::LoadOp::Load,
        );
    }

    /// The marks image (4 bytes a pixel) and the beam.
    pub fn retained_bytes(&self) -> RetainedBytes {
        RetainedBytes {
            gpu: self.marks.bytes + self.beam.as_ref().map_or(0, MarchBeam::gpu_bytes),
            cpu: 0,
        }
    }
}
