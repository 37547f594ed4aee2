//! What differs between a native window and a browser page, besides the
//! event loop and the device request (in `lib.rs` and, on wasm32, `web.rs`):
//! where a saved file goes, and the process's resident memory.

use std::path::Path;

/// Save `bytes` as `path`: a file natively (its directory created), a
/// download named after the path's file name in a browser.
pub fn save_file(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    #[cfg(target_arch = "wasm32")]
    {
        let name = path
            .file_name()
            .map_or_else(|| "strata.bin".into(), |n| n.to_string_lossy().into_owned());
        crate::web::download(&name, bytes)
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        use anyhow::Context;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
    }
}

/// The process's resident set size in bytes (`VmRSS` of `/proc/self/status`,
/// Linux); `None` where there is no such file (other systems, a browser).
pub fn rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
