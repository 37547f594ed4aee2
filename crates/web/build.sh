#!/usr/bin/env bash
# Build the browser bundle of the viewer into target/web (index.html + pkg/):
#   crates/web/build.sh            # then: cargo run --release -- serve
# Needs the wasm32-unknown-unknown target and wasm-bindgen-cli at the
# version of wasm-bindgen in Cargo.lock; both are installed when missing.
set -euo pipefail
cd "$(dirname "$0")/../.."
version=$(grep -A1 '^name = "wasm-bindgen"$' Cargo.lock | sed -n 's/^version = "\(.*\)"/\1/p')
rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown ||
    rustup target add wasm32-unknown-unknown
if [ "$(wasm-bindgen --version 2>/dev/null | cut -d' ' -f2)" != "$version" ]; then
    # --locked pins the CLI's own lock file, whose versions a crates.io
    # mirror may not have yet; resolving afresh is the fallback.
    cargo install wasm-bindgen-cli --locked --version "$version" ||
        cargo install wasm-bindgen-cli --version "$version"
fi
# The page's ?compare results name the revision they were built from, as
# native results do (only strata-web reads it, so only it rebuilds).
export STRATA_SOURCE_REVISION="${STRATA_SOURCE_REVISION:-$(git describe --always --dirty --tags 2>/dev/null || echo unknown)}"
# Line tables (the native release profile's) would double the .wasm.
CARGO_PROFILE_RELEASE_DEBUG=false \
    cargo build --release --target wasm32-unknown-unknown -p strata-web
out=target/web
rm -rf "$out/pkg"
mkdir -p "$out"
# Without the name section (function names, for stack traces only): 10.63
# MB of .wasm become 9.28 (3.61 MB gzipped become 3.23). Binaryen's
# wasm-opt -Oz (Debian's 108) made a bundle that Chromium refuses to start
# (`WebAssembly.Table.set(): Argument 1 is invalid`), so it is not used.
wasm-bindgen --target web --no-typescript --remove-name-section --remove-producers-section \
    --out-dir "$out/pkg" target/wasm32-unknown-unknown/release/strata_web.wasm
cp crates/web/www/index.html crates/web/www/decode-worker.js "$out/"
wasm="$out/pkg/strata_web_bg.wasm"
echo "bundle: $out ($(wc -c <"$wasm") bytes of wasm, $(gzip -9c "$wasm" | wc -c) gzipped)"
