//! A program to copy from: Strata's terrain in your own renderer, with your
//! own object composing by depth and colliding with the same terrain.
//!
//! ```text
//! cargo run -p strata-render --example drive -- [METHOD] [--frames N] [--out DIR]
//! ```
//!
//! It builds a small level (flat ground, a slab bridging the road), opens a
//! device of its own and hands it to Strata (`Gpu::from_device`), digs a
//! crater at start (`Renderer::apply_edit`, which also refits the terrain
//! collider through the edit listener), then drives a vehicle-sized box with
//! its own pipeline and vertex buffer along the road: under the slab and
//! through the crater, its height from collider ray casts. Each frame is
//! written as a PNG; the line per frame says whether the vehicle's centre
//! pixel shows the vehicle or the terrain in front of it. Headless (no
//! window): present `shared().color_view` to your surface the same way.

use glam::Vec3;
use std::sync::{Arc, Mutex};
use strata_camera::Camera;
use strata_collide::TerrainCollider;
use strata_level::edit::{EditRect, crater, edit_columns};
use strata_level::{Column, EditSite, Level};
use strata_render::{
    AdapterChoice, COLOR_FORMAT, DEPTH_FORMAT, Gpu, MethodSettings, Renderer, TerrainColors,
};
use wgpu::util::DeviceExt;

const W: u32 = 320;
const H: u32 = 200;
const ROAD_Y: f64 = 128.0;
/// Vehicle half extents: 4 x 2 x 1 units.
const HALF: Vec3 = Vec3::new(2.0, 1.0, 0.75);

const SHADER: &str = "
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) shade: f32 }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) shade: f32) -> Out {
    return Out(view_proj * vec4<f32>(p, 1.0), shade);
}
@fragment fn fs(in: Out) -> @location(0) vec4<f32> {
    return vec4<f32>(vec3<f32>(1.0, 0.157, 0.157) * in.shade, 1.0);
}
";

/// Flat ground at 40 with a slab (cave 40..70, top 80) across the road.
fn build_level() -> anyhow::Result<Level> {
    let mut level = Level::flat(256, 256, 40, 1)?;
    let bridge = EditRect {
        x: 100,
        y: 96,
        width: 32,
        height: 64,
    };
    edit_columns(&mut level, bridge, |_, _, c| Column {
        mid: 70,
        high: 80,
        dual: true,
        upper_type: 5,
        ..c
    });
    Ok(level)
}

