//! The shared 1024² shadow map: a directional light's depth map over the
//! camera's footprint, rendered once per frame by the ray-march core
//! (`shaders/shadow.wgsl`) before the method's passes, and sampled with 4-tap
//! PCF by `shading.wgsl`.

use crate::caps::{Capability, ShadowPassKind};
use crate::frame::{SHADOW_SIZE, Shared, storage_texture_entry};
use glam::Vec3;
use strata_camera::Camera;

/// Direction the sunlight travels (down and across the map).
pub fn light_direction() -> Vec3 {
    Vec3::new(0.45, 0.3, -0.84).normalize()
}

/// Where this frame's shadow map lies: a square on a plane perpendicular to
/// the light, far enough up the light that all terrain lies in front of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowFrame {
    pub enabled: bool,
    pub light: Vec3,
    /// Corner of the map's square (texel (0, 0)'s outer corner).
    pub origin: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    /// World units per texel.
    pub texel: f32,
    /// Depth bias, world units: how far behind the blocker a point must be to be in shadow.
    pub bias: f32,
}

impl ShadowFrame {
    /// Fit the map to the part of the view frustum inside the altitude slab
    /// [0, 255]: the eye and the corner rays, each clipped to the slab and
    /// the far plane, projected onto the light's plane.
    pub fn fit(camera: &Camera, enabled: bool) -> Self {
        let light = light_direction();
        let u = light.cross(Vec3::Z).normalize();
        let v = light.cross(u).normalize();
        let (w, h) = (camera.width as f32, camera.height as f32);
        let mut points = vec![camera.position];
        for (px, py) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h), (0.5 * w, 0.5 * h)] {
            let d = camera.image_direction(px, py);
            // View depth is t * focal along the unnormalised direction.
            let t_far = camera.far / camera.focal_px;
            let (mut t0, mut t1) = (0.0f32, t_far);
            if d.z.abs() > 1e-9 {
                let ta = -camera.position.z / d.z;
                let tb = (255.0 - camera.position.z) / d.z;
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
            if t0 <= t1 {
                points.push(camera.position + d * t0);
                points.push(camera.position + d * t1);
            }
        }
        // The footprint on the ground below the eye matters too (shadows cast
        // onto what the corner rays reach come from terrain between them).
        points.push(Vec3::new(camera.position.x, camera.position.y, 0.0));
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
        for p in &points {
            let q = glam::Vec2::new(p.dot(u), p.dot(v));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        // A margin for casters just outside the footprint; a square map.
        let side = (hi - lo).max_element() + 32.0;
        let centre = 0.5 * (lo + hi);
        let texel = side / SHADOW_SIZE as f32;
        // Put the plane well above every altitude: 600 units up the light.
        let along = points.iter().map(|p| p.dot(light)).fold(f32::MAX, f32::min) - 600.0;
        let origin = u * (centre.x - 0.5 * side) + v * (centre.y - 0.5 * side) + light * along;
        ShadowFrame {
            enabled,
            light,
            origin,
            u,
            v,
            texel,
            // With the normal offset in `shading.wgsl`, a texel plus half a
            // unit (the march's bisection error) keeps lit surfaces lit.
            bias: texel + 0.5,
        }
    }
}

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
                let out_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadow out"),
                    layout: &out_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&shared.shadow_view),
                    }],
                });
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
