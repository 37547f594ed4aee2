//! What differs between a native window and a browser page, besides the
//! event loop and the device request (in `lib.rs` and, on wasm32, `web.rs`),
//! behind one object the viewer holds ([`Platform`]): the window's
//! attributes, the page's script commands and the state published to it,
//! where a saved file goes, and the process's resident memory.

use crate::Script;
use std::path::Path;
use winit::window::WindowAttributes;

/// Where the viewer runs: a native window or a browser page.
#[derive(Clone, Copy, Debug, Default)]
pub struct Platform;

impl Platform {
    /// The window's attributes here (in a page: the page's canvas).
    pub fn window_attributes(self, attributes: WindowAttributes) -> WindowAttributes {
        #[cfg(target_arch = "wasm32")]
        return crate::page::canvas_attributes(attributes);
        #[cfg(not(target_arch = "wasm32"))]
        attributes
    }

    /// Script commands the page pushed since the last frame (none natively:
    /// a native script comes with `--script`).
    pub fn take_commands(self) -> Vec<Script> {
        #[cfg(target_arch = "wasm32")]
        return crate::page::take_commands();
        #[cfg(not(target_arch = "wasm32"))]
        Vec::new()
    }

    /// Publish the viewer's state after a frame to the page's scripts (and
    /// the browser test); natively nobody reads it, so it is not made.
    pub fn publish(self, state: impl FnOnce() -> serde_json::Value, frames: u64) {
        #[cfg(target_arch = "wasm32")]
        crate::page::publish(state(), frames);
        #[cfg(not(target_arch = "wasm32"))]
        let _ = (state, frames);
    }

    /// Save `bytes` as `path`: a file natively (its directory created), a
    /// download named after the path's file name in a browser.
    pub fn save_file(self, path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
        #[cfg(target_arch = "wasm32")]
        {
            let name = path
                .file_name()
                .map_or_else(|| "strata.bin".into(), |n| n.to_string_lossy().into_owned());
            crate::page::download(&name, bytes)
        }
        #[cfg(not(target_arch = "wasm32"))]
        {
            use anyhow::Context;
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("creating {}", dir.display()))?;
            }
            std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
        }
    }

    /// The process's resident set size in bytes (`VmRSS` of
    /// `/proc/self/status`, Linux); `None` where there is no such file
    /// (other systems, a browser).
    pub fn rss_bytes(self) -> Option<u64> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib * 1024)
    }
}
