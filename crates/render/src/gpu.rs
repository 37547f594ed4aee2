//! Device setup: one headless (or surface-compatible) wgpu device, the adapter
//! it runs on, and the error sinks that turn validation errors and a lost
//! device into `Err` values instead of panics or hangs.

use crate::caps::Capabilities;
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
    fn push(&self, msg: String) {
        if let Ok(mut v) = self.0.lock() {
            v.push(msg);
        }
    }

    /// Why the device was lost (destroyed included), once it has been: what
    /// fails after that is only a consequence.
    pub fn lost(&self) -> Option<String> {
        self.1.lock().ok().and_then(|l| l.clone())
    }

    fn set_lost(&self, why: String) {
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
}

const NO_ADAPTER_HELP: &str = "no GPU adapter found. On a machine without a GPU install Mesa's \
     software Vulkan driver (`apt install mesa-vulkan-drivers`, the lavapipe adapter) or its GL \
     driver (`libegl1 libgl1-mesa-dri`, llvmpipe); --backend vulkan|gl|dx12|metal (or \
     WGPU_BACKEND) selects a backend, --adapter N an adapter listed by `strata adapters`";

/// Which wgpu backend to look for adapters on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    /// Every backend, or those `WGPU_BACKEND` names.
    #[default]
    Auto,
    /// Vulkan only.
    Vulkan,
    /// OpenGL / GLES (EGL) only.
    Gl,
    /// Direct3D 12 only.
    Dx12,
    /// Metal only.
    Metal,
}

impl BackendChoice {
    /// The names `--backend` takes, in variant order.
    pub const NAMES: &[&str] = &["auto", "vulkan", "gl", "dx12", "metal"];

    /// The instance backends to create.
    pub fn backends(self) -> wgpu::Backends {
        match self {
            BackendChoice::Auto => wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all()),
            BackendChoice::Vulkan => wgpu::Backends::VULKAN,
            BackendChoice::Gl => wgpu::Backends::GL,
            BackendChoice::Dx12 => wgpu::Backends::DX12,
            BackendChoice::Metal => wgpu::Backends::METAL,
        }
    }
}

impl std::str::FromStr for BackendChoice {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "auto" => BackendChoice::Auto,
            "vulkan" | "vk" => BackendChoice::Vulkan,
            "gl" | "gles" | "opengl" => BackendChoice::Gl,
            "dx12" | "d3d12" => BackendChoice::Dx12,
            "metal" | "mtl" => BackendChoice::Metal,
            _ => anyhow::bail!(
                "unknown backend `{s}`; known: {}",
                BackendChoice::NAMES.join(", ")
            ),
        })
    }
}

impl std::fmt::Display for BackendChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let i = match self {
            BackendChoice::Auto => 0,
            BackendChoice::Vulkan => 1,
            BackendChoice::Gl => 2,
            BackendChoice::Dx12 => 3,
            BackendChoice::Metal => 4,
        };
        f.write_str(BackendChoice::NAMES[i])
    }
}

/// Which adapter to open: a backend, and optionally the adapter's index in
/// [`list_adapters`] for that backend (else the high-performance default,
/// or the one `WGPU_ADAPTER_NAME` names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdapterChoice {
    /// The backend to look on.
    pub backend: BackendChoice,
    /// The adapter's index in `list_adapters` (`--adapter N`); `None`: the default.
    pub index: Option<usize>,
}

impl AdapterChoice {
    /// A wgpu instance for this choice's backends (`WGPU_*` variables apply
    /// to everything the choice leaves open).
    pub fn instance(&self) -> wgpu::Instance {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = self.backend.backends();
        desc.flags = instance_flags(desc.flags);
        wgpu::Instance::new(desc)
    }
}

/// The instance flags Strata runs with: wgpu's defaults (or `WGPU_*`'s)
/// without indirect-call validation. Strata issues no indirect draws or
/// dispatches, and that validation builds a compute pipeline when the device
/// is made, which fails on GL contexts that claim compute without GLSL for it
/// (NVIDIA's desktop GL 3.3 through EGL refused every device for it).
pub fn instance_flags(flags: wgpu::InstanceFlags) -> wgpu::InstanceFlags {
    flags - wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL
}

/// One adapter as `strata adapters` lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AdapterListing {
    /// Pass as `--adapter N` (with the same `--backend`).
    pub index: usize,
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
    /// What it can do under the limits Strata would request.
    pub capabilities: Capabilities,
    /// Why the adapter as a whole is refused (its device cannot be made,
    /// or fails the GL self-check), if it is.
    pub refused: Option<String>,
    /// Every method, and whether it runs here.
    pub methods: Vec<MethodSupport>,
}

