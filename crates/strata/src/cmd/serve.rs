//! `strata serve`: the browser bundle (built by `crates/web/build.sh`) and a
//! world directory over HTTP on localhost, for `strata view` in a browser.
//!
//! A Strata store is served as it lies on disk, one request per chunk
//! object (the page streams it: `crates/web/src/stream.rs`); without
//! `--level` the built-in world is served as a store, written once next to
//! the default world's cache (`generated-v…-2048x16384.store`). Static files
//! only, so any static server or object store serves a store the same way.
//! Single byte ranges are served too (`Range: bytes=A-B` → 206 with
//! `Content-Range`; one that is malformed or starts past the end → 416; a
//! request for several ranges gets the whole file): what a store packed
//! into one file would be read with. `bench/web-stream/README.md` measures
//! it against one request per chunk; the page uses one request per chunk.

use anyhow::{Context, bail};
use std::path::{Component, Path, PathBuf};

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// A world directory to offer to the page (`?level=/level/`): a Vangers
    /// world (`world.ini`) or a Strata store (`zarr.json`, streamed chunk by
    /// chunk). Default: the built-in world as a store, made once and cached.
    #[arg(long, value_name = "DIR")]
    pub level: Option<PathBuf>,
    /// Without `--level`: serve no world (the page then generates the
    /// built-in one itself, `?world=WxH&seed=N`).
    #[arg(long, conflicts_with = "level")]
    pub no_level: bool,
    /// Port on 127.0.0.1 (0: any free one; the URL printed says which).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// The bundle directory (`index.html` + `pkg/`). Default: `target/web` of the checkout
    /// this binary was built from, where `crates/web/build.sh` writes.
    #[arg(long, value_name = "DIR", default_value = default_bundle(), hide_default_value = true)]
    pub bundle: PathBuf,
}

/// `target/web` of this checkout, where `crates/web/build.sh` writes.
fn default_bundle() -> &'static str {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/web")
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if !args.bundle.join("index.html").is_file() || !args.bundle.join("pkg").is_dir() {
        bail!(
            "no web bundle in {} (index.html and pkg/): build it with crates/web/build.sh",
            args.bundle.display()
        );
    }
    if let Some(dir) = &args.level
        && !dir.join("world.ini").is_file()
        && !dir.join("zarr.json").is_file()
    {
        bail!(
            "--level {}: no world.ini (a Vangers world) or zarr.json (a Strata store) there",
            dir.display()
        );
    }
    let mut args = args;
    if args.level.is_none() && !args.no_level {
        args.level = Some(default_store()?);
    }
    let server = tiny_http::Server::from_listener(listen(args.port)?, None)
        .map_err(|e| anyhow::anyhow!("cannot serve on 127.0.0.1:{}: {e}", args.port))?;
    let port = server
        .server_addr()
        .to_ip()
        .context("the server has no IP address")?
        .port();
    let query = if args.level.is_some() {
        "?level=/level/"
    } else {
        ""
    };
    println!("strata serve: http://127.0.0.1:{port}/{query}");
    use std::io::Write;
    std::io::stdout().flush()?;
    // A few answering threads: the page fetches several chunks at once.
    std::thread::scope(|scope| {
        for _ in 0..4 {
            scope.spawn(|| {
                while let Ok(request) = server.recv() {
                    let range = request
                        .headers()
                        .iter()
                        .find(|h| h.field.equiv("Range"))
                        .map(|h| h.value.as_str().to_string());
                    let response = respond(&args, request.url(), range.as_deref());
                    if let Err(e) = request.respond(response) {
                        eprintln!("strata serve: answering failed: {e}");
                    }
                }
            });
        }
    });
    Ok(())
}

/// A socket listening on 127.0.0.1:`port` whose connections send at once
/// (TCP_NODELAY, which accepted sockets inherit on Linux): tiny_http writes
/// a response's headers and its body apart, and with Nagle's algorithm the
/// body's last segment waited for the browser's delayed ACK, about 40 ms a
/// request (bench/web-stream/README.md).
fn listen(port: u16) -> anyhow::Result<std::net::TcpListener> {
    use socket2::{Domain, Socket, Type};
    let fail = |e: std::io::Error| anyhow::anyhow!("cannot listen on 127.0.0.1:{port}: {e}");
    let socket = Socket::new(Domain::IPV4, Type::STREAM, None).map_err(fail)?;
    socket.set_tcp_nodelay(true).map_err(fail)?;
    socket.set_reuse_address(true).map_err(fail)?;
    let address = std::net::SocketAddr::from(([127, 0, 0, 1], port));
    socket.bind(&address.into()).map_err(fail)?;
    socket.listen(128).map_err(fail)?;
    Ok(socket.into())
}

