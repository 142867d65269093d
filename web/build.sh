#!/usr/bin/env bash
# Builds the WebAssembly package into web/pkg/: meshcodec.js (an ES module, wasm-bindgen's web
# target), meshcodec_bg.wasm and the TypeScript types; Node 20 and browsers load the same files.
# Also installs web/node_modules (three.js for web/loader.js and the viewer).
# Installs what it needs on a fresh machine: Debian's rustc-web (a compiler whose standard
# library builds for wasm32: -Zbuild-std) and wasm-ld, and the wasm-bindgen command of the
# version Cargo.lock pins.
set -euo pipefail
cd "$(dirname "$0")/.."

as_root=""
[ "$(id -u)" -eq 0 ] || as_root="sudo"
if [ ! -x /usr/bin/cargo ] || [ ! -d /usr/lib/rustlib/src/rust/library ] || ! command -v wasm-ld >/dev/null; then
  $as_root apt-get update -qq
  $as_root apt-get install -y -qq rustc-web cargo-web rust-web-src lld >/dev/null
fi

# The wasm-bindgen command must be the version of the crate the bindings were compiled with.
version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/"/, "", $3); print $3 }' Cargo.lock)
if ! wasm-bindgen --version 2>/dev/null | grep -qx "wasm-bindgen $version"; then
  # Its own lockfile first; where the registry lacks one of the versions it pins, the newest
  # that fits its manifest.
  cargo install -q --locked wasm-bindgen-cli --version "$version" 2>/dev/null ||
    cargo install -q wasm-bindgen-cli --version "$version"
fi

# Debian's cargo and rustc for this build only (the rustup toolchain stays first on PATH);
# RUSTC_BOOTSTRAP lets that stable compiler take -Zbuild-std. RUSTFLAGS replaces
# .cargo/config.toml's target-cpu=native, which means nothing for wasm32. No debug info: the
# module is shipped.
RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 \
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER=wasm-ld \
  CARGO_PROFILE_RELEASE_DEBUG=0 \
  RUSTFLAGS='--cfg getrandom_backend="wasm_js"' \
  /usr/bin/cargo build -q --release -p meshcodec-web --target wasm32-unknown-unknown \
  -Zbuild-std=std,panic_abort --target-dir target/web

# three.js for the loader and the viewer, playwright-core for the browser test: the versions
# web/package-lock.json pins.
(cd web && npm ci --no-audit --no-fund --loglevel=error)

rm -rf web/pkg
wasm-bindgen --target web --out-dir web/pkg --out-name meshcodec --remove-name-section \
  target/web/wasm32-unknown-unknown/release/meshcodec_web.wasm
raw=$(stat -c %s web/pkg/meshcodec_bg.wasm)
zipped=$(gzip -9c web/pkg/meshcodec_bg.wasm | wc -c)
echo "web/pkg/meshcodec_bg.wasm: $raw bytes, $zipped gzip'd"
