//! Device setup: one headless (or surface-compatible) wgpu device, the adapter
//! it runs on, and the error sinks that turn validation errors and a lost
//! device into `Err` values instead of panics or hangs.

use serde::Serialize;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How long a single wait for the GPU may take before we call the device hung.
pub const GPU_WAIT_TIMEOUT: Duration = Duration::from_secs(120);

/// The adapter a result was produced on: printed in every output.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct AdapterReport {
    pub name: String,
    pub backend: String,
    pub driver: String,
    pub driver_info: String,
    pub device_type: String,
    /// Whether per-pass GPU timestamps are available on this device.
    pub timestamps: bool,
}

/// Errors reported by the device asynchronously (validation, out of memory,
/// device lost). Shared with every renderer built on the device.
#[derive(Clone, Default)]
pub struct ErrorSink(Arc<Mutex<Vec<String>>>);

impl ErrorSink {
    fn push(&self, msg: String) {
        if let Ok(mut v) = self.0.lock() {
            v.push(msg);
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
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub report: AdapterReport,
    pub errors: ErrorSink,
}

const NO_ADAPTER_HELP: &str = "no GPU adapter found. On a machine without a GPU install Mesa's \
     software Vulkan driver (`apt install mesa-vulkan-drivers`, the lavapipe adapter); \
     WGPU_BACKEND=vulkan|gl|metal|dx12 selects a backend, WGPU_ADAPTER_NAME a named adapter";

impl Gpu {
    /// A headless device. Honours `WGPU_BACKEND` (backend list),
    /// `WGPU_ADAPTER_NAME` (substring of the adapter name, case-insensitive)
    /// and `WGPU_POWER_PREF`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless() -> anyhow::Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::with_instance(instance, None)
    }

    /// A device able to present to `surface` (for a future viewer), chosen by the
    /// same environment variables.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> anyhow::Result<Self> {
        pollster::block_on(Self::with_instance_async(instance, surface))
    }

    /// [`Gpu::with_instance`] as a future: the browser answers adapter and
    /// device requests only once the page has control back.
    pub async fn with_instance_async(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> anyhow::Result<Self> {
        let adapter = pick_adapter(&instance, surface).await?;
        let info = adapter.get_info();
        // In the browser a timestamp read-back completes only after the page
        // yields, and the frame loop reads its stamps at once: untimed there.
        let timestamps = !cfg!(target_arch = "wasm32")
            && adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let limits = device_limits(&adapter.limits());
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("strata"),
                required_features: features,
                required_limits: limits,
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| anyhow::anyhow!("adapter `{}` refused a device: {e}", info.name))?;

        let errors = ErrorSink::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| sink.push(e.to_string())));
        let sink = errors.clone();
        device.set_device_lost_callback(move |reason, msg| {
            // A deliberate drop of the device is not an error.
            if reason != wgpu::DeviceLostReason::Destroyed {
                sink.push(format!("device lost ({reason:?}): {msg}"));
            }
        });

        let report = AdapterReport {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend).to_lowercase(),
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
            device_type: format!("{:?}", info.device_type),
            timestamps,
        };
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
            report,
            errors,
        })
    }

    /// Wait for all submitted work, turning a timeout or a lost device into an error.
    pub fn wait(&self) -> anyhow::Result<()> {
        wait_device(&self.device, &self.errors)
    }
}

/// Block until the device is idle, then report any collected error.
pub fn wait_device(device: &wgpu::Device, errors: &ErrorSink) -> anyhow::Result<()> {
    let polled = device.poll(wgpu::PollType::Wait {
        submission_index: None,
        timeout: Some(GPU_WAIT_TIMEOUT),
    });
    errors.check()?;
    polled.map_err(|e| anyhow::anyhow!("waiting for the GPU failed: {e}"))?;
    Ok(())
}

/// WebGPU default limits (so what runs here runs in a browser), except the
/// sizes that only bound image and buffer dimensions, which follow the adapter
/// so large render targets and method buffers work where the hardware allows.
fn device_limits(adapter: &wgpu::Limits) -> wgpu::Limits {
    let mut limits = wgpu::Limits::default();
    // In the browser: WebGPU's default limits and never more (a page must run
    // on every WebGPU adapter), or WebGL2's where the adapter is below them.
    if cfg!(target_arch = "wasm32") {
        return if limits.check_limits(adapter) {
            limits
        } else {
            wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.clone())
        };
    }
    if limits.check_limits(adapter) {
        limits.max_texture_dimension_2d = adapter.max_texture_dimension_2d;
        limits.max_buffer_size = adapter.max_buffer_size;
        limits.max_storage_buffer_binding_size = adapter.max_storage_buffer_binding_size;
        limits
    } else {
        // A downlevel adapter (e.g. GL): take what it has.
        adapter.clone()
    }
}

async fn pick_adapter(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
) -> anyhow::Result<wgpu::Adapter> {
    if let Ok(wanted) = std::env::var("WGPU_ADAPTER_NAME") {
        let wanted = wanted.to_lowercase();
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        let mut names = Vec::new();
        for adapter in adapters {
            let info = adapter.get_info();
            if surface.is_some_and(|s| !adapter.is_surface_supported(s)) {
                continue;
            }
            if info.name.to_lowercase().contains(&wanted) {
                return Ok(adapter);
            }
            names.push(format!("{} ({:?})", info.name, info.backend));
        }
        anyhow::bail!(
            "WGPU_ADAPTER_NAME=`{wanted}` matches no adapter; available: {}",
            if names.is_empty() {
                NO_ADAPTER_HELP.to_string()
            } else {
                names.join(", ")
            }
        );
    }
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env()
                .unwrap_or(wgpu::PowerPreference::HighPerformance),
            force_fallback_adapter: false,
            compatible_surface: surface,
            apply_limit_buckets: false,
        })
        .await
        .map_err(|e| anyhow::anyhow!("{NO_ADAPTER_HELP} ({e})"))
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
    // After the wait the callback has run; in the browser it runs only once
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
    /// Submit a copy of `texture` (4 bytes per texel of `aspect`) and ask for its map.
    pub fn start(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) -> Self {
        let (w, h) = (texture.width(), texture.height());
        let row = 4 * w;
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
