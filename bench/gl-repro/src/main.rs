//! Does a fragment shader see what its bind groups hold? Each probe binds
//! known values (uniform buffers, a `u32` texture, an array texture) in one
//! or two bind groups and writes one `u32` computed from them into a 1x1
//! `R32Uint` target, which is read back and compared with the answer.
//!
//! Strata refuses NVIDIA's GL adapter (a desktop 3.3 context wgpu opens
//! through EGL) because its full probe fails there; this program narrows
//! down which binding shape breaks, using wgpu alone:
//!
//!     cargo run --release -p strata-gl-repro               # every GL adapter
//!     WGPU_BACKEND=vulkan cargo run --release -p strata-gl-repro   # control
//!
//! `REPRO_LOG=trace` adds wgpu-hal's log (the GLSL naga wrote, which
//! block index and texture unit each binding got). It prints one line per probe (`ok` or the wrong value) and exits 1 if any
//! probe failed on any adapter.

const A: u32 = 0x5eed_1234;
const B: u32 = 0x0bad_cafe;
const C: u32 = 0x1357_9bdf;
const T: u32 = 0xa5;

/// What a probe binds, in bind group order.
#[derive(Clone, Copy)]
enum Res {
    /// A uniform buffer whose first `u32` is this.
    Uniform(u32),
    /// A 2x1 `Rgba8Uint` texture with this in texel (1, 0)'s red.
    Texture(u32),
    /// A 2x1x2 `Rgba8Uint` array texture with this in layer 1, texel (1, 0).
    ArrayTexture(u32),
}

struct Probe {
    name: &'static str,
    /// Bindings per group.
    groups: &'static [&'static [Res]],
    /// The fragment shader's body (WGSL declarations and `fs`).
    wgsl: &'static str,
    want: u32,
}

const VS: &str = "
@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}
struct P { value: vec4<u32> }
";

