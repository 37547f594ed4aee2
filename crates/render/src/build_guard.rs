//! A method's build under watch: out-of-memory and validation errors the
//! GPU raises while it is built are caught in error scopes (natively; a
//! browser answers a scope only after the page yields, so there they reach
//! the device's error sink, checked each frame) and become one error that
//! names the method, the picture size and the level size, so `compare` can
//! record the cell and go on and the viewer can say what failed.

use crate::gpu::catching;
use crate::options::RenderOptions;
use strata_level::Level;

/// What was being built, for the error.
pub struct BuildTarget<'a> {
    pub method: &'a str,
    pub width: u32,
    pub height: u32,
    pub level: &'a Level,
}

impl BuildTarget<'_> {
    fn describe(&self) -> String {
        format!(
            "building `{}` for a {}x{} picture of a {}x{} level",
            self.method,
            self.width,
            self.height,
            self.level.width(),
            self.level.height()
        )
    }
}

/// Run `build` for `target`, turning a GPU error it raised into a clear
/// one. `options.oversize_build` naming the method (a test hook) makes the
/// build also ask for a buffer over the device's limit.
pub fn guarded<T>(
    device: &wgpu::Device,
    options: &RenderOptions,
    target: &BuildTarget<'_>,
    build: impl FnOnce() -> anyhow::Result<T>,
) -> anyhow::Result<T> {
    let ((built, invalid), oom) = catching(device, wgpu::ErrorFilter::OutOfMemory, || {
        catching(device, wgpu::ErrorFilter::Validation, || {
            let built = build();
            if options.oversize_build.as_deref() == Some(target.method) {
                force_oversize(device);
            }
            built
        })
    });
    if let Some(e) = oom {
        anyhow::bail!(
            "{} ran out of GPU memory ({}); try a smaller --size or coarser settings",
            target.describe(),
            innermost(&e)
        );
    }
    if let Some(e) = invalid {
        anyhow::bail!(
            "{} failed: the GPU refused it ({})",
            target.describe(),
            innermost(&e)
        );
    }
    flatten(built, target)
}

/// The build's own error, prefixed with what was built, as one message (its
/// `Display` keeps the reason, which a context layer would hide).
fn flatten<T>(built: anyhow::Result<T>, target: &BuildTarget<'_>) -> anyhow::Result<T> {
    built.map_err(|e| anyhow::anyhow!("{}: {e:#}", target.describe()))
}

/// The root cause of a wgpu error, one line (its full text is a
/// multi-line "Caused by" dump).
fn innermost(e: &wgpu::Error) -> String {
    let mut cause: &dyn std::error::Error = e;
    while let Some(next) = cause.source() {
        cause = next;
    }
    let text = cause.to_string();
    let line = text.lines().rev().map(str::trim).find(|l| !l.is_empty());
    line.unwrap_or("no reason given").to_string()
}

/// A buffer one block over the device's limit, as an oversized build asks for.
fn force_oversize(device: &wgpu::Device) {
    let size = device.limits().max_buffer_size.saturating_add(256);
    let _ = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("oversize (test)"),
        size,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
}
