//! Opening the device: which backend and adapter ([`AdapterChoice`]), the
//! features and limits Strata requests, the GL self-check, and the list
//! `strata adapters` prints (with the methods each adapter runs).

use crate::caps::Capabilities;
use crate::gpu::{AdapterReport, ErrorSink, Gpu};
use anyhow::Context;
use serde::Serialize;
use std::sync::Arc;

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
/// [`list_adapters`] for that backend, or a piece of its name (else the
/// high-performance default).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AdapterChoice {
    /// The backend to look on.
    pub backend: BackendChoice,
    /// The adapter's index in `list_adapters` (`--adapter N`); `None`: the default.
    pub index: Option<usize>,
    /// Without an index: the first adapter whose name contains this,
    /// case-insensitive (the `strata` binary passes `WGPU_ADAPTER_NAME`).
    pub name: Option<String>,
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
        ..Default::default()
    };
    let instance = choice.instance();
    let adapters = pollster::block_on(instance.enumerate_adapters(backend.backends()));
    adapters
        .into_iter()
        .enumerate()
        .map(|(index, adapter)| {
            let mut refused = (adapter.get_info().backend == wgpu::Backend::Gl)
                .then(|| check_gl_adapter(&adapter).err())
                .flatten();
            // As `Gpu::open` does: wgpu's GL context mis-binds, Strata's own may not.
            let mut own_context = None;
            let mut adapter = adapter;
            if refused
                .as_ref()
                .is_some_and(|e| e.is::<crate::self_check::BindingsMisread>())
                && let Some((own, context)) = own_gl_adapter(&instance)
            {
                (adapter, own_context, refused) = (own, Some(context), None);
            }
            let mut info = adapter.get_info();
            if let Some(context) = &own_context {
                info.driver_info = format!(
                    "{} (Strata's own EGL context, {context}; wgpu's own misreads bindings: \
                     bench/gl-repro)",
                    info.driver_info
                );
            }
            let refused = refused.map(|e| format!("{e:#}"));
            let (features, limits) = device_request(&adapter);
            let capabilities = Capabilities::of(&adapter, &limits, features);
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

/// A GL adapter on a context Strata makes, if it passes the self-check, and
/// the context's description.
#[cfg(all(unix, not(target_vendor = "apple"), not(target_arch = "wasm32")))]
fn own_gl_adapter(instance: &wgpu::Instance) -> Option<(wgpu::Adapter, String)> {
    let (adapter, context) = crate::gl_context::open(instance).ok()?;
    check_gl_adapter(&adapter).ok()?;
    // The listing makes no device on it later (only limits and features):
    // the context may go.
    Some((adapter, context.description.clone()))
}

#[cfg(all(not(target_arch = "wasm32"), any(not(unix), target_vendor = "apple")))]
fn own_gl_adapter(_instance: &wgpu::Instance) -> Option<(wgpu::Adapter, String)> {
    None
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
    /// A headless device on the default adapter. wgpu honours `WGPU_BACKEND`
    /// (backend list) and `WGPU_POWER_PREF`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless() -> anyhow::Result<Self> {
        Self::open(&AdapterChoice::default())
    }

    /// A headless device on the adapter `choice` names.
    ///
    /// ```no_run
    /// use strata_render::{AdapterChoice, BackendChoice, Gpu};
    /// let gpu = Gpu::open(&AdapterChoice { backend: BackendChoice::Vulkan, ..Default::default() })?;
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
        // `STRATA_GL_OWN_CONTEXT=1`: headless GL on Strata's own context
        // even where wgpu's works (tests it on Mesa, measures it).
        if surface.is_none()
            && choice.backend == BackendChoice::Gl
            && std::env::var_os("STRATA_GL_OWN_CONTEXT").is_some_and(|v| v == "1")
        {
            return Self::on_own_gl_context(
                instance,
                anyhow::anyhow!("STRATA_GL_OWN_CONTEXT=1 asked for Strata's own GL context"),
            );
        }
        match pollster::block_on(Self::with_instance_async(instance.clone(), surface, choice)) {
            // Headless, wgpu's GL context mis-binds: try one of Strata's own.
            Err(e) if surface.is_none() && e.is::<crate::self_check::BindingsMisread>() => {
                Self::on_own_gl_context(instance, e)
            }
            other => other,
        }
    }

    /// The device on a GL context Strata makes (`gl_context.rs`), after
    /// wgpu's own failed the self-check with `why`.
    #[cfg(all(unix, not(target_vendor = "apple"), not(target_arch = "wasm32")))]
    fn on_own_gl_context(instance: wgpu::Instance, why: anyhow::Error) -> anyhow::Result<Self> {
        let (adapter, context) = match crate::gl_context::open(&instance) {
            Ok(pair) => pair,
            Err(e) => return Err(why.context(format!("{e:#}"))),
        };
        let mut gpu = pollster::block_on(Self::on_adapter(instance, adapter))
            .with_context(|| format!("on Strata's own {} context", context.description))?;
        gpu.report.driver_info = format!(
            "{} (Strata's own EGL context, {}: wgpu's desktop 3.3 context mis-binds uniform \
             blocks here, bench/gl-repro)",
            gpu.report.driver_info, context.description
        );
        gpu.own_gl_context = Some(Box::new(context));
        Ok(gpu)
    }

    #[cfg(all(not(target_arch = "wasm32"), any(not(unix), target_vendor = "apple")))]
    fn on_own_gl_context(_instance: wgpu::Instance, why: anyhow::Error) -> anyhow::Result<Self> {
        Err(why)
    }

    /// [`Gpu::with_instance`] as a future: a browser answers adapter and
    /// device requests only once the page has control back.
    pub async fn with_instance_async(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        choice: &AdapterChoice,
    ) -> anyhow::Result<Self> {
        let adapter = pick_adapter(&instance, surface, choice).await?;
        Self::on_adapter(instance, adapter).await
    }

    /// A device on `adapter` (of `instance`), with the features and limits
    /// Strata requests.
    async fn on_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> anyhow::Result<Self> {
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
                .with_context(|| format!("adapter `{}` (gl)", info.name))?;
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
            options: Default::default(),
            #[cfg(not(target_arch = "wasm32"))]
            own_gl_context: None,
        })
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
    if let Some(wanted) = &choice.name {
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