/// The built-in world as a store, next to its native cache: written the
/// first time (into a temporary sibling, renamed into place), then reused.
fn default_store() -> anyhow::Result<PathBuf> {
    use crate::world_arg::{cache_dir, cache_root, load_default};
    use strata_level::generate::GenerateParams;
    let params = GenerateParams::default();
    let root = cache_root().context(
        "no cache directory for the built-in world's store (set STRATA_CACHE_DIR or HOME), or pass --level",
    )?;
    let native = cache_dir(&root, &params);
    let dir = native.with_file_name(format!(
        "{}.store",
        native
            .file_name()
            .map_or_else(|| "generated".into(), |n| n.to_string_lossy().into_owned())
    ));
    if dir.join("zarr.json").is_file() {
        return Ok(dir);
    }
    eprintln!(
        "strata serve: writing the built-in world as a store in {} (once)",
        dir.display()
    );
    let start = std::time::Instant::now();
    let world = load_default(&params, Some(&root))?;
    let tmp = dir.with_file_name(format!(".store.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    strata_store::DirStore::create(&tmp, &world, &strata_store::Layout::default())
        .with_context(|| format!("writing the store {}", tmp.display()))?;
    strata_store::DirStore::build_lods(&tmp, &|_, _| {})
        .with_context(|| format!("writing the levels of detail of {}", tmp.display()))?;
    if let Err(e) = std::fs::rename(&tmp, &dir) {
        let _ = std::fs::remove_dir_all(&tmp);
        // Another server may have finished first: that copy is as good.
        if !dir.join("zarr.json").is_file() {
            return Err(e).with_context(|| format!("renaming into {}", dir.display()));
        }
    }
    eprintln!(
        "strata serve: the store is written ({:.1} s)",
        start.elapsed().as_secs_f64()
    );
    Ok(dir)
}

/// The file a URL path names: `/level/…` inside the world directory, the
/// rest inside the bundle; `None` for a path that leaves them.
fn resolve(args: &Args, url: &str) -> Option<PathBuf> {
    let path = url.split(['?', '#']).next().unwrap_or("/");
    let (root, rest) = match (path.strip_prefix("/level/"), &args.level) {
        (Some(rest), Some(level)) => (level.as_path(), rest),
        (Some(_), None) => return None,
        _ => (args.bundle.as_path(), path.trim_start_matches('/')),
    };
    let rest = if rest.is_empty() { "index.html" } else { rest };
    let relative = Path::new(rest);
    if !relative
        .components()
        .all(|c| matches!(c, Component::Normal(_)))
    {
        return None;
    }
    Some(root.join(relative))
}

fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        Some("txt" | "ini") => "text/plain; charset=utf-8",
        Some("png") => "image/png",
        _ => "application/octet-stream",
    }
}

/// What a `Range` header asks of a file of some length.
#[derive(Debug, PartialEq, Eq)]
enum ByteRange {
    /// No range (or one in units other than bytes, or several ranges): the whole file.
    Whole,
    /// Bytes `start..=end`.
    Part(u64, u64),
    /// A malformed byte range, or one that starts past the end (416).
    Unsatisfiable,
}

/// The `Range` header `header` against a file of `len` bytes: `bytes=A-B`,
/// `bytes=A-` or `bytes=-N` (the last N).
fn byte_range(header: Option<&str>, len: u64) -> ByteRange {
    let Some(spec) = header.and_then(|h| h.trim().strip_prefix("bytes=")) else {
        return ByteRange::Whole;
    };
    if spec.contains(',') {
        return ByteRange::Whole;
    }
    let Some((a, b)) = spec.trim().split_once('-') else {
        return ByteRange::Unsatisfiable;
    };
    let number = |t: &str| t.trim().parse::<u64>().ok();
    let last = len.checked_sub(1);
    match (a.trim().is_empty(), number(a), number(b), last) {
        // The last N bytes.
        (true, _, Some(n), Some(last)) if n > 0 => ByteRange::Part(len.saturating_sub(n), last),
        (false, Some(start), None, Some(last)) if b.trim().is_empty() && start <= last => {
            ByteRange::Part(start, last)
        }
        (false, Some(start), Some(end), Some(last)) if start <= end && start <= last => {
            ByteRange::Part(start, end.min(last))
        }
        _ => ByteRange::Unsatisfiable,
    }
}

fn header(name: &str, value: &str) -> tiny_http::Header {
    tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("a valid header")
}

/// Bytes `start..=end` of the file at `path`.
fn read_part(path: &Path, start: u64, end: u64) -> std::io::Result<Vec<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    let mut file = std::fs::File::open(path)?;
    file.seek(SeekFrom::Start(start))?;
    let mut bytes = vec![0; (end - start + 1) as usize];
    file.read_exact(&mut bytes)?;
    Ok(bytes)
}

