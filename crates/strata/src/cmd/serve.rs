//! `strata serve`: the browser bundle (built by `crates/web/build.sh`) and a
//! world directory over HTTP on localhost, for `strata view` in a browser.

use anyhow::{Context, bail};
use std::path::{Component, Path, PathBuf};

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// A world directory to offer to the page (`?level=/level/`); without it
    /// the page generates the built-in world.
    #[arg(long, value_name = "DIR")]
    pub level: Option<PathBuf>,
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
    {
        bail!("--level {}: no world.ini there", dir.display());
    }
    let server = tiny_http::Server::http(("127.0.0.1", args.port))
        .map_err(|e| anyhow::anyhow!("cannot listen on 127.0.0.1:{}: {e}", args.port))?;
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
    for request in server.incoming_requests() {
        let response = respond(&args, request.url());
        if let Err(e) = request.respond(response) {
            eprintln!("strata serve: answering failed: {e}");
        }
    }
    Ok(())
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

fn respond(args: &Args, url: &str) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    let file = resolve(args, url).and_then(|p| std::fs::read(&p).ok().map(|b| (p, b)));
    match file {
        Some((path, bytes)) => {
            let header =
                tiny_http::Header::from_bytes(&b"Content-Type"[..], content_type(&path).as_bytes())
                    .expect("a valid header");
            let no_cache = tiny_http::Header::from_bytes(&b"Cache-Control"[..], &b"no-cache"[..])
                .expect("a valid header");
            tiny_http::Response::from_data(bytes)
                .with_header(header)
                .with_header(no_cache)
        }
        None => tiny_http::Response::from_data(format!("not found: {url}\n").into_bytes())
            .with_status_code(404),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_stay_inside_the_bundle_and_the_level() {
        let args = Args {
            level: Some("/worlds/a".into()),
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
        let without = Args {
            level: None,
            ..args
        };
        assert_eq!(resolve(&without, "/level/world.ini"), None);
    }
}
