//! What differs between a native window and a browser page, besides the
//! event loop and the device request (in `lib.rs` and [`crate::web`]):
//! where a saved file goes.

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
