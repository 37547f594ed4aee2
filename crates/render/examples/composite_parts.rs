//! Where `render_into`'s composite time goes on an adapter: each way of
//! moving a frame's colour and depth into a caller's textures, timed alone
//! by timestamps written by empty compute passes around it (the same
//! bracket `composite_cost` uses). Plain wgpu, no Strata method: the
//! source textures have the usages Strata's own colour and depth targets
//! have.
//!
//! ```text
//! cargo run --release -p strata-render --example composite_parts -- [--size WxH] [--frames N]
//! ```

use strata_render::Gpu;
use wgpu::TextureFormat as F;
use wgpu::TextureUsages as U;

const COMPUTE_COPY: &str = r#"
@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var dst: texture_storage_2d<rgba8unorm, write>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(src);
    if id.x >= size.x || id.y >= size.y { return; }
    textureStore(dst, id.xy, textureLoad(src, id.xy, 0));
}
"#;

const DEPTH_PASS: &str = r#"
@group(0) @binding(0) var src: texture_depth_2d;
@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
@group(0) @binding(1) var color: texture_2d<f32>;
@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @builtin(frag_depth) f32 {
    return textureLoad(src, vec2<i32>(p.xy), 0);
}
struct Both {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}
@fragment
fn fs_both(@builtin(position) p: vec4<f32>) -> Both {
    return Both(textureLoad(color, vec2<i32>(p.xy), 0), textureLoad(src, vec2<i32>(p.xy), 0));
}
"#;