/// Whether one method runs on an adapter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodSupport {
    /// The method's name.
    pub name: String,
    /// `None` when it runs; else why not (the capabilities missing).
    pub refused: Option<String>,
}

/// Every adapter the chosen backend offers, in `--adapter` index order, with
/// what each can do under the limits Strata would request.
#[cfg(not(target_arch = "wasm32"))]
pub fn list_adapters(backend: BackendChoice) -> Vec<AdapterListing> {
    let choice = AdapterChoice {
        backend,
        index: None,
    };
    let instance = choice.instance();
    let adapters = pollster::block_on(instance.enumerate_adapters(backend.backends()));
    adapters
        .into_iter()
        .enumerate()
        .map(|(index, adapter)| {
            let info = adapter.get_info();
            let (features, limits) = device_request(&adapter);
            let capabilities = Capabilities::of(&adapter, &limits, features);
            let refused = (info.backend == wgpu::Backend::Gl)
                .then(|| check_gl_adapter(&adapter).err().map(|e| format!("{e:#}")))
                .flatten();
            let methods = crate::methods::METHODS
                .iter()
                .map(|entry| MethodSupport {
                    name: entry.name.to_string(),
                    refused: match &refused {
                        Some(_) => Some(format!("{}: the adapter is refused (above)", entry.name)),
                        None => entry.check(&capabilities).err().map(|r| r.to_string()),
                    },
                })
                .collect();
            AdapterListing {
                index,
                name: info.name.clone(),
                backend: backend_name(info.backend),
                driver: info.driver.clone(),
                driver_info: info.driver_info.clone(),
                device_type: format!("{:?}", info.device_type),
                capabilities,
                refused,
                methods,
            }
        })
        .collect()
}

/// Make a device on a GL adapter and run the self-check on it.
#[cfg(not(target_arch = "wasm32"))]
fn check_gl_adapter(adapter: &wgpu::Adapter) -> anyhow::Result<()> {
    let (features, limits) = device_request(adapter);
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("strata adapters"),
        required_features: features,
        required_limits: limits,
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }))
    .map_err(|e| anyhow::anyhow!("it refused a device: {e}"))?;
    let errors = ErrorSink::default();
    let sink = errors.clone();
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| sink.push(e.to_string())));
    crate::self_check::uniforms_read_back(&device, &queue, &errors)
}

fn backend_name(backend: wgpu::Backend) -> String {
    format!("{backend:?}").to_lowercase()
}

/// The features and limits Strata requests of `adapter`.
fn device_request(adapter: &wgpu::Adapter) -> (wgpu::Features, wgpu::Limits) {
    let mut features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
    // In a browser a timestamp read-back completes only after the page
    // yields, and the frame loop reads its stamps at once: untimed there.
    if cfg!(target_arch = "wasm32") {
        features = wgpu::Features::empty();
    }
    (features, device_limits(&adapter.limits()))
}

