//! Issue 18 (embedding): on the caller's own device and queue
//! (`Gpu::from_device`), after any method's frame, the caller's own
//! rasterised object, drawn with its own pipeline and vertex buffer into the
//! renderer's colour and depth targets (`COLOR_FORMAT`, `DEPTH_FORMAT`: depth
//! 0 near .. 1 far under `Camera::view_proj`, compare `Less`), composes with
//! the terrain by the ordinary depth test: in front of a slab it shows, under
//! it the slab's colour stays. Every method.

mod common;

use glam::Vec3;
use strata_camera::Camera;
use strata_render::{COLOR_FORMAT, DEPTH_FORMAT, MethodSettings, Renderer, TerrainColors};
use wgpu::util::DeviceExt;

const W: u32 = 96;
const H: u32 = 64;
const OBJECT: [u8; 3] = [255, 0, 255];

const SHADER: &str = "
@group(0) @binding(0) var<uniform> view_proj: mat4x4<f32>;
@vertex fn vs(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view_proj * vec4<f32>(p, 1.0);
}
@fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(1.0, 0.0, 1.0, 1.0); }
";

/// The caller's object: a small square facing the camera around world
/// point `centre`, `half` pixels wide, with its own pipeline and buffers.
fn draw_object(renderer: &Renderer, camera: &Camera, centre: Vec3, half: f32) {
    let s = renderer.shared();
    let vp = camera.view_proj();
    let b = camera.basis();
    // `half` pixels at the centre's view depth, in world units.
    let k = half * (centre - camera.position).dot(b.forward) / camera.focal_px;
    let (r, u) = (-b.right * k, b.up * k);
    let corner = |x: f32, y: f32| (centre + r * x + u * y).to_array();
    let quad = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    let d = &s.device;
    let vertices = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("object vertices"),
        contents: bytemuck::cast_slice(&quad),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("object view_proj"),
        contents: bytemuck::cast_slice(&vp.to_cols_array()),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("object"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("object"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
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
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("object"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    let mut encoder = d.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("object"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &s.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
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
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..6, 0..1);
    }
    s.queue.submit([encoder.finish()]);
}

fn pixel(color: &[u8], x: u32, y: u32) -> [u8; 3] {
    let k = ((y * W + x) * 4) as usize;
    [color[k], color[k + 1], color[k + 2]]
}

#[test]
fn callers_object_composes_by_depth_in_every_method() {
    // The caller's own device and queue, with every feature and limit its
    // adapter offers, handed to Strata (embedding).
    let instance = strata_render::AdapterChoice::default().instance();
    let Ok(adapter) = pollster::block_on(instance.request_adapter(&Default::default())) else {
        common::skip_loudly("no GPU adapter for the caller's device");
        return;
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("the caller's device"),
        required_features: adapter.features(),
        required_limits: adapter.limits(),
        ..Default::default()
    }))
    .expect("the caller's device");
    eprintln!("caller's adapter: {:?}", adapter.get_info().name);
    let gpu = strata_render::Gpu::from_device(instance, adapter, device, queue).unwrap();
    let level = common::synthetic_level();
    let view = common::synthetic_views()
        .into_iter()
        .find(|v| v.name == "bridge60")
        .unwrap();
    let camera = Camera::from_view(&level, &view, W, H).unwrap();
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    let mut tested = 0;
    for name in strata_render::methods::names() {
        let mut r = match Renderer::new(&gpu, &level, &colors, name, &settings, W, H) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name}: not on this adapter ({e:#})");
                continue;
            }
        };
        // The objects below are drawn over Strata's own depth target.
        r.set_depth_attachment(true);
        r.render_frame(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        let terrain = r.read_color().unwrap();
        // A pixel whose surface is a slab top, away from the image edge.
        let world = |x: u32, y: u32| {
            let d = depth[(y * W + x) as usize];
            let t = camera.depth_to_distance(x, y, d);
            (d, camera.position + camera.pixel_ray(x, y) * t)
        };
        let pick = (8..H - 8)
            .flat_map(|y| (8..W - 8).map(move |x| (x, y)))
            .find(|&(x, y)| {
                let (d, p) = world(x, y);
                let c = level.column(p.x.floor() as i64, p.y.floor() as i64);
                d < 1.0 && c.dual && (p.z - f32::from(c.high)).abs() < 1.5
            });
        let Some((x, y)) = pick else {
            panic!("{name}: no slab-top pixel in the bridge60 view");
        };
        let (_, p) = world(x, y);
        let eye = camera.position;
        // Under the slab (farther along the pixel's ray): the slab stays.
        draw_object(&r, &camera, eye + (p - eye) * 1.25, 3.0);
        let behind = r.read_color().unwrap();
        // Between the eye and the slab: the object shows.
        draw_object(&r, &camera, eye + (p - eye) * 0.6, 3.0);
        let front = r.read_color().unwrap();
        println!(
            "{name}: slab pixel ({x}, {y}) terrain {:?}, object behind -> {:?}, in front -> {:?}",
            pixel(&terrain, x, y),
            pixel(&behind, x, y),
            pixel(&front, x, y)
        );
        assert_eq!(
            pixel(&behind, x, y),
            pixel(&terrain, x, y),
            "{name}: behind"
        );
        assert_ne!(pixel(&terrain, x, y), OBJECT, "{name}");
        assert_eq!(pixel(&front, x, y), OBJECT, "{name}: in front");
        tested += 1;
    }
    assert!(tested >= 2, "{tested} methods ran");
}
