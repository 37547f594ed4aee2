//! From the renderer's picture to the window: the picture (or an A/B pair)
//! is composed into a window-sized image, the overlay is painted on top, and
//! that image is copied to the swapchain. Screenshots read the window image,
//! so they show exactly what the window shows.
//!
//! The picture follows the window's size (times the render scale) once the
//! renderer has been resized; until then (a method is being built in the
//! background) it is scaled to fit, with bars.

use bytemuck::{Pod, Zeroable};
use strata_render::Shared;
use strata_render::frame::texture_2d;
use strata_render::fullscreen;
use strata_render::gpu::TextureReadback;

/// The window image's format: what egui paints into and screenshots hold.
pub const WINDOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Twin of `Params` in `present.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    viewport: [f32; 4],
    options: [f32; 4],
}

/// A texture and its default view.
struct Image {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

/// A window-format image (RGBA8) of `size`.
fn image(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    usage: wgpu::TextureUsages,
) -> Image {
    let (texture, view) = texture_2d(device, label, size, WINDOW_FORMAT, usage);
    Image { texture, view }
}

pub struct Compositor {
    device: wgpu::Device,
    queue: wgpu::Queue,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    compose: wgpu::RenderPipeline,
    present: wgpu::RenderPipeline,
    compose_params: wgpu::Buffer,
    present_params: wgpu::Buffer,
    /// The A picture of an A/B pair, copied out before B is drawn.
    left: Image,
    /// Binds the shared picture on both sides / the A copy left of it.
    single_group: wgpu::BindGroup,
    split_group: wgpu::BindGroup,
    window: Image,
    present_group: wgpu::BindGroup,
    render_size: (u32, u32),
    window_size: (u32, u32),
}

impl Compositor {
    pub fn new(
        shared: &Shared,
        window_size: (u32, u32),
        surface_format: wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        let device = shared.device.clone();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("present.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../shaders/present.wgsl").into()),
        });
        let texture_entry = |binding| strata_render::frame::fragment_texture_entry(binding, true);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("present"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(1),
                texture_entry(2),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("present"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str, format: wgpu::TextureFormat| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let compose = pipeline("fs_compose", WINDOW_FORMAT);
        let present = pipeline("fs_present", surface_format);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("picture"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let params = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: std::mem::size_of::<Params>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let (compose_params, present_params) = (params("compose"), params("present"));
        shared.queue.write_buffer(
            &present_params,
            0,
            bytemuck::bytes_of(&Params {
                viewport: [0.0; 4],
                options: [2.0, f32::from(u8::from(surface_format.is_srgb())), 0.0, 0.0],
            }),
        );
        let group = |left: &wgpu::TextureView, right: &wgpu::TextureView, params: &wgpu::Buffer| {
            bind_images(&device, &layout, &sampler, params, left, right)
        };
        let window = Self::window_image(&device, window_size);
        let present_group = group(&window.view, &window.view, &present_params);
        let (left, single_group, split_group) =
            picture_groups(shared, &layout, &sampler, &compose_params);
        Ok(Compositor {
            queue: shared.queue.clone(),
            layout,
            sampler,
            compose,
            present,
            compose_params,
            present_params,
            left,
            single_group,
            split_group,
            window,
            present_group,
            render_size: (shared.width, shared.height),
            window_size,
            device,
        })
    }

    /// The renderer's targets were resized: bind the new ones.
    pub fn rebind_picture(&mut self, shared: &Shared) {
        (self.left, self.single_group, self.split_group) =
            picture_groups(shared, &self.layout, &self.sampler, &self.compose_params);
        self.render_size = (shared.width, shared.height);
    }

    fn window_image(device: &wgpu::Device, size: (u32, u32)) -> Image {
        use wgpu::TextureUsages as U;
        image(
            device,
            "window image",
            (size.0.max(1), size.1.max(1)),
            U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
        )
    }

    /// The window's inner size changed.
    pub fn resize(&mut self, size: (u32, u32)) {
        if size == self.window_size {
            return;
        }
        self.window_size = size;
        self.window = Self::window_image(&self.device, size);
        self.present_group = bind_images(
            &self.device,
            &self.layout,
            &self.sampler,
            &self.present_params,
            &self.window.view,
            &self.window.view,
        );
    }

    pub fn window_size(&self) -> (u32, u32) {
        self.window_size
    }

    /// Where the picture lies in the window: x, y, width, height in pixels
    /// (the largest fit that keeps the render's aspect, centred).
    pub fn picture_rect(&self) -> [f32; 4] {
        fit_rect(self.render_size, self.window_size)
    }

    /// A window position (physical pixels) as a point of the rendered
    /// picture (render pixels), or `None` on the bars.
    pub fn window_to_picture(&self, x: f32, y: f32) -> Option<(f32, f32)> {
        window_to_picture(self.render_size, self.window_size, (x, y))
    }

    /// Keep the current picture as the A side of an A/B pair.
    pub fn keep_left(&self, shared: &Shared, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_texture(
            shared.color.as_image_copy(),
            self.left.texture.as_image_copy(),
            wgpu::Extent3d {
                width: self.render_size.0,
                height: self.render_size.1,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Draw the picture into the window image: alone, or the kept A left of
    /// the current picture with the divider at `split` (fraction of the width).
    pub fn compose(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        split: Option<f32>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let params = Params {
            viewport: self.picture_rect(),
            options: [split.unwrap_or(2.0), 0.0, 0.0, 0.0],
        };
        self.queue
            .write_buffer(&self.compose_params, 0, bytemuck::bytes_of(&params));
        let group = if split.is_some() {
            &self.split_group
        } else {
            &self.single_group
        };
        let target = &self.window.view;
        // The shaders write every pixel (bars included): the clear is unseen.
        fullscreen::draw(
            encoder,
            "compose",
            target,
            &self.compose,
            &[group],
            timestamps,
        );
    }

    /// The window image, for the overlay to paint on (load, don't clear).
    pub fn window_view(&self) -> &wgpu::TextureView {
        &self.window.view
    }

    /// Copy the window image to the swapchain image `target`.
    pub fn present(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let group = &self.present_group;
        fullscreen::draw(
            encoder,
            "present",
            target,
            &self.present,
            &[group],
            timestamps,
        );
    }

    /// The window image as RGBA8 (what a screenshot saves).
    /// Start copying what the window shows (RGBA8, top row first) to the CPU.
    pub fn start_read_window(&self) -> TextureReadback {
        TextureReadback::start(
            &self.device,
            &self.queue,
            &self.window.texture,
            wgpu::TextureAspect::All,
        )
    }
}

/// The pass's bind group: parameters, left and right images, the sampler.
fn bind_images(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    sampler: &wgpu::Sampler,
    params: &wgpu::Buffer,
    left: &wgpu::TextureView,
    right: &wgpu::TextureView,
) -> wgpu::BindGroup {
    strata_render::frame::bind_group(
        device,
        "present",
        layout,
        &[
            params.as_entire_binding(),
            wgpu::BindingResource::TextureView(left),
            wgpu::BindingResource::TextureView(right),
            wgpu::BindingResource::Sampler(sampler),
        ],
    )
}

/// The kept A picture (the renderer's size) and the compose groups: the
/// renderer's picture alone, and the A copy left of it.
fn picture_groups(
    shared: &Shared,
    layout: &wgpu::BindGroupLayout,
    sampler: &wgpu::Sampler,
    params: &wgpu::Buffer,
) -> (Image, wgpu::BindGroup, wgpu::BindGroup) {
    let device = &shared.device;
    let left = image(
        device,
        "A picture",
        (shared.width, shared.height),
        wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let color = &shared.color_view;
    let single = bind_images(device, layout, sampler, params, color, color);
    let split = bind_images(device, layout, sampler, params, &left.view, color);
    (left, single, split)
}

/// The largest rectangle of the render's aspect inside the window, centred:
/// x, y, width, height in window pixels.
pub fn fit_rect(render: (u32, u32), window: (u32, u32)) -> [f32; 4] {
    let (ww, wh) = (window.0 as f32, window.1 as f32);
    let (rw, rh) = (render.0 as f32, render.1 as f32);
    let scale = (ww / rw).min(wh / rh);
    let (w, h) = ((rw * scale).round(), (rh * scale).round());
    [((ww - w) * 0.5).floor(), ((wh - h) * 0.5).floor(), w, h]
}

/// Window pixel position `at` as a point of the picture in render pixels,
/// or `None` outside the picture (on the bars).
pub fn window_to_picture(
    render: (u32, u32),
    window: (u32, u32),
    at: (f32, f32),
) -> Option<(f32, f32)> {
    let [px, py, pw, ph] = fit_rect(render, window);
    let (u, v) = ((at.0 - px) / pw, (at.1 - py) / ph);
    ((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v))
        .then_some((u * render.0 as f32, v * render.1 as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_picture_fills_a_same_aspect_window_and_letterboxes_otherwise() {
        assert_eq!(fit_rect((640, 400), (1280, 800)), [0.0, 0.0, 1280.0, 800.0]);
        // A taller window: bars above and below.
        assert_eq!(fit_rect((640, 400), (640, 600)), [0.0, 100.0, 640.0, 400.0]);
        // A wider one: bars left and right.
        assert_eq!(
            fit_rect((640, 400), (1000, 400)),
            [180.0, 0.0, 640.0, 400.0]
        );
    }

    #[test]
    fn window_positions_map_to_render_pixels() {
        // Half-size render: window pixel (101, 51) is render (50.5, 25.5).
        assert_eq!(
            window_to_picture((640, 400), (1280, 800), (101.0, 51.0)),
            Some((50.5, 25.5))
        );
        // Letterboxed: the bar is outside, the picture's corner is (0, 0).
        assert_eq!(
            window_to_picture((640, 400), (640, 600), (10.0, 50.0)),
            None
        );
        assert_eq!(
            window_to_picture((640, 400), (640, 600), (0.0, 100.0)),
            Some((0.0, 0.0))
        );
        assert_eq!(
            window_to_picture((640, 400), (640, 600), (639.0, 500.0)),
            None
        );
    }
}
