//! `painted` (§3.4): every ground sample of the camera's footprint becomes a
//! bar [0, low] and, for a dual column, a bar [mid, high]. One instanced draw,
//! no vertex buffer: the vertex shader derives each corner from the instance
//! index (the sample, front to back: `forward.wgsl`) and the vertex index
//! (bar, face, corner), and emits only the faces that face the eye. The draw
//! is indexed over the seven corners of a bar's visible faces: 14 vertex
//! shader runs per sample, not 36. A side face starts above the neighbour
//! column's solid it touches, so the hidden part of every wall is not
//! rasterised (`bench/painted-indexed/`: 2.9x faster on the H200).

use super::common::{begin_pass, forward_pipeline, index_buffer, uniform_binding};
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use super::forward::{self, FootprintParams};
use super::knobs::Sweep;
use crate::frame::Shared;
use strata_camera::Camera;
use strata_level::Level;

/// The indices of one sample: two bars of three faces of two triangles. A
/// bar's seven vertices are the corner its visible faces share (0) and the
/// six around it (1..=6, see `painted.wgsl`); each face is two triangles
/// fanned from the shared corner over three consecutive ring corners.
const BAR_INDICES: [u16; 36] = {
    let mut out = [0u16; 36];
    let mut i = 0;
    while i < 36 {
        let (bar, k) = (i / 18, i % 18);
        // Triangle k / 3 of the bar: (0, j, j + 1) with j = 1..=6, wrapping.
        let j = k / 3 + 1;
        let corner = match k % 3 {
            0 => 0,
            1 => j,
            _ => j % 6 + 1,
        };
        out[i] = (bar * 7 + corner) as u16;
        i += 1;
    }
    out
};

pub struct Painted {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    /// [`BAR_INDICES`].
    indices: wgpu::Buffer,
    /// Samples the next `record` draws (written by `prepare`).
    samples: u32,
}

/// The footprint uniform, its bind group layout and group.
fn footprint_binding(
    shared: &Shared,
    label: &str,
) -> (wgpu::Buffer, wgpu::BindGroupLayout, wgpu::BindGroup) {
    let params = shared.uniform_buffer(label, bytemuck::bytes_of(&FootprintParams::default()));
    let (layout, group) = uniform_binding(shared, label, &params);
    (params, layout, group)
}

pub fn create(
    shared: &Shared,
    _level: &Level,
    _settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let (params, layout, group) = footprint_binding(shared, "painted");
    let pipeline = forward_pipeline(
        shared,
        "painted",
        "painted.wgsl",
        &layout,
        ("vs_painted", "fs_painted"),
    )?;
    let indices = index_buffer(shared, "painted indices", &BAR_INDICES);
    Ok(Box::new(Painted {
        pipeline,
        group,
        params,
        indices,
        samples: 0,
    }))
}

impl Method for Painted {
    fn name(&self) -> &'static str {
        "painted"
    }

    fn update_settings(&mut self, _: &Shared, _: &MethodSettings) -> anyhow::Result<bool> {
        // Painted has no setting of its own.
        Ok(true)
    }

    fn prepare(&mut self, shared: &Shared, camera: &Camera) -> anyhow::Result<()> {
        let f = forward::footprint(camera, Some("painted"));
        self.samples = f.count[0];
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&f));
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = begin_pass(shared, frame, encoder, "painted");
        if self.samples == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint16);
        pass.draw_indexed(0..BAR_INDICES.len() as u32, 0, 0..self.samples);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The 48-byte footprint uniform and 72 bytes of indices; no
        // per-column geometry.
        RetainedBytes {
            gpu: forward::PARAMS_BYTES + std::mem::size_of_val(&BAR_INDICES) as u64,
            cpu: 0,
        }
    }
}

/// `strata tune` measures it at its one setting.
pub static SWEEP: Sweep = Sweep {
    order: 5,
    knob: "none",
    full: &[],
    quick: &[],
    at_paper_size: false,
};
