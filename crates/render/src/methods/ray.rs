//! `ray`: the paper's height-field march (§3.1) as one full-screen fragment
//! pass over the shared WGSL core (`ray_core.wgsl::ray_pixel`). A ray takes
//! `ray_steps` uniform samples, one column decode each; a step is flagged for
//! the exact walk when the ray's piece of it in the column under either of
//! its samples meets that column's floor or slab (`ray_core.wgsl::march`),
//! where the paper tests only the sample point.
//!
//! Where the adapter runs compute and lets fragments read storage, each ray
//! begins at the last of its samples before its 8x8-pixel tile's beam
//! (`methods/march_beam.rs`), and a rising ray ends above the map's highest
//! top: the same samples, fewer of them (issue 36 item 2; `ray:N/nobeam`
//! marches as before).

use super::common::{draw_fullscreen, fullscreen_pipeline};
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use super::knobs::{Flag, Knobs, Slider, Sweep, count, plain};
use super::march_beam::{
    MarchBeam, NO_BEAM_FLAG, highest_top, highest_top_in, nobeam_tag, split_nobeam,
};
use crate::frame::{Shared, uniform_layout_entry};
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};

pub struct Ray {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    /// The tiles' starts (none: `/nobeam`, or no compute / fragment storage).
    beam: Option<MarchBeam>,
    /// The uniform's words: steps, the highest top (255: none).
    data: [u32; 4],
    /// `settings.march_beam` at creation (a change rebuilds).
    march_beam: bool,
}

/// Most forward samples a ray may take (`MAX_MARCH_STEPS` in `ray_core.wgsl`,
/// which clamps to it, so a bad uniform read cannot hang the GPU).
pub const MAX_RAY_STEPS: u32 = 16384;

/// Check `--ray-steps`: the method's uniform (`RayParams`).
fn ray_params_data(settings: &MethodSettings) -> anyhow::Result<[u32; 4]> {
    if settings.ray_steps == 0 || settings.ray_steps > MAX_RAY_STEPS {
        anyhow::bail!(
            "ray steps must be 1..={MAX_RAY_STEPS} (got {})",
            settings.ray_steps
        );
    }
    Ok([settings.ray_steps, 0, 0, 0])
}

/// Check `--ray-steps` and build the method's uniform (`RayParams`).
pub(crate) fn ray_params(
    shared: &Shared,
    settings: &MethodSettings,
) -> anyhow::Result<wgpu::Buffer> {
    let data = ray_params_data(settings)?;
    Ok(shared.uniform_buffer("ray params", bytemuck::cast_slice(&data)))
}

/// Rewrite the uniform for new settings (the steps are all it holds).
pub(crate) fn update_ray_params(
    shared: &Shared,
    params: &wgpu::Buffer,
    settings: &MethodSettings,
) -> anyhow::Result<bool> {
    let data = ray_params_data(settings)?;
    shared
        .queue
        .write_buffer(params, 0, bytemuck::cast_slice(&data));
    Ok(true)
}

/// The fragment's group: the uniform, and the starts with the beam.
fn ray_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    beam: Option<&MarchBeam>,
) -> wgpu::BindGroup {
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: params.as_entire_binding(),
    }];
    entries.extend(beam.map(MarchBeam::binding));
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray"),
        layout,
        entries: &entries,
    })
}