/// The caller's own object: a box with its own pipeline and vertex buffer.
struct Vehicle {
    pipeline: wgpu::RenderPipeline,
    vertices: wgpu::Buffer,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl Vehicle {
    fn new(device: &wgpu::Device) -> Self {
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
        let vertices = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vehicle vertices"),
            size: 36 * 16,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vehicle view_proj"),
            contents: &[0u8; 64],
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
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

    /// Draw the box centred at `c` into the renderer's targets, after its frame.
    fn draw(&self, renderer: &Renderer, camera: &Camera, c: Vec3) {
        let s = renderer.shared();
        let mut data: Vec<f32> = Vec::with_capacity(36 * 4);
        // Six faces, two triangles each; a fixed shade per face.
        let faces: [(Vec3, Vec3, Vec3, f32); 6] = [
            (Vec3::Z, Vec3::X, Vec3::Y, 1.0),
            (-Vec3::Z, Vec3::Y, Vec3::X, 0.4),
            (Vec3::X, Vec3::Y, Vec3::Z, 0.8),
            (-Vec3::X, Vec3::Z, Vec3::Y, 0.7),
            (Vec3::Y, Vec3::Z, Vec3::X, 0.6),
            (-Vec3::Y, Vec3::X, Vec3::Z, 0.9),
        ];
        for (n, u, v, shade) in faces {
            let corner = |a: f32, b: f32| c + (n + u * a + v * b) * HALF;
            for (a, b) in [
                (-1., -1.),
                (1., -1.),
                (1., 1.),
                (-1., -1.),
                (1., 1.),
                (-1., 1.),
            ] {
                data.extend(corner(a, b).to_array());
                data.push(shade);
            }
        }
        s.queue
            .write_buffer(&self.vertices, 0, bytemuck::cast_slice(&data));
        s.queue.write_buffer(
            &self.uniform,
            0,
            bytemuck::cast_slice(&camera.view_proj().to_cols_array()),
        );
        let mut encoder = s.device.create_command_encoder(&Default::default());
        {
            let load = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("vehicle"),
                color_attachments: &[load(&s.color_view)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &s.depth_view,
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
        s.queue.submit([encoder.finish()]);
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut method, mut frames, mut out) = ("mesh".to_string(), 6u32, None);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--frames" => frames = args.next().unwrap_or_default().parse()?,
            "--out" => out = args.next().map(std::path::PathBuf::from),
            m if !m.starts_with('-') => method = m.to_string(),
            other => anyhow::bail!("unknown argument {other:?}"),
        }
    }
    let mut level = build_level()?;

    // Your device and queue, handed to Strata.
    let instance = AdapterChoice::default().instance();
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("my engine"),
        required_features: adapter.features(),
        required_limits: adapter.limits(),
        ..Default::default()
    }))?;
    let gpu = Gpu::from_device(instance, adapter, device, queue)?;
    let settings = MethodSettings::default();
    let colors = TerrainColors::test_ramps();
    let mut renderer = Renderer::new(&gpu, &level, &colors, &method, &settings, W, H)?;

    // The collider follows every edit the renderer applies.
    let tolerance = strata_mesh::tolerance_for_quality(f64::from(settings.mesh_quality))
        .expect("the default quality is in range");
    let collider = Arc::new(Mutex::new(TerrainCollider::fit(&level, tolerance)));
    let follower = collider.clone();
    renderer.set_edit_listener(Some(Box::new(move |level, rects| {
        follower.lock().unwrap().apply_edit(level, rects);
    })));

    // Dig a crater in the road at start.
    let mut site = EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) = (180, ROAD_Y as i64, 18, 20.0);
    let dirty = crater(&mut level, &site);
    renderer.apply_edit(&level, &dirty)?;

    // Looking along the road from the side, above.
    let camera = Camera::new(Vec3::new(135.0, -40.0, 190.0), 0.0, -45.0, W, H)?;
    let vehicle = Vehicle::new(&gpu.device);
    if let Some(dir) = &out {
        std::fs::create_dir_all(dir)?;
    }
    let mut z = 60.0f64;
    for f in 0..frames {
        let x = 60.0 + 150.0 * f64::from(f) / f64::from(frames.max(2) - 1);
        // The ground under the vehicle: cast down from just above its
        // current height (out of a crater; under the slab, whose
        // ceiling is 30 above the road, it finds the cave floor).
        let ground = collider
            .lock()
            .unwrap()
            .cast_ray([x, ROAD_Y, z + 20.0], [0.0, 0.0, -1.0], 400.0)
            .map_or(0.0, |h| h.point[2]);
        z = ground + f64::from(HALF.z);
        let centre = Vec3::new(x as f32, ROAD_Y as f32, z as f32);
        renderer.render_frame(&camera)?;
        vehicle.draw(&renderer, &camera, centre);
        let rgba = renderer.read_color()?;
        let on_screen = camera
            .project(centre)
            .filter(|p| p.x >= 0.0 && p.y >= 0.0 && p.x < W as f32 && p.y < H as f32);
        let seen = on_screen.map(|p| {
            let k = ((p.y as u32 * W + p.x as u32) * 4) as usize;
            rgba[k] > 100 && rgba[k + 1] < 80 && rgba[k + 2] < 80
        });
        println!(
            "frame {f}: vehicle at ({x:.0}, {ROAD_Y}, {z:.1}) on ground {ground:.1}: {}",
            match seen {
                Some(true) => "visible",
                Some(false) => "hidden by terrain",
                None => "off screen",
            }
        );
        if let Some(dir) = &out {
            let path = dir.join(format!("drive-{method}-{f:02}.png"));
            image::save_buffer(&path, &rgba, W, H, image::ExtendedColorType::Rgba8)?;
        }
    }
    Ok(())
}
