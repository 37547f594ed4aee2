//! `ray-compute`: the `ray` march as a compute dispatch (one invocation per
//! pixel) over the same WGSL core. Colour goes straight into the shared colour
//! target through a storage view; depth goes into an R32Float storage texture
//! that a tiny full-screen pass copies into the shared depth target (a depth
//! texture can be neither a storage texture nor a copy destination from a
//! colour one). Both passes are timed; the copy is part of the method's cost.

use super::common::{DepthCopy, compute_pipeline, dispatch_per_pixel};
use super::contract::{Frame, Method, MethodSettings, RetainedBytes};
use super::ray::{ray_params, update_ray_params};
use crate::frame::{Shared, uniform_layout_entry};
use strata_level::Level;

pub struct RayCompute {
    march: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    march_layout: wgpu::BindGroupLayout,
    march_group: wgpu::BindGroup,
    depth: DepthCopy,
}

/// The march's outputs (shared colour, own depth image) and its parameters.
fn march_group(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    depth: &DepthCopy,
) -> wgpu::BindGroup {
    let [color_binding, depth_binding] = depth.bindings(shared, 1);
    shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ray-compute"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            color_binding,
            depth_binding,
        ],
    })
}

pub fn create(
    shared: &Shared,
    _level: &Level,
    settings: &MethodSettings,
) -> anyhow::Result<Box<dyn Method>> {
    let params = ray_params(shared, settings)?;
    let depth = DepthCopy::new(shared, "ray-compute", "depth blit")?;
    let [color_entry, depth_entry] = DepthCopy::layout_entries(1);
    let march_layout = shared
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ray-compute"),
            entries: &[uniform_layout_entry(0), color_entry, depth_entry],
        });
    let march_group = march_group(shared, &march_layout, &params, &depth);
    let march = compute_pipeline(
        shared,
        "ray-compute",
        "ray_compute.wgsl",
        &shared.pipeline_layout("ray-compute", &[&march_layout]),
        "cs_ray",
    )?;
    Ok(Box::new(RayCompute {
        march,
        params,
        march_layout,
        march_group,
        depth,
    }))
}

impl Method for RayCompute {
    fn name(&self) -> &'static str {
        "ray-compute"
    }

    fn update_settings(
        &mut self,
        shared: &Shared,
        settings: &MethodSettings,
    ) -> anyhow::Result<bool> {
        update_ray_params(shared, &self.params, settings)
    }

    fn resize(&mut self, shared: &Shared) -> anyhow::Result<()> {
        self.depth.resize(shared);
        self.march_group = march_group(shared, &self.march_layout, &self.params, &self.depth);
        Ok(())
    }

    fn draws_color_by_attachment(&self) -> bool {
        false
    }

    fn store_color_into(
        &mut self,
        shared: &Shared,
        view: Option<&wgpu::TextureView>,
    ) -> anyhow::Result<bool> {
        if self.depth.set_color_out(view) {
            self.march_group = march_group(shared, &self.march_layout, &self.params, &self.depth);
        }
        Ok(true)
    }

    fn record(&self, shared: &Shared, frame: &Frame<'_>, encoder: &mut wgpu::CommandEncoder) {
        dispatch_per_pixel(
            shared,
            frame,
            encoder,
            "ray-compute march",
            &self.march,
            &self.march_group,
        );
        self.depth
            .record(shared, frame, encoder, "ray-compute depth copy");
    }

    fn retained_bytes(&self) -> RetainedBytes {
        // The R32Float depth image plus the 16-byte uniform.
        RetainedBytes {
            gpu: self.depth.bytes() + 16,
            cpu: 0,
        }
    }

    fn depth_image(&self) -> Option<&wgpu::Texture> {
        Some(self.depth.texture())
    }
}