pub fn create(
    shared: &Shared,
    level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let mut data = ray_params_data(settings)?;
    // The highest top ends rising rays (255: the march as the paper's).
    data[1] = if settings.march_beam {
        highest_top(level)
    } else {
        255
    };
    let params = shared.uniform_buffer("ray params", bytemuck::cast_slice(&data));
    let beam = if settings.march_beam && MarchBeam::available(shared, level) {
        Some(MarchBeam::new(shared, level, "ray beam")?)
    } else {
        None
    };
    let mut entries = vec![uniform_layout_entry(0)];
    if beam.is_some() {
        entries.push(MarchBeam::layout_entry());
    }
    let layout = shared
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ray"),
            entries: &entries,
        });
    let group = ray_group(shared, &layout, &params, beam.as_ref());
    let (shader, entry) = if beam.is_some() {
        ("ray_beam.wgsl", "fs_ray_beam")
    } else {
        ("ray.wgsl", "fs_ray")
    };
    let pipeline = fullscreen_pipeline(
        shared,
        "ray",
        shader,
        &shared.pipeline_layout("ray", &[&layout]),
        entry,
    )?;
    Ok(Box::new(Ray {
        pipeline,
        params,
        layout,
        group,
        beam,
        data,
        march_beam: settings.march_beam,
    }))
}

impl Method for Ray {
    fn name(&self) -> &'static str {
        "ray"
    }

    fn apply_edit(
        &mut self,
        shared: &Shared,
        level: &Level,
        rects: &[DirtyRect],
    ) -> anyhow::Result<()> {
        if let Some(beam) = &mut self.beam {
            beam.enqueue(rects);
        }
        // An edit may raise the highest top (a lower one stays a bound).
        if self.data[1] < 255 {
            self.data[1] = self.data[1].max(highest_top_in(level, rects));
            shared
                .queue
                .write_buffer(&self.params, 0, bytemuck::cast_slice(&self.data));
        }
        Ok(())
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        let data = ray_params_data(settings)?;
        if settings.march_beam != self.march_beam {
            return Ok(false);
        }
        self.data[0] = data[0];
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::cast_slice(&self.data));
        Ok(true)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        if let Some(beam) = &mut self.beam {
            beam.resize(shared);
            self.group = ray_group(shared, &self.layout, &self.params, Some(beam));
        }
        Ok(())
    }

    fn prepare(&mut self, shared: &Shared, _camera: &Camera) -> anyhow::Result<()> {
        if let Some(beam) = &mut self.beam {
            beam.prepare(shared);
        }
        Ok(())
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        if let Some(beam) = &self.beam {
            beam.record(shared, frame, encoder);
        }
        draw_fullscreen(shared, frame, encoder, "ray", &self.pipeline, &self.group);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // One 16-byte uniform (the paper: no auxiliary storage), and the
        // beam's pyramid and starts.
        let beam = self.beam.as_ref().map_or(0, MarchBeam::gpu_bytes);
        RetainedBytes {
            gpu: 16 + beam,
            cpu: 0,
        }
    }
}

/// `ray:N` (`ray-compute` too): N forward samples per ray.
pub static KNOBS: Knobs = Knobs {
    grammar: "N or N/nobeam",
    default: Some("128"),
    parse: |text, s| {
        let (steps, beam) = split_nobeam(text);
        s.ray_steps = plain(count(steps))?;
        s.march_beam = beam;
        Ok(())
    },
    describe: |s| format!("steps={}{}", s.ray_steps, nobeam_tag(s)),
    keep: |from, to| {
        to.ray_steps = from.ray_steps;
        to.march_beam = from.march_beam;
    },
    sliders: &[Slider::count(
        "ray-steps",
        "ray steps",
        (8, 512),
        |s| s.ray_steps as f32,
        |s, v| s.ray_steps = v as u32,
    )],
    flags: &[
        Flag {
            long: "ray-steps",
            value: Some("N"),
            help: "`ray`, `ray-compute`: forward samples per ray.",
            default: |s| s.ray_steps.to_string(),
            apply: |text, s| {
                s.ray_steps = count(text)?;
                Ok(())
            },
        },
        NO_BEAM_FLAG,
    ],
};

/// `strata tune`'s sweep of the steps.
pub static SWEEP: Sweep = Sweep {
    order: 0,
    knob: "steps",
    full: &["16", "32", "64", "128", "256"],
    quick: &["16", "128", "256"],
    at_paper_size: false,
};
