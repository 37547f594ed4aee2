//! A draw with a known answer, run once when a device is made on wgpu's GL
//! backend: a uniform buffer's value written out by a fragment shader. wgpu
//! translates bind groups into GL binding points itself, and on NVIDIA's
//! desktop GL 3.3 context (through EGL) uniform blocks read wrong values:
//! every method drew sky, and `ray`'s step count came back in the billions
//! (the GPU hung). Such an adapter is refused by name instead of drawing
//! wrong pictures; headless, Strata then tries a GL context of its own
//! (`gl_context.rs`). `bench/gl-repro/` narrows the fault down with wgpu alone.

use crate::gpu::{ErrorSink, read_texture};

const SHADER: &str = "
struct Probe { value: vec4<u32> }
@group(0) @binding(0) var<uniform> first: Probe;
@group(0) @binding(1) var<uniform> second: Probe;
@group(0) @binding(2) var texels: texture_2d_array<u32>;
@group(1) @binding(0) var<uniform> method: Probe;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs() -> @location(0) vec4<u32> {
    let t = textureLoad(texels, vec2<i32>(1, 0), 1, 0).x;
    return vec4<u32>(first.value.x ^ (second.value.x * 3u) ^ (method.value.x * 7u) ^ (t * 11u), 0u, 0u, 0u);
}
";

/// What each uniform holds (`x`), and the texel at (1, 0) of layer 1.
const FIRST: u32 = 0x5eed_1234;
const SECOND: u32 = 0x0bad_cafe;
const METHOD: u32 = 0x1357_9bdf;
const TEXEL: u32 = 0xa5;

fn uniform(device: &wgpu::Device, queue: &wgpu::Queue, x: u32) -> wgpu::Buffer {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("self check"),
        size: 16,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&[x, 0, 0, 0]));
    buffer
}

/// The self-check's failure: what the probe computed and what was due.
#[derive(Debug)]
pub struct BindingsMisread {
    pub got: u32,
    pub want: u32,
}

impl std::fmt::Display for BindingsMisread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a fragment shader computed {:#010x} from its bindings where {:#010x} was due: bind \
             groups (uniforms in two groups and an array texture, as every method binds them) \
             do not reach shaders on this adapter through wgpu (NVIDIA's desktop GL 3.3 context \
             through EGL: every uniform block reads binding point 0, because wgpu-hal takes \
             GL_ARB_compute_shader for explicit binding layouts that naga's GLSL 330 lacks; \
             bench/gl-repro/ shows it with wgpu alone); use another backend (--backend vulkan)",
            self.got, self.want
        )
    }
}

impl std::error::Error for BindingsMisread {}

/// `Err` ([`BindingsMisread`] when the answer is wrong) when a fragment shader does not compute what the bindings hold: two
/// uniforms and a `u32` array texture in group 0, a uniform in group 1, as
/// every method binds the shared frame and its own parameters.
pub fn uniforms_read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    errors: &ErrorSink,
) -> anyhow::Result<()> {
    use crate::frame::{texture_entry, uniform_layout_entry};
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("self check"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let (first, second, method) = (
        uniform(device, queue, FIRST),
        uniform(device, queue, SECOND),
        uniform(device, queue, METHOD),
    );
    // Two layers, as the terrain texture always has (see terrain.rs).
    let texels = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("self check"),
        size: wgpu::Extent3d {
            width: 2,
            height: 1,
            depth_or_array_layers: 2,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Uint,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut data = [0u8; 16];
    data[12] = TEXEL as u8;
    queue.write_texture(
        texels.as_image_copy(),
        &data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(8),
            rows_per_image: Some(1),
        },
        texels.size(),
    );
    let texels_view = texels.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("self check frame"),
        entries: &[
            uniform_layout_entry(0),
            uniform_layout_entry(1),
            texture_entry(
                2,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2Array,
            ),
        ],
    });
    let method_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("self check method"),
        entries: &[uniform_layout_entry(0)],
    });
    let frame_group = crate::frame::bind_group(
        device,
        "self check frame",
        &frame_layout,
        &[
            first.as_entire_binding(),
            second.as_entire_binding(),
            wgpu::BindingResource::TextureView(&texels_view),
        ],
    );
    let method_group = crate::frame::bind_group(
        device,
        "self check method",
        &method_layout,
        &[method.as_entire_binding()],
    );
    let format = wgpu::TextureFormat::R32Uint;
    let pipeline = crate::fullscreen::pipeline(
        device,
        "self check",
        &[&frame_layout, &method_layout],
        &module,
        ("vs", "fs"),
        format,
    );
    let (target, view) = crate::frame::texture_2d(
        device,
        "self check",
        (1, 1),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let mut encoder = device.create_command_encoder(&Default::default());
    crate::fullscreen::draw(
        &mut encoder,
        "self check",
        &view,
        &pipeline,
        &[&frame_group, &method_group],
        None,
    );
    queue.submit([encoder.finish()]);
    let raw = read_texture(device, queue, errors, &target, wgpu::TextureAspect::All)?;
    let want = FIRST ^ SECOND.wrapping_mul(3) ^ METHOD.wrapping_mul(7) ^ TEXEL.wrapping_mul(11);
    let got = raw
        .first_chunk::<4>()
        .map(|b| u32::from_le_bytes(*b))
        .ok_or_else(|| anyhow::anyhow!("the self-check read back no pixel"))?;
    if got != want {
        return Err(BindingsMisread { got, want }.into());
    }
    Ok(())
}
