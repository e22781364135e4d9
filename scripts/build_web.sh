#!/bin/sh
# Builds the workbench for the browser into dist/ (index.html, penumbra.js,
# penumbra_bg.wasm): a static site any web server can serve (docs/web.md). Installs what it
# needs from the registries: the wasm32 target and the wasm-bindgen CLI of the version the
# lock file pins.
set -eu
cd "$(dirname "$0")/.."
rustup target add wasm32-unknown-unknown
version=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"$/\1/p;}' Cargo.lock)
if ! wasm-bindgen --version 2>/dev/null | grep -qF "$version"; then
    cargo install wasm-bindgen-cli --version "$version"
fi
cargo build --profile web --target wasm32-unknown-unknown --bin penumbra
rm -rf dist
wasm-bindgen --target web --no-typescript --out-dir dist --out-name penumbra \
    "${CARGO_TARGET_DIR:-target}/wasm32-unknown-unknown/web/penumbra.wasm"
cp assets/web/index.html dist/
wasm=$(wc -c < dist/penumbra_bg.wasm)
gz=$(gzip -9 -c dist/penumbra_bg.wasm | wc -c)
echo "dist/: penumbra_bg.wasm $wasm bytes ($gz gzipped)"
