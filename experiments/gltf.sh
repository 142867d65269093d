#!/usr/bin/env bash
# Regenerates paper-tables/gltf.md and results/gltf.json: glTF scenes packed by `meshcodec pack`
# beside glTF-Transform's Draco and gltfpack at the same quantization (sizes, glTF-Validator),
# and the time to the first frame and to the full model in headless Chromium at 5 and 25 Mbit/s.
# The public scenes (experiments/gltf/samples.tsv) are downloaded at their commits, or taken
# from $GLTF_SAMPLES. GLTF_ROUNDS (default 3) sets the timing rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --bin meshcodec
bash web/build.sh
bash tests/chromium.sh
(cd web && npm ci --no-audit --no-fund --silent)
(cd experiments/gltf && npm ci --no-audit --no-fund --silent)
node experiments/gltf/table.mjs
