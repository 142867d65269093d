#!/usr/bin/env bash
# Fuzzes the targets one after another, each for SECONDS (default 60), with the limits the
# decoders promise (2 s and 1 GiB an input), and prints each target's executions and findings.
# Runs without a sanitizer (FUZZING.md: the little unsafe code, emc's slab lanes, checks every
# access in this build), and libFuzzer runs several times as many inputs a second without
# AddressSanitizer. The working corpus grows in fuzz/corpus/
# (not committed); crashes land in fuzz/artifacts/<target>/.
# Usage: bash fuzz/run.sh [SECONDS] [TARGET...]
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cd fuzz/fuzz_targets && ls *.rs | sed 's/\.rs$//')
fi
# The committed corpus is one archive (fuzz/corpus.tar.xz); work on it unpacked.
if [ ! -d fuzz/corpus ] && [ -f fuzz/corpus.tar.xz ]; then
  tar -C fuzz -xJf fuzz/corpus.tar.xz
fi
export RUSTC_BOOTSTRAP=1 # cargo-fuzz passes -Z flags; this lets the stable toolchain take them
if ! cargo fuzz build -s none; then
  echo "fuzz/run.sh: the targets did not build (cargo-fuzz installed? FUZZING.md)" >&2
  exit 1
fi
# The binaries are run directly, so that editing the sources meanwhile rebuilds nothing.
bin=fuzz/target/x86_64-unknown-linux-gnu/release
mkdir -p fuzz/logs
for target in "${targets[@]}"; do
  mkdir -p "fuzz/corpus/$target" "fuzz/artifacts/$target"
  inputs=("fuzz/corpus/$target")
  [ -d "fuzz/seeds/$target" ] && inputs+=("fuzz/seeds/$target")
  [ -d "fuzz/regressions/$target" ] && inputs+=("fuzz/regressions/$target")
  "$bin/$target" -artifact_prefix="fuzz/artifacts/$target/" "${inputs[@]}" \
    -max_total_time="$seconds" -max_len=4096 -timeout=2 -rss_limit_mb=1024 -malloc_limit_mb=1024 \
    -print_final_stats=1 >"fuzz/logs/$target.log" 2>&1
  status=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "fuzz/logs/$target.log" | grep -o '[0-9]*$')
  crashes=$(ls "fuzz/artifacts/$target" 2>/dev/null | wc -l)
  echo "$target: ${runs:-?} executions in ${seconds} s, exit $status, ${crashes} saved crash inputs"
done
