//! [`Renderer`]: the shared frame plus one method, the API the CLI and the
//! harness drive: build, `render_frame`, `apply_edit`, read back, report memory.

use crate::frame::{Globals, LevelShape, Shared, TerrainColors};
use crate::gpu::{ErrorSink, Gpu, read_buffer, wait_device};
use crate::methods::{self, Frame, Method, MethodSettings, RetainedBytes};
use crate::shadow::{ShadowFrame, ShadowPass};
use crate::timing::{FrameTimings, MAX_TIMED_PASSES, PassTimer};
use std::time::Instant;
use strata_camera::Camera;
use strata_level::{DirtyRect, Level};

/// What [`Renderer::measure`] saw.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    pub first_frame_ms: f64,
    pub warmup_ms: f64,
    pub timings: Vec<FrameTimings>,
}

/// One method rendering one level at one size.
pub struct Renderer {
    shared: Shared,
    method: Box<dyn Method>,
    shadow: ShadowPass,
    settings: MethodSettings,
    timer: PassTimer,
    /// Resolve target and mappable copy of the timestamps.
    stamps: Option<(wgpu::Buffer, wgpu::Buffer)>,
    period_ns: f64,
    errors: ErrorSink,
    level_shape: LevelShape,
    frames: u64,
    adapter: crate::gpu::AdapterReport,
    setup_ms: f64,
}

impl Renderer {
    /// Upload `level`, build method `method` for `width` x `height` targets.
    pub fn new(
        gpu: &Gpu,
        level: &Level,
        colors: &TerrainColors,
        method: &str,
        settings: &MethodSettings,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Self> {
        let start = Instant::now();
        // Unknown names fail before any GPU work.
        if !methods::names().contains(&method) {
            anyhow::bail!(
                "unknown method `{method}`; known: {}",
                methods::names().join(", ")
            );
        }
        let shared = Shared::new(&gpu.device, &gpu.queue, level, colors, width, height)?;
        let method = methods::create(method, &shared, level, settings)?;
        let shadow = ShadowPass::new(&shared)?;
        let timer = PassTimer::new(&gpu.device, gpu.report.timestamps);
        let stamps = gpu.report.timestamps.then(|| {
            let size = u64::from(2 * MAX_TIMED_PASSES) * 8;
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps read"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (resolve, read)
        });
        let mut renderer = Renderer {
            shared,
            method,
            shadow,
            settings: settings.clone(),
            timer,
            stamps,
            period_ns: f64::from(gpu.queue.get_timestamp_period()),
            errors: gpu.errors.clone(),
            level_shape: LevelShape::of(level),
            frames: 0,
            adapter: gpu.report.clone(),
            setup_ms: 0.0,
        };
        wait_device(&renderer.shared.device, &renderer.errors)?;
        renderer.setup_ms = ms(start);
        Ok(renderer)
    }

    pub fn method_name(&self) -> &'static str {
        self.method.name()
    }

    /// The adapter this renderer runs on.
    pub fn adapter(&self) -> &crate::gpu::AdapterReport {
        &self.adapter
    }

    /// Wall-clock ms `new` took: terrain upload, pipelines, method data,
    /// waiting for the GPU to finish them (the protocol's "setup").
    pub fn setup_ms(&self) -> f64 {
        self.setup_ms
    }

    pub fn settings(&self) -> &MethodSettings {
        &self.settings
    }

    /// The shared resources (for tests and tools that inspect them).
    pub fn shared(&self) -> &Shared {
        &self.shared
    }

