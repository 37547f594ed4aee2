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
wasm-bindgen --target web --no-typescript --out-dir "$out/pkg" \
    target/wasm32-unknown-unknown/release/strata_web.wasm
cp crates/web/www/index.html "$out/"
wasm="$out/pkg/strata_web_bg.wasm"
# Binaryen's wasm-opt (Debian's `binaryen`) when present: -Oz took main's
# bundle from 10.46 MB (3.55 MB gzipped) to 8.14 MB (3.16 MB) in 1.4 CPU
# minutes. The features are those rustc emits for wasm32-unknown-unknown.
# STRATA_WASM_OPT=0 skips it.
if [ "${STRATA_WASM_OPT:-1}" != 0 ] && command -v wasm-opt >/dev/null; then
    echo "wasm-opt -Oz: $(wc -c <"$wasm") bytes before"
    wasm-opt -Oz --enable-bulk-memory --enable-sign-ext --enable-mutable-globals \
        --enable-nontrapping-float-to-int --enable-reference-types --enable-multivalue \
        "$wasm" -o "$wasm.opt"
    mv "$wasm.opt" "$wasm"
else
    echo "no wasm-opt (apt-get install binaryen): the bundle is not shrunk" >&2
fi
echo "bundle: $out ($(wc -c <"$wasm") bytes of wasm, $(gzip -9c "$wasm" | wc -c) gzipped)"
