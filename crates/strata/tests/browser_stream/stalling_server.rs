//! The stall test's server (`a_server_that_stops_answering_mid_flight`): a
//! small HTTP server over the bundle and a store that stops answering
//! mid-flight for the chunks it is told to.

use std::collections::{HashMap, HashSet};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the stalling server does with a `heights` chunk outside `keep`.
#[derive(Clone, Copy, Debug)]
enum Stall {
    /// The headers and half the body, then nothing.
    PartBody,
    /// Nothing at all (the connection accepted, the request read).
    Silent,
}

/// A small HTTP server over the bundle (`/`) and a store (`/level/`) that
/// stops answering mid-flight for every `heights` chunk outside `keep`
/// (rows of even number: half the body, then silence; odd: no answer at
/// all); its URL and the requests it saw, by path.
pub fn stalling_server(
    bundle: PathBuf,
    store: PathBuf,
    keep: HashSet<(u64, u64)>,
) -> (String, Arc<Mutex<HashMap<String, u32>>>) {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("a listening socket");
    let url = format!("http://{}", listener.local_addr().expect("its address"));
    let requests = Arc::new(Mutex::new(HashMap::new()));
    let counts = requests.clone();
    let keep = Arc::new(keep);
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let (bundle, store, keep, counts) =
                (bundle.clone(), store.clone(), keep.clone(), counts.clone());
            std::thread::spawn(move || answer(stream, &bundle, &store, &keep, &counts));
        }
    });
    (url, requests)
}

/// Answer one request on `stream` (then close it), or stall.
fn answer(
    mut stream: std::net::TcpStream,
    bundle: &Path,
    store: &Path,
    keep: &HashSet<(u64, u64)>,
    counts: &Mutex<HashMap<String, u32>>,
) {
    let mut head = Vec::new();
    let mut buf = [0u8; 4096];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") {
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => return,
            Ok(n) => head.extend_from_slice(&buf[..n]),
        }
    }
    let head = String::from_utf8_lossy(&head);
    let path = head
        .split_whitespace()
        .nth(1)
        .unwrap_or("/")
        .split('?')
        .next()
        .unwrap_or("/")
        .to_string();
    *counts
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(path.clone())
        .or_insert(0) += 1;
    let stall = path
        .strip_prefix("/level/heights/c/")
        .and_then(|cell| {
            let (cy, cx) = cell.split_once('/')?;
            Some((cy.parse::<u64>().ok()?, cx.parse::<u64>().ok()?))
        })
        .filter(|cell| !keep.contains(cell))
        .map(|(cy, _)| {
            if cy % 2 == 0 {
                Stall::PartBody
            } else {
                Stall::Silent
            }
        });
    let file = match path.strip_prefix("/level/") {
        Some(rest) => store.join(rest),
        None if path == "/" => bundle.join("index.html"),
        None => bundle.join(path.trim_start_matches('/')),
    };
    let body = (!path.contains(".."))
        .then(|| std::fs::read(&file).ok())
        .flatten();
    let Some(body) = body else {
        let _ = stream
            .write_all(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n");
        return;
    };
    let kind = match file.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        _ => "application/octet-stream",
    };
    let header = format!(
        "HTTP/1.1 200 OK\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    match stall {
        None => {
            let _ = stream.write_all(header.as_bytes());
            let _ = stream.write_all(&body);
        }
        Some(Stall::PartBody) => {
            let _ = stream.write_all(header.as_bytes());
            let _ = stream.write_all(&body[..body.len() / 2]);
            let _ = stream.flush();
            std::thread::sleep(Duration::from_secs(600));
        }
        Some(Stall::Silent) => std::thread::sleep(Duration::from_secs(600)),
    }
}