fn probes() -> Vec<Probe> {
    use Res::*;
    vec![
        Probe {
            name: "one uniform (group 0)",
            groups: &[&[Uniform(A)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(a.value.x); }",
            want: A,
        },
        Probe {
            name: "second of two uniforms (group 0)",
            groups: &[&[Uniform(A), Uniform(B)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(0) @binding(1) var<uniform> b: P;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(b.value.x); }",
            want: B,
        },
        Probe {
            name: "two uniforms of one type (group 0), both read",
            groups: &[&[Uniform(A), Uniform(B)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(0) @binding(1) var<uniform> b: P;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(a.value.x ^ (b.value.x * 3u)); }",
            want: A ^ B.wrapping_mul(3),
        },
        Probe {
            name: "uniform in group 1 (group 0 has one too)",
            groups: &[&[Uniform(A)], &[Uniform(C)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(1) @binding(0) var<uniform> c: P;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(c.value.x); }",
            want: C,
        },
        Probe {
            name: "uniforms in groups 0 and 1, both read",
            groups: &[&[Uniform(A)], &[Uniform(C)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(1) @binding(0) var<uniform> c: P;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(a.value.x ^ (c.value.x * 7u)); }",
            want: A ^ C.wrapping_mul(7),
        },
        Probe {
            name: "u32 texture alone",
            groups: &[&[Texture(T)]],
            wgsl: "@group(0) @binding(0) var t: texture_2d<u32>;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(textureLoad(t, vec2<i32>(1, 0), 0).x); }",
            want: T,
        },
        Probe {
            name: "u32 array texture, layer 1",
            groups: &[&[ArrayTexture(T)]],
            wgsl: "@group(0) @binding(0) var t: texture_2d_array<u32>;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(textureLoad(t, vec2<i32>(1, 0), 1, 0).x); }",
            want: T,
        },
        Probe {
            name: "uniform then texture (group 0), the uniform",
            groups: &[&[Uniform(A), Texture(T)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(0) @binding(1) var t: texture_2d<u32>;
                   @fragment fn fs() -> @location(0) vec4<u32> { return vec4<u32>(a.value.x ^ textureLoad(t, vec2<i32>(1, 0), 0).x); }",
            want: A ^ T,
        },
        Probe {
            name: "Strata's shape: 2 uniforms + array texture (group 0), uniform (group 1)",
            groups: &[&[Uniform(A), Uniform(B), ArrayTexture(T)], &[Uniform(C)]],
            wgsl: "@group(0) @binding(0) var<uniform> a: P;
                   @group(0) @binding(1) var<uniform> b: P;
                   @group(0) @binding(2) var t: texture_2d_array<u32>;
                   @group(1) @binding(0) var<uniform> c: P;
                   @fragment fn fs() -> @location(0) vec4<u32> {
                       let x = textureLoad(t, vec2<i32>(1, 0), 1, 0).x;
                       return vec4<u32>(a.value.x ^ (b.value.x * 3u) ^ (c.value.x * 7u) ^ (x * 11u));
                   }",
            want: A ^ B.wrapping_mul(3) ^ C.wrapping_mul(7) ^ T.wrapping_mul(11),
        },
    ]
}

/// Prints wgpu's log records at or above `REPRO_LOG`'s level to stderr.
struct Logger(log::LevelFilter);

impl log::Log for Logger {
    fn enabled(&self, meta: &log::Metadata) -> bool {
        meta.level() <= self.0
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            eprintln!("[{} {}] {}", record.level(), record.target(), record.args());
        }
    }
    fn flush(&self) {}
}

fn main() {
    if let Some(level) = std::env::var("REPRO_LOG").ok().and_then(|l| l.parse().ok()) {
        let logger: &'static Logger = Box::leak(Box::new(Logger(level)));
        if log::set_logger(logger).is_ok() {
            log::set_max_level(level);
        }
    }
    let own_context = std::env::args().any(|a| a == "--own-context");
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    if std::env::var_os("WGPU_BACKEND").is_none() {
        desc.backends = wgpu::Backends::GL;
    }
    // wgpu-core's indirect-draw validation needs compute shaders, which a
    // desktop 3.3 context lacks: without this, no device at all.
    desc.flags -= wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL;
    let instance = wgpu::Instance::new(desc);
    let mut adapters = if own_context {
        Vec::new()
    } else {
        pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
    };
    // Kept alive (and current on this thread) while its adapter is probed.
    let mut contexts = Vec::new();
    if own_context {
        for version in [
            ContextVersion::Desktop(3, 3),
            ContextVersion::Desktop(4, 6),
            ContextVersion::Desktop(4, 5),
            ContextVersion::Es(3, 2),
        ] {
            match own_gl_context(version) {
                Ok((context, exposed)) => {
                    println!("own EGL context {version:?}: made");
                    // SAFETY: the adapter comes from a context made current
                    // on this thread, for an instance with the GL backend.
                    adapters.push(unsafe { instance.create_adapter_from_hal(exposed) });
                    contexts.push(context);
                }
                Err(e) => println!("own EGL context {version:?}: {e}"),
            }
        }
    }
    if adapters.is_empty() {
        eprintln!("no adapter found");
        std::process::exit(2);
    }
    let mut failed = 0;
    for (i, adapter) in adapters.into_iter().enumerate() {
        if own_context {
            contexts[i].make_current();
        }
        let info = adapter.get_info();
        println!(
            "adapter: {} ({:?}, driver {:?} {:?})",
            info.name, info.backend, info.driver, info.driver_info
        );
        let (device, queue) =
            match pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())) {
                Ok(pair) => pair,
                Err(e) => {
                    println!("  no device: {e}");
                    continue;
                }
            };
        device.on_uncaptured_error(std::sync::Arc::new(|e| println!("  wgpu error: {e}")));
        for probe in probes() {
            let got = run(&device, &queue, &probe);
            if got == probe.want {
                println!("  ok      {}", probe.name);
            } else {
                failed += 1;
                println!(
                    "  WRONG   {}: got {got:#010x}, want {:#010x}",
                    probe.name, probe.want
                );
            }
        }
    }
    std::process::exit(if failed > 0 { 1 } else { 0 });
}

fn resource(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    res: Res,
) -> (wgpu::BindGroupLayoutEntry, Owned) {
    let visibility = wgpu::ShaderStages::FRAGMENT;
    match res {
        Res::Uniform(x) => {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            queue.write_buffer(
                &buffer,
                0,
                &[x.to_le_bytes(), [0; 4], [0; 4], [0; 4]].concat(),
            );
            let ty = wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            };
            (entry(visibility, ty), Owned::Buffer(buffer))
        }
        Res::Texture(x) | Res::ArrayTexture(x) => {
            let layers = if matches!(res, Res::ArrayTexture(_)) {
                2
            } else {
                1
            };
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: 2,
                    height: 1,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let mut data = vec![0u8; 8 * layers as usize];
            data[8 * (layers as usize - 1) + 4] = x as u8;
            queue.write_texture(
                texture.as_image_copy(),
                &data,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(8),
                    rows_per_image: Some(1),
                },
                texture.size(),
            );
            let dimension = if layers == 2 {
                wgpu::TextureViewDimension::D2Array
            } else {
                wgpu::TextureViewDimension::D2
            };
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(dimension),
                ..Default::default()
            });
            let ty = wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: dimension,
                multisampled: false,
            };
            (entry(visibility, ty), Owned::View(view))
        }
    }
}

enum Owned {
    Buffer(wgpu::Buffer),
    View(wgpu::TextureView),
}

fn entry(visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility,
        ty,
        count: None,
    }
}

