//! The shared 1024² shadow map: a directional light's depth map over the
//! camera's footprint, rendered once per frame by the ray-march core
//! (`shaders/shadow.wgsl`) before the method's passes, and sampled with 4-tap
//! PCF by `shading.wgsl`.

use crate::caps::{Capability, ShadowPassKind};
use crate::frame::{SHADOW_SIZE, Shared, storage_texture_entry};
// The light and the map's frame live with the camera: the CPU colour
// reference casts the same map.
pub use strata_camera::light::{ShadowFrame, light_direction};

/// How the shadow map is filled: a compute pass writing it as a storage
/// texture, or (no compute: WebGL2) a full-screen fragment pass drawing it as
/// a render target. Both run `shadow_distance` of `shadow.wgsl`.
enum ShadowPipeline {
    Compute {
        pipeline: wgpu::ComputePipeline,
        out_group: wgpu::BindGroup,
    },
    Fragment(wgpu::RenderPipeline),
}

/// The pass that fills the shadow map.
pub struct ShadowPass {
    pipeline: ShadowPipeline,
    frame_group: wgpu::BindGroup,
    /// The map as a render target (the fragment pass).
    target: wgpu::TextureView,
}

impl ShadowPass {
    pub fn new(shared: &Shared) -> anyhow::Result<Self> {
        // Group 0 here omits the shadow map: it cannot be sampled and written
        // in the same pass.
        let device = &shared.device;
        let (frame_layout, frame_group) = frame_without_shadow_map(shared, "shadow frame");
        let module = shared.shader("shadow.wgsl")?;
        let kind = shared.caps.shadow_pass().ok_or_else(|| {
            anyhow::anyhow!(
                "the shadow map needs {} or {}, which this adapter lacks",
                Capability::ComputeShaders,
                Capability::Float32Targets
            )
        })?;
        let pipeline = match kind {
            ShadowPassKind::Compute => {
                let out_layout =
                    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some("shadow out"),
                        entries: &[storage_texture_entry(0, wgpu::TextureFormat::R32Float)],
                    });
                let out_group = crate::frame::bind_group(
                    device,
                    "shadow out",
                    &out_layout,
                    &[wgpu::BindingResource::TextureView(&shared.shadow_view)],
                );
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("shadow"),
                    bind_group_layouts: &[Some(&frame_layout), Some(&out_layout)],
                    immediate_size: 0,
                });
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("shadow"),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some("cs_shadow"),
                    compilation_options: Default::default(),
                    cache: None,
                });
                ShadowPipeline::Compute {
                    pipeline,
                    out_group,
                }
            }
            ShadowPassKind::Fragment => ShadowPipeline::Fragment(crate::fullscreen::pipeline(
                device,
                "shadow",
                &[&frame_layout],
                &module,
                ("vs_fullscreen", "fs_shadow"),
                wgpu::TextureFormat::R32Float,
            )),
        };
        Ok(ShadowPass {
            pipeline,
            frame_group,
            target: shared.shadow_view.clone(),
        })
    }

    /// Which kind of pass fills the map on this adapter.
    pub fn kind(&self) -> ShadowPassKind {
        match self.pipeline {
            ShadowPipeline::Compute { .. } => ShadowPassKind::Compute,
            ShadowPipeline::Fragment(_) => ShadowPassKind::Fragment,
        }
    }

    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timer: &crate::timing::PassTimer) {
        match &self.pipeline {
            ShadowPipeline::Compute {
                pipeline,
                out_group,
            } => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("shadow map"),
                    timestamp_writes: timer.compute("shadow"),
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &self.frame_group, &[]);
                pass.set_bind_group(1, out_group, &[]);
                pass.dispatch_workgroups(SHADOW_SIZE.div_ceil(8), SHADOW_SIZE.div_ceil(8), 1);
            }
            ShadowPipeline::Fragment(pipeline) => crate::fullscreen::draw(
                encoder,
                "shadow map",
                &self.target,
                pipeline,
                &[&self.frame_group],
                timer.render("shadow"),
            ),
        }
    }
}

/// Group 0 without the shadow map (globals and terrain only), for a pass
/// that writes the map: it cannot be sampled and written in the same pass.
pub(crate) fn frame_without_shadow_map(
    shared: &Shared,
    label: &str,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let layout = shared
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[
                crate::frame::uniform_layout_entry(0),
                crate::frame::texture_entry(
                    2,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D2Array,
                ),
            ],
        });
    let group = shared.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: shared.globals.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(&shared.terrain.view),
            },
        ],
    });
    (layout, group)
}
