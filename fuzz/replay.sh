#!/usr/bin/env bash
# Builds the fuzz targets and runs each once over its committed corpus, seeds and regression
# inputs (no fuzzing): a decoder or reader that panics, overruns 2 s or 1 GiB on any of them
# fails. Installs cargo-fuzz if it is missing. Used by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz --version 0.13.2 --locked
fi
# The committed corpus is one archive (fuzz/corpus.tar.xz); work on it unpacked.
if [ ! -d fuzz/corpus ] && [ -f fuzz/corpus.tar.xz ]; then
  tar -C fuzz -xJf fuzz/corpus.tar.xz
fi
export RUSTC_BOOTSTRAP=1 # cargo-fuzz passes -Z flags; this lets the stable toolchain take them
cargo fuzz build -s none
bin=fuzz/target/x86_64-unknown-linux-gnu/release
for source in fuzz/fuzz_targets/*.rs; do
  target=$(basename "$source" .rs)
  inputs=()
  for kind in corpus seeds regressions; do
    [ -d "fuzz/$kind/$target" ] && inputs+=("fuzz/$kind/$target")
  done
  count=$(find "${inputs[@]}" -type f | wc -l)
  if ! "$bin/$target" -runs=0 -timeout=2 -rss_limit_mb=1024 -malloc_limit_mb=1024 \
    "${inputs[@]}" >"/tmp/replay-$target.log" 2>&1; then
    tail -n 40 "/tmp/replay-$target.log"
    echo "fuzz replay: $target failed" >&2
    exit 1
  fi
  echo "fuzz replay: $target, $count inputs, clean"
done
