#!/usr/bin/env bash
# Shrinks each target's corpus in fuzz/corpus/ to the fewest inputs that keep its coverage
# (libFuzzer -merge=1) and packs them into fuzz/corpus.tar.xz, the committed corpus that CI
# replays. Run after bash fuzz/run.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=fuzz/target/x86_64-unknown-linux-gnu/release
for dir in fuzz/corpus/*/; do
  target=$(basename "$dir")
  [ -x "$bin/$target" ] || continue
  fresh=$(mktemp -d)
  "$bin/$target" -merge=1 -timeout=2 -rss_limit_mb=1024 -malloc_limit_mb=1024 "$fresh" "$dir" \
    >"/tmp/minimize-$target.log" 2>&1
  rm -rf "$dir"
  mv "$fresh" "$dir"
  chmod 755 "$dir"
  echo "$target: $(ls "$dir" | wc -l) inputs, $(cat "$dir"/* 2>/dev/null | wc -c) bytes"
done
tar -C fuzz -cJf fuzz/corpus.tar.xz --sort=name --owner=0 --group=0 --numeric-owner \
  --mtime=2026-01-01 corpus
echo "fuzz/corpus.tar.xz: $(wc -c <fuzz/corpus.tar.xz) bytes"
