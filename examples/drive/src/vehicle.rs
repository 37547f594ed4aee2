//! Your own object: a box with its own pipeline, vertex buffer and uniform,
//! drawn after Strata's terrain into the same colour and depth views, so the
//! terrain hides it by the ordinary depth test.

use crate::scene::VEHICLE_HALF;
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

const SHADER: &str = "
struct View { view_proj: mat4x4<f32>, centre: vec4<f32> }
@group(0) @binding(0) var<uniform> view: View;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) shade: f32 }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) shade: f32) -> Out {
    return Out(view.view_proj * vec4<f32>(p + view.centre.xyz, 1.0), shade);
}
@fragment fn fs(in: Out) -> @location(0) vec4<f32> {
    return vec4<f32>(vec3<f32>(1.0, 0.0, 1.0) * in.shade, 1.0);
}
";

/// Whether a pixel (RGBA or BGRA bytes) shows the vehicle: its magenta
/// (red and blue, no green) at any face shade.
pub fn is_vehicle_pixel(px: [u8; 3]) -> bool {
    px[1] == 0 && px[0] > 60 && px[2] > 60
}

/// The box: its pipeline for one pair of target formats, vertex buffer,
/// view uniform.
pub struct Vehicle {
    pipeline: wgpu::RenderPipeline,
    vertices: wgpu::Buffer,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl Vehicle {
    /// A vehicle drawn into `color` / `depth` format views of one sample.
    pub fn new(
        device: &wgpu::Device,
        color: wgpu::TextureFormat,
        depth: wgpu::TextureFormat,
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("vehicle"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vehicle"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 16,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32],
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
            // Strata's depth convention: 0 near .. 1 far under
            // `Camera::view_proj`, compare `Less`.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: depth,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(color.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vehicle vertices"),
            contents: bytemuck::cast_slice(&box_vertices()),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vehicle view"),
            size: 80,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vehicle"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        Vehicle {
            pipeline,
            vertices,
            uniform,
            group,
        }
    }

    /// Draw the box centred at `centre` over what the views hold (the
    /// terrain), testing and writing depth.
    pub fn draw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        view_proj: Mat4,
        centre: Vec3,
        color: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        let mut data = view_proj.to_cols_array().to_vec();
        data.extend(centre.extend(0.0).to_array());
        queue.write_buffer(&self.uniform, 0, bytemuck::cast_slice(&data));
        let load = wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        };
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("vehicle"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: color,
                    depth_slice: None,
                    resolve_target: None,
                    ops: load,
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.set_vertex_buffer(0, self.vertices.slice(..));
            pass.draw(0..36, 0..1);
        }
        queue.submit([encoder.finish()]);
    }
}

/// Six faces of two triangles around the origin, a fixed shade per face:
/// position (x, y, z) and shade per vertex.
fn box_vertices() -> Vec<[f32; 4]> {
    let faces: [(Vec3, Vec3, Vec3, f32); 6] = [
        (Vec3::Z, Vec3::X, Vec3::Y, 1.0),
        (-Vec3::Z, Vec3::Y, Vec3::X, 0.4),
        (Vec3::X, Vec3::Y, Vec3::Z, 0.8),
        (-Vec3::X, Vec3::Z, Vec3::Y, 0.7),
        (Vec3::Y, Vec3::Z, Vec3::X, 0.6),
        (-Vec3::Y, Vec3::X, Vec3::Z, 0.9),
    ];
    let mut out = Vec::with_capacity(36);
    for (n, u, v, shade) in faces {
        for (a, b) in [
            (-1., -1.),
            (1., -1.),
            (1., 1.),
            (-1., -1.),
            (1., 1.),
            (-1., 1.),
        ] {
            let p = (n + u * a + v * b) * VEHICLE_HALF;
            out.push([p.x, p.y, p.z, shade]);
        }
    }
    out
}