impl Gpu {
    /// A headless device on the default adapter. Honours `WGPU_BACKEND`
    /// (backend list), `WGPU_ADAPTER_NAME` (substring of the adapter name,
    /// case-insensitive) and `WGPU_POWER_PREF`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless() -> anyhow::Result<Self> {
        Self::open(&AdapterChoice::default())
    }

    /// A headless device on the adapter `choice` names.
    ///
    /// ```no_run
    /// use strata_render::{AdapterChoice, BackendChoice, Gpu};
    /// let gpu = Gpu::open(&AdapterChoice { backend: BackendChoice::Vulkan, index: None })?;
    /// println!("on {} ({})", gpu.report.name, gpu.report.backend);
    /// # anyhow::Ok(())
    /// ```
    #[cfg(not(target_arch = "wasm32"))]
    pub fn open(choice: &AdapterChoice) -> anyhow::Result<Self> {
        Self::with_instance(choice.instance(), None, choice)
    }

    /// A device able to present to `surface` (the viewer), on `instance`
    /// (made by [`AdapterChoice::instance`]) and the adapter `choice` names.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        choice: &AdapterChoice,
    ) -> anyhow::Result<Self> {
        pollster::block_on(Self::with_instance_async(instance, surface, choice))
    }

    /// [`Gpu::with_instance`] as a future: a browser answers adapter and
    /// device requests only once the page has control back.
    pub async fn with_instance_async(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        choice: &AdapterChoice,
    ) -> anyhow::Result<Self> {
        let adapter = pick_adapter(&instance, surface, choice).await?;
        let info = adapter.get_info();
        let (features, limits) = device_request(&adapter);
        let caps = Capabilities::of(&adapter, &limits, features);
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
        Self::from_parts(instance, adapter, device, queue, caps)
    }

    /// Embedding: run Strata on the caller's own device and queue (made from
    /// `adapter` of `instance` with whatever features and limits the caller
    /// chose). Methods the device's limits or features cannot run are
    /// refused by name when they are created ([`Capabilities`]). This
    /// installs Strata's uncaptured-error and device-lost handlers on the
    /// device (they collect errors that [`Gpu::wait`] and every frame report),
    /// replacing the caller's.
    ///
    /// ```no_run
    /// # fn f(instance: wgpu::Instance, adapter: wgpu::Adapter) -> anyhow::Result<()> {
    /// // Your engine's device and queue...
    /// let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
    /// // ...shared with Strata (wgpu handles are reference-counted clones).
    /// let gpu = strata_render::Gpu::from_device(instance, adapter, device.clone(), queue.clone())?;
    /// # Ok(()) }
    /// ```
    pub fn from_device(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> anyhow::Result<Self> {
        let caps = Capabilities::of(&adapter, &device.limits(), device.features());
        Self::from_parts(instance, adapter, device, queue, caps)
    }

    fn from_parts(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        caps: Capabilities,
    ) -> anyhow::Result<Self> {
        let info = adapter.get_info();
        let errors = ErrorSink::default();
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| sink.push(e.to_string())));
        let sink = errors.clone();
        device.set_device_lost_callback(move |reason, msg| {
            sink.set_lost(match msg.as_str() {
                "" => format!("{reason:?}"),
                _ => format!("{reason:?}: {msg}"),
            });
            // A deliberate drop of the device is not an error.
            if reason != wgpu::DeviceLostReason::Destroyed {
                sink.push(format!("device lost ({reason:?}): {msg}"));
            }
        });

        // wgpu maps bind groups to GL binding points itself: check, with a
        // draw of known answer, that it worked, before any picture is trusted.
        // (Not in a browser: its read-back cannot block; the browser test
        // compares WebGL2's picture with WebGPU's instead.)
        if !cfg!(target_arch = "wasm32") && info.backend == wgpu::Backend::Gl {
            crate::self_check::uniforms_read_back(&device, &queue, &errors)
                .map_err(|e| anyhow::anyhow!("adapter `{}` (gl): {e:#}", info.name))?;
        }

        let report = AdapterReport {
            name: info.name.clone(),
            backend: backend_name(info.backend),
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
            device_type: format!("{:?}", info.device_type),
            timestamps: caps.timestamps,
        };
        Ok(Gpu {
            instance,
            adapter,
            device,
            queue,
            report,
            caps,
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

/// WebGPU default limits (so what runs here runs in a browser), except the
/// sizes that only bound image and buffer dimensions, which follow the adapter
/// so large render targets and method buffers work where the hardware allows.
fn device_limits(adapter: &wgpu::Limits) -> wgpu::Limits {
    let mut limits = wgpu::Limits::default();
    // In a browser: WebGPU's default limits and never more (a page must run
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
    choice: &AdapterChoice,
) -> anyhow::Result<wgpu::Adapter> {
    let listed = |adapters: &[wgpu::Adapter]| -> String {
        if adapters.is_empty() {
            return NO_ADAPTER_HELP.to_string();
        }
        let names: Vec<String> = adapters
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let info = a.get_info();
                format!("{i}: {} ({})", info.name, backend_name(info.backend))
            })
            .collect();
        names.join(", ")
    };
    if let Some(index) = choice.index {
        let adapters = instance.enumerate_adapters(choice.backend.backends()).await;
        let (count, names) = (adapters.len(), listed(&adapters));
        let Some(adapter) = adapters.into_iter().nth(index) else {
            anyhow::bail!(
                "--adapter {index}: backend `{}` has {count} adapter(s): {names}",
                choice.backend
            );
        };
        if surface.is_some_and(|s| !adapter.is_surface_supported(s)) {
            anyhow::bail!(
                "--adapter {index} (`{}`) cannot present to this window",
                adapter.get_info().name
            );
        }
        return Ok(adapter);
    }
    if let Ok(wanted) = std::env::var("WGPU_ADAPTER_NAME") {
        let wanted = wanted.to_lowercase();
        let adapters = instance.enumerate_adapters(choice.backend.backends()).await;
        let usable: Vec<wgpu::Adapter> = adapters
            .into_iter()
            .filter(|a| surface.is_none_or(|s| a.is_surface_supported(s)))
            .collect();
        let names = listed(&usable);
        return usable
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&wanted))
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "WGPU_ADAPTER_NAME=`{wanted}` matches no adapter; available: {names}"
                )
            });
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
        .map_err(|e| {
            let on = match choice.backend {
                BackendChoice::Auto => String::new(),
                b => format!(" on backend `{b}`"),
            };
            anyhow::anyhow!("{NO_ADAPTER_HELP}{on} ({e})")
        })
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
