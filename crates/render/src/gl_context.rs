//! A GL context Strata makes itself, for the one adapter wgpu's own GL
//! context mis-binds.
//!
//! Through EGL, wgpu asks for a desktop GL 3.3 core context whenever the
//! driver offers desktop GL. NVIDIA's driver gives exactly 3.3, and also
//! lists `GL_ARB_compute_shader`; wgpu-hal 30 takes that extension as "the
//! shaders carry `layout(binding = N)`" and skips binding uniform blocks by
//! name, while naga's GLSL 330 carries no such layout: every uniform block
//! reads binding point 0 (`bench/gl-repro/` shows it with wgpu alone). A
//! desktop 4.6 (or 4.5, 4.3) core context, or GLES 3.2, has the layouts in
//! the shaders and draws right.
//!
//! So when wgpu's GL adapter fails the self-check and no window is
//! involved, Strata makes such a context on EGL's surfaceless platform (what
//! wgpu itself uses headless), makes it current on the calling thread and
//! hands it to wgpu ([`wgpu::hal::gles::Adapter::new_external`]). wgpu then
//! makes no context current itself: the device must be used from the thread
//! that opened it (every headless command does; the viewer, which builds
//! methods on threads and presents to a window, keeps wgpu's context).

use std::sync::Arc;

type Egl = khronos_egl::DynamicInstance<khronos_egl::EGL1_5>;

/// The context, destroyed when the [`crate::Gpu`] holding it is dropped
/// (after its device: the field comes last).
pub struct OwnGlContext {
    egl: Arc<Egl>,
    display: khronos_egl::Display,
    context: khronos_egl::Context,
    /// `desktop GL 4.6 core` or `GLES 3.2`: what was asked for and given.
    pub description: String,
}

impl Drop for OwnGlContext {
    fn drop(&mut self) {
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
    }
}

// SAFETY: the handles are plain EGL names; EGL calls on them are
// thread-safe. The context is only made current on the opening thread.
unsafe impl Send for OwnGlContext {}
unsafe impl Sync for OwnGlContext {}

/// The context versions tried, best first.
const VERSIONS: [(khronos_egl::Enum, i32, i32); 4] = [
    (khronos_egl::OPENGL_API, 4, 6),
    (khronos_egl::OPENGL_API, 4, 5),
    (khronos_egl::OPENGL_API, 4, 3),
    (khronos_egl::OPENGL_ES_API, 3, 2),
];

/// An adapter of `instance` (which must have the GL backend) on a context of
/// the first version EGL gives (desktop GL 4.6, 4.5, 4.3 core, then GLES
/// 3.2), current on this thread.
pub fn open(instance: &wgpu::Instance) -> anyhow::Result<(wgpu::Adapter, OwnGlContext)> {
    use anyhow::Context;
    use khronos_egl as egl;
    const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
    // SAFETY: loads the system's libEGL, as wgpu-hal does.
    let lib = Arc::new(unsafe { Egl::load_required() }.context("cannot load libEGL")?);
    // SAFETY: the surfaceless platform takes no native display.
    let display = unsafe {
        lib.get_platform_display(
            PLATFORM_SURFACELESS_MESA,
            egl::DEFAULT_DISPLAY,
            &[egl::ATTRIB_NONE],
        )
    }
    .context("eglGetPlatformDisplay (surfaceless)")?;
    lib.initialize(display).context("eglInitialize")?;
    let mut tried = Vec::new();
    for (api, major, minor) in VERSIONS {
        let desktop = api == egl::OPENGL_API;
        let description = match desktop {
            true => format!("desktop GL {major}.{minor} core"),
            false => format!("GLES {major}.{minor}"),
        };
        let mut attributes = vec![
            egl::CONTEXT_MAJOR_VERSION,
            major,
            egl::CONTEXT_MINOR_VERSION,
            minor,
        ];
        if desktop {
            attributes.extend([
                egl::CONTEXT_OPENGL_PROFILE_MASK,
                egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
            ]);
        }
        attributes.push(egl::NONE);
        let made = lib.bind_api(api).and_then(|()| {
            // No config: EGL_KHR_no_config_context (NVIDIA, Mesa); nothing
            // is drawn to an EGL surface.
            // SAFETY: EGL_NO_CONFIG_KHR is the null config.
            let config = unsafe { egl::Config::from_ptr(std::ptr::null_mut()) };
            let context = lib.create_context(display, config, None, &attributes)?;
            match lib.make_current(display, None, None, Some(context)) {
                Ok(()) => Ok(context),
                Err(e) => {
                    let _ = lib.destroy_context(display, context);
                    Err(e)
                }
            }
        });
        let context = match made {
            Ok(context) => context,
            Err(e) => {
                tried.push(format!("{description}: {e}"));
                continue;
            }
        };
        let own = OwnGlContext {
            egl: lib.clone(),
            display,
            context,
            description,
        };
        let loader = lib.clone();
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
        };
        match exposed {
            // SAFETY: made from a context current on this thread, for an
            // instance with the GL backend (the caller's contract).
            Some(exposed) => {
                return Ok((unsafe { instance.create_adapter_from_hal(exposed) }, own));
            }
            None => tried.push(format!("{}: wgpu refused the context", own.description)),
        }
    }
    anyhow::bail!("no GL context Strata could make: {}", tried.join("; "))
}