    /// Render one frame and wait for it. GPU time is the sum of the per-pass
    /// timestamp intervals; CPU time is submit until the GPU is done.
    pub fn render_frame(&mut self, camera: &Camera) -> anyhow::Result<FrameTimings> {
        if camera.width != self.shared.width || camera.height != self.shared.height {
            anyhow::bail!(
                "camera is {}x{} but the renderer was built for {}x{}",
                camera.width,
                camera.height,
                self.shared.width,
                self.shared.height
            );
        }
        let record_start = Instant::now();
        let shadow = ShadowFrame::fit(camera, self.settings.shadows);
        let globals = Globals::new(camera, &self.level_shape, &shadow);
        self.shared
            .queue
            .write_buffer(&self.shared.globals, 0, bytemuck::bytes_of(&globals));
        self.method.prepare(&self.shared, camera)?;

        let mut encoder = self
            .shared
            .device
            .create_command_encoder(&Default::default());
        self.timer.reset();
        if self.settings.shadows {
            self.shadow.record(&mut encoder, &self.timer);
        }
        let frame = Frame {
            camera,
            timer: &self.timer,
            index: self.frames,
        };
        self.method.record(&self.shared, &frame, &mut encoder);
        let used = self.timer.used();
        if let (Some((resolve, read)), Some(qs)) = (&self.stamps, self.timer.query_set())
            && used > 0
        {
            encoder.resolve_query_set(qs, 0..2 * used, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, u64::from(2 * used) * 8);
        }
        let commands = encoder.finish();
        let record_ms = ms(record_start);

        let submit_start = Instant::now();
        self.shared.queue.submit([commands]);
        wait_device(&self.shared.device, &self.errors)?;
        let cpu_ms = ms(submit_start);
        self.frames += 1;

        let (gpu_ms, passes) = match &self.stamps {
            Some((_, read)) if used > 0 => {
                let raw = read_buffer(
                    &self.shared.device,
                    &self.errors,
                    read,
                    u64::from(2 * used) * 8,
                )?;
                let ticks: &[u64] = bytemuck::cast_slice(&raw);
                let passes: Vec<(String, f64)> = self
                    .timer
                    .labels()
                    .into_iter()
                    .zip(ticks.chunks_exact(2))
                    .map(|(label, t)| {
                        (
                            label,
                            t[1].wrapping_sub(t[0]) as f64 * self.period_ns * 1e-6,
                        )
                    })
                    .collect();
                (Some(passes.iter().map(|p| p.1).sum()), passes)
            }
            _ => (None, Vec::new()),
        };
        Ok(FrameTimings {
            gpu_ms,
            cpu_ms,
            record_ms,
            passes,
            untimed_passes: self.timer.untimed(),
        })
    }

    /// The protocol's frame loop: one first frame, `warmup` untimed frames,
    /// then `frames` timed ones (wall-clock ms of the first frame and of the
    /// warm-up as a whole, as preparation costs).
    pub fn measure(
        &mut self,
        camera: &Camera,
        warmup: u32,
        frames: u32,
    ) -> anyhow::Result<Measured> {
        let start = Instant::now();
        self.render_frame(camera)?;
        let first_frame_ms = ms(start);
        let start = Instant::now();
        for _ in 0..warmup {
            self.render_frame(camera)?;
        }
        let warmup_ms = ms(start);
        let timings = (0..frames)
            .map(|_| self.render_frame(camera))
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok(Measured {
            first_frame_ms,
            warmup_ms,
            timings,
        })
    }

    /// The level changed inside `rects` (`level` is the edited level): upload
    /// only those rectangles, then let the method update its derived data.
    pub fn apply_edit(&mut self, level: &Level, rects: &[DirtyRect]) -> anyhow::Result<()> {
        self.shared
            .terrain
            .upload(&self.shared.queue, level, rects)?;
        self.method.apply_edit(&self.shared, level, rects)?;
        Ok(())
    }

    /// The colour target, RGBA8, row-major, top row first.
    pub fn read_color(&self) -> anyhow::Result<Vec<u8>> {
        self.read_texture(&self.shared.color, wgpu::TextureAspect::All)
    }

    /// The depth target: depth-buffer values (0 near .. 1 far, 1 = sky), row-major.
    pub fn read_depth(&self) -> anyhow::Result<Vec<f32>> {
        let raw = self.read_texture(&self.shared.depth, wgpu::TextureAspect::DepthOnly)?;
        Ok(bytemuck::cast_slice::<u8, f32>(&raw).to_vec())
    }

    /// Bytes the method keeps beyond the shared resources.
    pub fn retained_bytes(&self) -> RetainedBytes {
        self.method.retained_bytes()
    }

    /// Bytes of the shared resources (terrain, uniforms, shadow map, targets).
    pub fn shared_gpu_bytes(&self) -> u64 {
        self.shared.gpu_bytes()
    }

    /// Copy a 4-byte-per-texel target to the CPU, unpadding rows.
    fn read_texture(
        &self,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) -> anyhow::Result<Vec<u8>> {
        let (w, h) = (self.shared.width, self.shared.height);
        let row = 4 * w;
        let padded =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let size = u64::from(padded) * u64::from(h);
        let buffer = self.shared.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .shared
            .device
            .create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.shared.queue.submit([encoder.finish()]);
        let raw = read_buffer(&self.shared.device, &self.errors, &buffer, size)?;
        let mut out = Vec::with_capacity((row * h) as usize);
        for r in raw.chunks_exact(padded as usize) {
            out.extend_from_slice(&r[..row as usize]);
        }
        Ok(out)
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}
