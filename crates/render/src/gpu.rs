//! The device Strata draws on ([`Gpu`]; opened in `adapter.rs`), the error
//! sinks that turn validation errors and a lost device into `Err` values
//! instead of panics or hangs, and the platform seams every GPU module
//! shares: waiting for the device, error scopes ([`catching`]), blocking and
//! polled read-backs.

use crate::caps::Capabilities;
use crate::options::RenderOptions;
use serde::Serialize;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How long a single wait for the GPU may take before we call the device hung.
pub const GPU_WAIT_TIMEOUT: Duration = Duration::from_secs(120);

/// The adapter a result was produced on: printed in every output.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct AdapterReport {
    /// The adapter's name (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub name: String,
    /// Its backend, lower case (`vulkan`, `gl`, `metal`, `dx12`).
    pub backend: String,
    /// The driver's name.
    pub driver: String,
    /// The driver's version information.
    pub driver_info: String,
    /// `DiscreteGpu`, `IntegratedGpu`, `Cpu`, ...
    pub device_type: String,
    /// Whether per-pass GPU timestamps are available on this device.
    pub timestamps: bool,
}

/// Errors reported by the device asynchronously (validation, out of memory,
/// device lost). Shared with every renderer built on the device.
#[derive(Clone, Default)]
pub struct ErrorSink(Arc<Mutex<Vec<String>>>, Arc<Mutex<Option<String>>>);

impl ErrorSink {
    pub(crate) fn push(&self, msg: String) {
        if let Ok(mut v) = self.0.lock() {
            v.push(msg);
        }
    }

    /// Why the device was lost (destroyed included), once it has been: what
    /// fails after that is only a consequence.
    pub fn lost(&self) -> Option<String> {
        self.1.lock().ok().and_then(|l| l.clone())
    }

    pub(crate) fn set_lost(&self, why: String) {
        if let Ok(mut l) = self.1.lock() {
            l.get_or_insert(why);
        }
    }

    /// Drain collected errors into one `Err`, if any.
    pub fn check(&self) -> anyhow::Result<()> {
        let errors: Vec<String> = match self.0.lock() {
            Ok(mut v) => std::mem::take(&mut *v),
            Err(_) => vec!["GPU error sink poisoned".into()],
        };
        if errors.is_empty() {
            Ok(())
        } else {
            anyhow::bail!("GPU error: {}", errors.join("\n"))
        }
    }
}

/// A device, its queue and the adapter it came from.
pub struct Gpu {
    /// The wgpu instance the adapter came from.
    pub instance: wgpu::Instance,
    /// The adapter the device was made on.
    pub adapter: wgpu::Adapter,
    /// The device Strata builds on (yours, with [`Gpu::from_device`]).
    pub device: wgpu::Device,
    /// The queue Strata submits on.
    pub queue: wgpu::Queue,
    /// The adapter, as every output names it.
    pub report: AdapterReport,
    /// What the adapter can do, under the limits requested for the device.
    pub caps: Capabilities,
    /// Validation errors and device loss, collected (checked by [`Gpu::wait`] and each frame).
    pub errors: ErrorSink,
    /// The caller's measuring switches and test hooks for renderers built
    /// on this device (default: the product's).
    pub options: RenderOptions,
    /// A GL context Strata made itself (`gl_context.rs`), kept until the
    /// device above is gone (fields drop in order).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) own_gl_context: Option<Box<dyn std::any::Any + Send + Sync>>,
}

impl Gpu {
    /// Wait for all submitted work, turning a timeout or a lost device into an error.
    pub fn wait(&self) -> anyhow::Result<()> {
        wait_device(&self.device, &self.errors)
    }
}

/// Block until the device is idle, then report any collected error.
pub fn wait_device(device: &wgpu::Device, errors: &ErrorSink) -> anyhow::Result<()> {
    let polled = wait_idle(device);
    errors.check()?;
    polled.map_err(|e| anyhow::anyhow!("waiting for the GPU failed: {e}"))?;
    Ok(())
}

/// Block until the device is idle, up to [`GPU_WAIT_TIMEOUT`]. wgpu's GL
/// backend cuts one wait to about 2.1 s (a 32-bit nanosecond count), which a
/// first frame on NVIDIA's GL outlasts while it compiles shaders: so wait
/// again while our own limit has not passed.
pub fn wait_idle(device: &wgpu::Device) -> Result<(), wgpu::PollError> {
    // A page cannot block: the browser runs the queue in order after it
    // yields (read-backs are polled per frame there, see `TextureReadback`).
    if cfg!(target_arch = "wasm32") {
        return device.poll(wgpu::PollType::Poll).map(|_| ());
    }
    let start = web_time::Instant::now();
    loop {
        match device.poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout: Some(GPU_WAIT_TIMEOUT.saturating_sub(start.elapsed())),
        }) {
            Err(wgpu::PollError::Timeout) if start.elapsed() < GPU_WAIT_TIMEOUT => continue,
            Err(e) => return Err(e),
            Ok(_) => return Ok(()),
        }
    }
}