fn respond(
    args: &Args,
    url: &str,
    range: Option<&str>,
) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    let not_found = || {
        tiny_http::Response::from_data(format!("not found: {url}\n").into_bytes())
            .with_status_code(404)
    };
    let Some((path, len)) = resolve(args, url).and_then(|p| {
        std::fs::metadata(&p)
            .ok()
            .filter(|m| m.is_file())
            .map(|m| (p, m.len()))
    }) else {
        return not_found();
    };
    let (status, bytes, content_range) = match byte_range(range, len) {
        ByteRange::Whole => match std::fs::read(&path) {
            Ok(bytes) => (200, bytes, None),
            Err(_) => return not_found(),
        },
        ByteRange::Part(start, end) => match read_part(&path, start, end) {
            Ok(bytes) => (206, bytes, Some(format!("bytes {start}-{end}/{len}"))),
            Err(_) => return not_found(),
        },
        ByteRange::Unsatisfiable => {
            return tiny_http::Response::from_data(
                format!(
                    "{url}: range {} not satisfiable ({len} bytes)\n",
                    range.unwrap_or("")
                )
                .into_bytes(),
            )
            .with_status_code(416)
            .with_header(header("Content-Range", &format!("bytes */{len}")));
        }
    };
    let mut response = tiny_http::Response::from_data(bytes)
        .with_status_code(status)
        .with_header(header("Content-Type", content_type(&path)))
        .with_header(header("Cache-Control", "no-cache"))
        .with_header(header("Accept-Ranges", "bytes"));
    if let Some(value) = content_range {
        response = response.with_header(header("Content-Range", &value));
    }
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_inside_the_bundle_and_the_level() {
        let args = Args {
            level: Some("/worlds/a".into()),
            no_level: false,
            port: 0,
            bundle: "/b".into(),
        };
        assert_eq!(resolve(&args, "/"), Some("/b/index.html".into()));
        assert_eq!(
            resolve(&args, "/pkg/x.wasm?v=1"),
            Some("/b/pkg/x.wasm".into())
        );
        assert_eq!(
            resolve(&args, "/level/world.ini"),
            Some("/worlds/a/world.ini".into())
        );
        assert_eq!(resolve(&args, "/../etc/passwd"), None);
        assert_eq!(resolve(&args, "/level/../../etc/passwd"), None);
        // A store's chunk objects, as they lie on disk.
        assert_eq!(
            resolve(&args, "/level/heights/c/3/1"),
            Some("/worlds/a/heights/c/3/1".into())
        );
        assert_eq!(resolve(&args, "/level/heights/c/../../../x"), None);
        let without = Args {
            level: None,
            ..args
        };
        assert_eq!(resolve(&without, "/level/world.ini"), None);
    }

    #[test]
    fn byte_ranges() {
        use ByteRange::*;
        assert_eq!(byte_range(None, 100), Whole);
        assert_eq!(byte_range(Some("items=0-5"), 100), Whole);
        assert_eq!(byte_range(Some("bytes=0-9,20-29"), 100), Whole);
        assert_eq!(byte_range(Some("bytes=0-9"), 100), Part(0, 9));
        assert_eq!(byte_range(Some("bytes=90-200"), 100), Part(90, 99));
        assert_eq!(byte_range(Some("bytes=50-"), 100), Part(50, 99));
        assert_eq!(byte_range(Some("bytes=-10"), 100), Part(90, 99));
        assert_eq!(byte_range(Some("bytes=-500"), 100), Part(0, 99));
        assert_eq!(byte_range(Some("bytes=100-"), 100), Unsatisfiable);
        assert_eq!(byte_range(Some("bytes=100-120"), 100), Unsatisfiable);
        assert_eq!(byte_range(Some("bytes=9-3"), 100), Unsatisfiable);
        assert_eq!(byte_range(Some("bytes=x-3"), 100), Unsatisfiable);
        assert_eq!(byte_range(Some("bytes=-0"), 100), Unsatisfiable);
        assert_eq!(byte_range(Some("bytes=0-0"), 0), Unsatisfiable);
    }

    #[test]
    fn ranges_are_served_from_the_file() {
        let dir = std::env::temp_dir().join(format!("strata-serve-range-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("pkg")).unwrap();
        std::fs::write(dir.join("index.html"), b"<html>").unwrap();
        let bytes: Vec<u8> = (0..=255u8).collect();
        std::fs::write(dir.join("pack.bin"), &bytes).unwrap();
        let args = Args {
            level: Some(dir.clone()),
            no_level: false,
            port: 0,
            bundle: dir.clone(),
        };
        let body = |r: tiny_http::Response<std::io::Cursor<Vec<u8>>>| {
            let code = r.status_code().0;
            let range = r
                .headers()
                .iter()
                .find(|h| h.field.equiv("Content-Range"))
                .map(|h| h.value.to_string());
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut r.into_reader(), &mut data).unwrap();
            (code, range, data)
        };
        let (code, range, data) = body(respond(&args, "/level/pack.bin", Some("bytes=16-31")));
        assert_eq!((code, range.as_deref()), (206, Some("bytes 16-31/256")));
        assert_eq!(data, &bytes[16..32]);
        let (code, range, data) = body(respond(&args, "/level/pack.bin", None));
        assert_eq!((code, range, data.len()), (200, None, 256));
        let (code, range, _) = body(respond(&args, "/level/pack.bin", Some("bytes=300-")));
        assert_eq!((code, range.as_deref()), (416, Some("bytes */256")));
        let (code, _, _) = body(respond(&args, "/level/none.bin", Some("bytes=0-1")));
        assert_eq!(code, 404);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
