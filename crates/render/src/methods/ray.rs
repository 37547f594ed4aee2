//! `ray`: the paper's height-field march (§3.1) as one full-screen fragment
//! pass over the shared WGSL core (`ray_core.wgsl::ray_pixel`). A ray takes
//! `ray_steps` uniform samples, one column decode each; a step is flagged for
//! the exact walk when the ray's piece of it in the column under either of
//! its samples meets that column's floor or slab (`ray_core.wgsl::march`),
//! where the paper tests only the sample point.

use super::common::{draw_fullscreen, fullscreen_pipeline, uniform_binding};
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use super::knobs::{Flag, Knobs, Slider, Sweep, count, plain};
use crate::frame::Shared;
use strata_level::Level;

pub struct Ray {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    group: wgpu::BindGroup,
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

pub fn create(
    shared: &Shared,
    _level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let params = ray_params(shared, settings)?;
    let (layout, group) = uniform_binding(shared, "ray", &params);
    let pipeline = fullscreen_pipeline(
        shared,
        "ray",
        "ray.wgsl",
        &shared.pipeline_layout("ray", &[&layout]),
        "fs_ray",
    )?;
    Ok(Box::new(Ray {
        pipeline,
        params,
        group,
    }))
}

impl Method for Ray {
    fn name(&self) -> &'static str {
        "ray"
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        update_ray_params(shared, &self.params, settings)
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        draw_fullscreen(shared, frame, encoder, "ray", &self.pipeline, &self.group);
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // One 16-byte uniform; no auxiliary storage (the paper: none).
        RetainedBytes { gpu: 16, cpu: 0 }
    }
}

/// `ray:N` (`ray-compute` too): N forward samples per ray.
pub static KNOBS: Knobs = Knobs {
    grammar: "N",
    default: Some("128"),
    parse: |text, s| {
        s.ray_steps = plain(count(text))?;
        Ok(())
    },
    describe: |s| format!("steps={}", s.ray_steps),
    keep: |from, to| to.ray_steps = from.ray_steps,
    sliders: &[Slider::count(
        "ray-steps",
        "ray steps",
        (8, 512),
        |s| s.ray_steps as f32,
        |s, v| s.ray_steps = v as u32,
    )],
    flags: &[Flag {
        long: "ray-steps",
        value: Some("N"),
        help: "`ray`, `ray-compute`: forward samples per ray.",
        default: |s| s.ray_steps.to_string(),
        apply: |text, s| {
            s.ray_steps = count(text)?;
            Ok(())
        },
    }],
};

/// `strata tune`'s sweep of the steps.
pub static SWEEP: Sweep = Sweep {
    order: 0,
    knob: "steps",
    full: &["16", "32", "64", "128", "256"],
    quick: &["16", "128", "256"],
    at_paper_size: false,
};