fn main() -> anyhow::Result<()> {
    let (mut size, mut frames) = ((1280u32, 800u32), 200u32);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let v = args
            .next()
            .ok_or_else(|| anyhow::anyhow!("{a} needs a value"))?;
        match a.as_str() {
            "--size" => {
                size = v
                    .split_once('x')
                    .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
                    .ok_or_else(|| anyhow::anyhow!("--size {v:?}: expected WxH"))?
            }
            "--frames" => frames = v.parse()?,
            other => anyhow::bail!("unknown argument {other:?}"),
        }
    }
    let gpu = Gpu::headless()?;
    anyhow::ensure!(gpu.caps.timestamps, "this adapter has no timestamp queries");
    let device = &gpu.device;
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let src_color = texture(
        "src colour",
        F::Rgba8Unorm,
        U::STORAGE_BINDING | U::TEXTURE_BINDING | U::COPY_SRC | U::RENDER_ATTACHMENT,
    );
    let src_depth = texture(
        "src depth",
        F::Depth32Float,
        U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
    );
    let dst_color = texture(
        "caller colour",
        F::Rgba8Unorm,
        U::RENDER_ATTACHMENT | U::COPY_DST | U::STORAGE_BINDING,
    );
    let dst_depth = texture(
        "caller depth",
        F::Depth32Float,
        U::RENDER_ATTACHMENT | U::COPY_DST,
    );
    let view = |t: &wgpu::Texture| t.create_view(&Default::default());
    let (src_color_view, src_depth_view) = (view(&src_color), view(&src_depth));
    let (dst_color_view, dst_depth_view) = (view(&dst_color), view(&dst_depth));

    let copy_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("compute copy"),
        source: wgpu::ShaderSource::Wgsl(COMPUTE_COPY.into()),
    });
    let copy_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("compute copy"),
        layout: None,
        module: &copy_module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let copy_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("compute copy"),
        layout: &copy_pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&src_color_view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&dst_color_view),
            },
        ],
    });
    let depth_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth pass"),
        source: wgpu::ShaderSource::Wgsl(DEPTH_PASS.into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("depth pass"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("depth pass"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let color_target = [Some(wgpu::ColorTargetState::from(F::Rgba8Unorm))];
    let pass_pipeline = |entry: &str, with_color: bool| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth pass"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &depth_module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: F::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &depth_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: if with_color { &color_target } else { &[] },
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let depth_pipeline = pass_pipeline("fs", false);
    let both_pipeline = pass_pipeline("fs_both", true);
    let depth_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("depth pass"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&src_depth_view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&src_color_view),
            },
        ],
    });

    let set = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("parts"),
        ty: wgpu::QueryType::Timestamp,
        count: 2,
    });
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("parts stamps"),
        size: 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("parts stamps read"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let period_ms = f64::from(gpu.queue.get_timestamp_period()) * 1e-6;
    let extent = wgpu::Extent3d {
        width: size.0,
        height: size.1,
        depth_or_array_layers: 1,
    };
    let stamp = |encoder: &mut wgpu::CommandEncoder, index| {
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("stamp"),
            timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                query_set: &set,
                beginning_of_pass_write_index: Some(index),
                end_of_pass_write_index: None,
            }),
        });
    };
    let copy_color = |e: &mut wgpu::CommandEncoder| {
        e.copy_texture_to_texture(src_color.as_image_copy(), dst_color.as_image_copy(), extent)
    };
    let copy_depth = |e: &mut wgpu::CommandEncoder| {
        e.copy_texture_to_texture(src_depth.as_image_copy(), dst_depth.as_image_copy(), extent)
    };
    let compute_color = |e: &mut wgpu::CommandEncoder| {
        let mut pass = e.begin_compute_pass(&Default::default());
        pass.set_pipeline(&copy_pipeline);
        pass.set_bind_group(0, &copy_group, &[]);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
    };
    // SAFETY (of DontCare): the full-screen triangle writes every pixel.
    let dont_care = wgpu::LoadOp::DontCare(unsafe { wgpu::LoadOpDontCare::enabled() });
    let pass = |e: &mut wgpu::CommandEncoder, with_color: bool, load: wgpu::LoadOp<f32>| {
        let color_load = match load {
            wgpu::LoadOp::Clear(_) => wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            wgpu::LoadOp::Load => wgpu::LoadOp::Load,
            wgpu::LoadOp::DontCare(t) => wgpu::LoadOp::DontCare(t),
        };
        let colors = [Some(wgpu::RenderPassColorAttachment {
            view: &dst_color_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: color_load,
                store: wgpu::StoreOp::Store,
            },
        })];
        let mut pass = e.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth pass"),
            color_attachments: if with_color { &colors } else { &[] },
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &dst_depth_view,
                depth_ops: Some(wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(if with_color {
            &both_pipeline
        } else {
            &depth_pipeline
        });
        pass.set_bind_group(0, &depth_group, &[]);
        pass.draw(0..3, 0..1);
    };
    type Part<'a> = (&'a str, Box<dyn Fn(&mut wgpu::CommandEncoder) + 'a>);
    let parts: Vec<Part> = vec![
        ("nothing (the stamps alone)", Box::new(|_| {})),
        ("copy colour", Box::new(copy_color)),
        ("copy depth", Box::new(copy_depth)),
        (
            "copy colour + copy depth",
            Box::new(|e| {
                copy_color(e);
                copy_depth(e)
            }),
        ),
        ("compute colour into storage view", Box::new(compute_color)),
        (
            "compute colour + copy depth",
            Box::new(|e| {
                compute_color(e);
                copy_depth(e)
            }),
        ),
        (
            "depth-only pass, load",
            Box::new(|e| pass(e, false, wgpu::LoadOp::Load)),
        ),
        (
            "depth-only pass, clear",
            Box::new(|e| pass(e, false, wgpu::LoadOp::Clear(1.0))),
        ),
        (
            "depth-only pass, dont-care",
            Box::new(|e| pass(e, false, dont_care)),
        ),
        (
            "compute colour + depth-only pass, dont-care",
            Box::new(|e| {
                compute_color(e);
                pass(e, false, dont_care)
            }),
        ),
        (
            "colour+depth pass, clear",
            Box::new(|e| pass(e, true, wgpu::LoadOp::Clear(1.0))),
        ),
        (
            "colour+depth pass, load",
            Box::new(|e| pass(e, true, wgpu::LoadOp::Load)),
        ),
        (
            "colour+depth pass, dont-care",
            Box::new(|e| pass(e, true, dont_care)),
        ),
    ];
    println!(
        "adapter {} ({}), {}x{}, {frames} frames a line, median (min) GPU ms",
        gpu.report.name, gpu.report.backend, size.0, size.1
    );
    let _ = &dst_color_view;
    for (name, record) in &parts {
        let mut times = Vec::new();
        for _ in 0..frames {
            let mut encoder = device.create_command_encoder(&Default::default());
            stamp(&mut encoder, 0);
            record(&mut encoder);
            stamp(&mut encoder, 1);
            encoder.resolve_query_set(&set, 0..2, &resolve, 0);
            encoder.copy_buffer_to_buffer(&resolve, 0, &read, 0, 16);
            gpu.queue.submit([encoder.finish()]);
            gpu.wait()?;
            let raw = strata_render::gpu::read_buffer(device, &gpu.errors, &read, 16)?;
            let t: &[u64] = bytemuck::cast_slice(&raw);
            times.push(t[1].saturating_sub(t[0]) as f64 * period_ms);
        }
        times.sort_by(f64::total_cmp);
        println!("{name}: {:.4} ({:.4})", times[times.len() / 2], times[0]);
    }
    Ok(())
}