/// Draw the probe and read its one pixel back.
fn run(device: &wgpu::Device, queue: &wgpu::Queue, probe: &Probe) -> u32 {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(probe.name),
        source: wgpu::ShaderSource::Wgsl(format!("{VS}\n{}", probe.wgsl).into()),
    });
    let mut layouts = Vec::new();
    let mut groups = Vec::new();
    for bindings in probe.groups {
        let made: Vec<_> = bindings
            .iter()
            .map(|r| resource(device, queue, *r))
            .collect();
        let entries: Vec<_> = made
            .iter()
            .enumerate()
            .map(|(i, (e, _))| wgpu::BindGroupLayoutEntry {
                binding: i as u32,
                ..*e
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &entries,
        });
        let group_entries: Vec<_> = made
            .iter()
            .enumerate()
            .map(|(i, (_, owned))| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: match owned {
                    Owned::Buffer(b) => b.as_entire_binding(),
                    Owned::View(v) => wgpu::BindingResource::TextureView(v),
                },
            })
            .collect();
        groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &group_entries,
        }));
        layouts.push(layout);
    }
    let layout_refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &layout_refs,
        immediate_size: 0,
    });
    let format = wgpu::TextureFormat::R32Uint;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(probe.name),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 256,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let view = target.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        for (i, group) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, group, &[]);
        }
        pass.draw(0..3, 0..1);
    }
    encoder.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(256),
                rows_per_image: None,
            },
        },
        target.size(),
    );
    queue.submit([encoder.finish()]);
    readback.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    let _ = device.poll(wgpu::PollType::wait_indefinitely());
    let Ok(bytes) = readback.slice(..4).get_mapped_range() else {
        return 0xffff_ffff;
    };
    u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
}

#[derive(Clone, Copy, Debug)]
enum ContextVersion {
    Desktop(i32, i32),
    Es(i32, i32),
}

type Egl = khronos_egl::DynamicInstance<khronos_egl::EGL1_5>;

/// An EGL context of our choosing on the surfaceless platform (what wgpu
/// picks without a window), made current.
struct OwnContext {
    egl: std::sync::Arc<Egl>,
    display: khronos_egl::Display,
    context: khronos_egl::Context,
}

impl OwnContext {
    fn make_current(&self) {
        let _ = self
            .egl
            .make_current(self.display, None, None, Some(self.context));
    }
}

fn own_gl_context(
    version: ContextVersion,
) -> Result<(OwnContext, wgpu::hal::ExposedAdapter<wgpu::hal::api::Gles>), String> {
    use khronos_egl as egl;
    const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
    // SAFETY: loading the system's libEGL, as wgpu-hal does.
    let instance = std::sync::Arc::new(
        unsafe { Egl::load_required() }.map_err(|e| format!("cannot load libEGL: {e}"))?,
    );
    // SAFETY: the surfaceless platform takes no native display.
    let display = unsafe {
        instance.get_platform_display(
            PLATFORM_SURFACELESS_MESA,
            egl::DEFAULT_DISPLAY,
            &[egl::ATTRIB_NONE],
        )
    }
    .map_err(|e| format!("eglGetPlatformDisplay: {e}"))?;
    instance
        .initialize(display)
        .map_err(|e| format!("eglInitialize: {e}"))?;
    let (api, renderable, attributes) = match version {
        ContextVersion::Desktop(major, minor) => (
            egl::OPENGL_API,
            egl::OPENGL_BIT,
            vec![
                egl::CONTEXT_MAJOR_VERSION,
                major,
                egl::CONTEXT_MINOR_VERSION,
                minor,
                egl::CONTEXT_OPENGL_PROFILE_MASK,
                egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
                egl::NONE,
            ],
        ),
        ContextVersion::Es(major, minor) => (
            egl::OPENGL_ES_API,
            egl::OPENGL_ES3_BIT,
            vec![
                egl::CONTEXT_MAJOR_VERSION,
                major,
                egl::CONTEXT_MINOR_VERSION,
                minor,
                egl::NONE,
            ],
        ),
    };
    // Surfaceless needs no config where EGL_KHR_no_config_context is (NVIDIA
    // and Mesa have it); a matching one otherwise.
    let config = match instance
        .choose_first_config(display, &[egl::RENDERABLE_TYPE, renderable, egl::NONE])
        .map_err(|e| format!("eglChooseConfig: {e}"))?
    {
        Some(config) => config,
        // SAFETY: EGL_NO_CONFIG_KHR is the null config.
        None => unsafe { egl::Config::from_ptr(std::ptr::null_mut()) },
    };
    instance
        .bind_api(api)
        .map_err(|e| format!("eglBindAPI: {e}"))?;
    let context = instance
        .create_context(display, config, None, &attributes)
        .map_err(|e| format!("eglCreateContext: {e}"))?;
    instance
        .make_current(display, None, None, Some(context))
        .map_err(|e| format!("eglMakeCurrent (surfaceless): {e}"))?;
    let loader = instance.clone();
    // SAFETY: the context is current on this thread.
    let exposed = unsafe {
        wgpu::hal::gles::Adapter::new_external(
            |name| {
                loader
                    .get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
            },
            wgpu::GlBackendOptions::default(),
        )
    }
    .ok_or("wgpu refused the context")?;
    Ok((
        OwnContext {
            egl: instance,
            display,
            context,
        },
        exposed,
    ))
}
