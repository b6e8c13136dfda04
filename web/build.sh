#!/usr/bin/env bash
# Builds the live book's WebAssembly package: the geosens estimators
# (web/, crate geosens-web) for wasm32-unknown-unknown, with its JavaScript
# glue, into book/src/live/pkg/ (not committed: built here, by .ci/run and by
# book/serve.sh). Installs the wasm32 target and wasm-bindgen-cli at the
# version of the wasm-bindgen crate in Cargo.lock when missing (the glue of
# another version refuses to load).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
version="$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/"/, "", $3); print $3; exit}' Cargo.lock)"
if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  rustup target add wasm32-unknown-unknown
fi
if [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$version" ]; then
  # Not --locked: a crate its lock file pins may be missing from the index.
  cargo install wasm-bindgen-cli --version "$version"
fi
cargo build -p geosens-web --target wasm32-unknown-unknown --release
target_dir="${CARGO_TARGET_DIR:-target}"
out=book/src/live/pkg
rm -rf "$out"
wasm-bindgen --target web --no-typescript --out-dir "$out" \
  "$target_dir/wasm32-unknown-unknown/release/geosens_web.wasm"
echo "built $out ($(du -k "$out/geosens_web_bg.wasm" | cut -f1) KiB of wasm)"
