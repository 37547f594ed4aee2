//! Drawing the physics toy's bodies: one small instanced pipeline of the
//! viewer's own (a unit sphere and a unit cube, a matrix and colour per
//! body) drawn into the renderer's colour and depth after a method's frame,
//! so the bodies compose with the terrain by the ordinary depth test in
//! every method (the renderer's documented embedding contract).

use glam::{Mat4, Quat, Vec3};
use strata_physics::{BodyPose, BodyShape};
use strata_render::{COLOR_FORMAT, DEPTH_FORMAT, Shared};
use wgpu::util::DeviceExt;

const SHADER: &str = "
struct Frame { view_proj: mat4x4<f32>, light: vec4<f32> }
@group(0) @binding(0) var<uniform> frame: Frame;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) normal: vec3<f32>, @location(1) color: vec3<f32> }
@vertex fn vs(
    @location(0) p: vec3<f32>, @location(1) n: vec3<f32>,
    @location(2) m0: vec4<f32>, @location(3) m1: vec4<f32>, @location(4) m2: vec4<f32>,
    @location(5) m3: vec4<f32>, @location(6) color: vec4<f32>,
) -> Out {
    let m = mat4x4<f32>(m0, m1, m2, m3);
    // Scales are along the body's own axes, where the unit meshes' normals
    // are axis-aligned (cube) or radial (sphere, uniform scale): m * n keeps
    // their direction.
    return Out(frame.view_proj * m * vec4<f32>(p, 1.0), (m * vec4<f32>(n, 0.0)).xyz, color.rgb);
}
@fragment fn fs(in: Out) -> @location(0) vec4<f32> {
    let lit = 0.35 + 0.65 * max(dot(normalize(in.normal), frame.light.xyz), 0.0);
    return vec4<f32>(in.color * lit, 1.0);
}
";

/// Per-body instance data: model matrix columns, then colour.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Instance {
    model: [[f32; 4]; 4],
    color: [f32; 4],
}

const SPHERE_COLOR: [f32; 4] = [1.0, 0.55, 0.1, 1.0];
const BOX_COLOR: [f32; 4] = [0.2, 0.8, 1.0, 1.0];
/// Bodies at rest are drawn a little darker.
const ASLEEP: f32 = 0.7;

/// (position, normal) vertices and triangle indices.
type Mesh = (Vec<[f32; 6]>, Vec<u16>);

/// A UV sphere of radius 1.
fn sphere() -> Mesh {
    let (rings, segments) = (10u16, 16u16);
    let mut vertices = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * f32::from(r) / f32::from(rings);
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * f32::from(s) / f32::from(segments);
            let n = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            vertices.push([n[0], n[1], n[2], n[0], n[1], n[2]]);
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    (vertices, indices)
}

/// A cube from -1 to 1, flat normals.
fn cube() -> Mesh {
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for (n, u, v) in [
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
    ] {
        let base = vertices.len() as u16;
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let p = n + u * a + v * b;
            vertices.push([p.x, p.y, p.z, n.x, n.y, n.z]);
        }
        indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (vertices, indices)
}

struct Uploaded {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

fn upload(device: &wgpu::Device, (vertices, indices): Mesh, name: &str) -> Uploaded {
    let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(name),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let count = indices.len() as u32;
    let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(name),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    Uploaded {
        vertices,
        indices,
        count,
    }
}

/// The bodies' pipeline, meshes and buffers.
pub struct BodyPainter {
    pipeline: wgpu::RenderPipeline,
    sphere: Uploaded,
    cube: Uploaded,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    instances: wgpu::Buffer,
    capacity: usize,
}

impl BodyPainter {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bodies"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("bodies"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 24,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: size_of::<Instance>() as u64,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes: &wgpu::vertex_attr_array![
                            2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4,
                            6 => Float32x4
                        ],
                    }),
                ],
            },
            // No culling: the depth test alone orders convex shapes, whatever
            // the projection's handedness.
            primitive: wgpu::PrimitiveState::default(),
            // The terrain's depth convention: 0 near .. 1 far, `Less`.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
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
                targets: &[Some(COLOR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bodies frame"),
            size: 80,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = strata_render::frame::bind_group(
            device,
            "bodies",
            &pipeline.get_bind_group_layout(0),
            &[uniform.as_entire_binding()],
        );
        let capacity = 64;
        BodyPainter {
            pipeline,
            sphere: upload(device, sphere(), "body sphere"),
            cube: upload(device, cube(), "body cube"),
            uniform,
            group,
            instances: instance_buffer(device, capacity),
            capacity,
        }
    }

    /// Draw `bodies` into `shared`'s colour and depth, seen by `view_proj`
    /// from `eye`. The map is a torus: each body is drawn at its copy
    /// nearest the eye (`size`: the map's width and height).
    pub fn draw(
        &mut self,
        shared: &Shared,
        view_proj: Mat4,
        eye: Vec3,
        size: [f32; 2],
        bodies: &[BodyPose],
    ) {
        if bodies.is_empty() {
            return;
        }
        let (device, queue) = (&shared.device, &shared.queue);
        let nearest = |v: f32, e: f32, n: f32| v + ((e - v) / n).round() * n;
        // Spheres first, then boxes: one instanced draw each.
        let mut instances: Vec<Instance> = Vec::with_capacity(bodies.len());
        let mut spheres = 0u32;
        for sphere_pass in [true, false] {
            for b in bodies {
                let (scale, color) = match b.shape {
                    BodyShape::Sphere { radius } if sphere_pass => {
                        (Vec3::splat(radius), SPHERE_COLOR)
                    }
                    BodyShape::Box { half_extents } if !sphere_pass => {
                        (Vec3::from(half_extents), BOX_COLOR)
                    }
                    _ => continue,
                };
                let p = Vec3::new(
                    nearest(b.position[0], eye.x, size[0]),
                    nearest(b.position[1], eye.y, size[1]),
                    b.position[2],
                );
                let model = Mat4::from_scale_rotation_translation(
                    scale,
                    Quat::from_array(b.rotation).normalize(),
                    p,
                );
                let shade = if b.sleeping { ASLEEP } else { 1.0 };
                instances.push(Instance {
                    model: model.to_cols_array_2d(),
                    color: [color[0] * shade, color[1] * shade, color[2] * shade, 1.0],
                });
            }
            if sphere_pass {
                spheres = instances.len() as u32;
            }
        }
        if instances.len() > self.capacity {
            self.capacity = instances.len().next_power_of_two();
            self.instances = instance_buffer(device, self.capacity);
        }
        queue.write_buffer(&self.instances, 0, bytemuck::cast_slice(&instances));
        let light = Vec3::new(0.4, 0.3, 0.85).normalize();
        let mut frame = view_proj.to_cols_array().to_vec();
        frame.extend([light.x, light.y, light.z, 0.0]);
        queue.write_buffer(&self.uniform, 0, bytemuck::cast_slice(&frame));

        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("bodies"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &shared.color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &shared.depth_view,
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
            pass.set_vertex_buffer(1, self.instances.slice(..));
            let total = instances.len() as u32;
            for (mesh, range) in [(&self.sphere, 0..spheres), (&self.cube, spheres..total)] {
                if range.is_empty() {
                    continue;
                }
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint16);
                pass.draw_indexed(0..mesh.count, 0, range);
            }
        }
        queue.submit([encoder.finish()]);
    }
}

fn instance_buffer(device: &wgpu::Device, capacity: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("body instances"),
        size: (capacity * size_of::<Instance>()) as u64,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