/// Map `buffer`'s first `size` bytes and copy them out.
pub fn read_buffer(
    device: &wgpu::Device,
    errors: &ErrorSink,
    buffer: &wgpu::Buffer,
    size: u64,
) -> anyhow::Result<Vec<u8>> {
    let slice = buffer.slice(..size);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    wait_device(device, errors)?;
    // After the wait the callback has run; in a browser it runs only once
    // the page yields, so there this read fails instead of blocking the page.
    rx.try_recv()
        .map_err(|_| {
            anyhow::anyhow!(
                "buffer map callback never ran (a blocking read-back is not possible in a browser)"
            )
        })?
        .map_err(|e| anyhow::anyhow!("mapping a readback buffer failed: {e}"))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| anyhow::anyhow!("reading a mapped buffer failed: {e}"))?
        .to_vec();
    buffer.unmap();
    Ok(data)
}

/// Copy a 2D texture of 4 bytes per texel (`aspect` of it) to the CPU,
/// rows unpadded, top row first.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    errors: &ErrorSink,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
) -> anyhow::Result<Vec<u8>> {
    TextureReadback::start(device, queue, texture, aspect).wait(device, errors)
}

/// The result of a buffer map, once its callback has run.
type MapState = Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// A texture on its way to the CPU without blocking: the copy is submitted
/// and the map requested at start; [`TextureReadback::try_take`] answers once
/// the map has completed (after a device poll natively, after the page has
/// yielded in a browser), so a frame loop can poll it once per frame.
pub struct TextureReadback {
    buffer: wgpu::Buffer,
    /// Bytes of one row, unpadded and padded.
    row: u32,
    padded: u32,
    mapped: MapState,
}

impl TextureReadback {
    /// Submit a copy of `texture` (its `aspect`'s bytes per texel, 4 where
    /// the format does not say) and ask for its map.
    pub fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) -> Self {
        let (w, h) = (texture.width(), texture.height());
        let texel = texture.format().block_copy_size(Some(aspect)).unwrap_or(4);
        let row = texel * w;
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded = row.div_ceil(align) * align;
        let size = u64::from(padded) * u64::from(h);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
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
        queue.submit([encoder.finish()]);
        let mapped = MapState::default();
        let sink = Arc::clone(&mapped);
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            if let Ok(mut state) = sink.lock() {
                *state = Some(r);
            }
        });
        TextureReadback {
            buffer,
            row,
            padded,
            mapped,
        }
    }

    /// The texels (rows unpadded, top row first) once the map has completed;
    /// `None` while it has not.
    pub fn try_take(&self, device: &wgpu::Device) -> Option<anyhow::Result<Vec<u8>>> {
        // Natively the map completes in a poll; in a browser this does nothing.
        let _ = device.poll(wgpu::PollType::Poll);
        let state = self.mapped.lock().ok()?.take()?;
        Some(
            state
                .map_err(|e| anyhow::anyhow!("mapping a readback buffer failed: {e}"))
                .and_then(|()| {
                    let slice = self.buffer.slice(..);
                    let raw = slice
                        .get_mapped_range()
                        .map_err(|e| anyhow::anyhow!("reading a mapped buffer failed: {e}"))?;
                    let mut out =
                        Vec::with_capacity(raw.len() / self.padded as usize * self.row as usize);
                    for r in raw.chunks_exact(self.padded as usize) {
                        out.extend_from_slice(&r[..self.row as usize]);
                    }
                    drop(raw);
                    self.buffer.unmap();
                    Ok(out)
                }),
        )
    }

    /// Block until the texels are here (not possible in a browser: there
    /// this fails; poll [`TextureReadback::try_take`] per frame instead).
    pub fn wait(self, device: &wgpu::Device, errors: &ErrorSink) -> anyhow::Result<Vec<u8>> {
        wait_device(device, errors)?;
        self.try_take(device).unwrap_or_else(|| {
            Err(anyhow::anyhow!(
                "buffer map callback never ran (a blocking read-back is not possible in a browser)"
            ))
        })
    }
}

/// Run `f` with the errors of `filter` it raises caught in an error scope:
/// what it returned, and the first such error. A browser answers a scope
/// only after the page yields, so there nothing is caught: the errors reach
/// the device's error sink (checked after each frame).
pub fn catching<T>(
    device: &wgpu::Device,
    filter: wgpu::ErrorFilter,
    f: impl FnOnce() -> T,
) -> (T, Option<wgpu::Error>) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let scope = device.push_error_scope(filter);
        let out = f();
        (out, pollster::block_on(scope.pop()))
    }
    #[cfg(target_arch = "wasm32")]
    {
        let _ = (device, filter);
        (f(), None)
    }
}

/// Copy `buffer` (`COPY_SRC`) whole to the CPU as `u32` words, blocking
/// (tests and checks; `what` names it in errors).
pub fn read_words(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    what: &str,
) -> anyhow::Result<Vec<u32>> {
    let size = buffer.size();
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(what),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    let raw = read_buffer(device, &ErrorSink::default(), &staging, size)
        .map_err(|e| anyhow::anyhow!("{what}: {e:#}"))?;
    Ok(bytemuck::pod_collect_to_vec(&raw))
}
