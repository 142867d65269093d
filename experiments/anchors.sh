#!/usr/bin/env bash
# Regenerates paper-tables/emc-vs-anchors.md and emc-rate-distortion.{png,svg}: our codecs at 12
# bits on bunny.ply, armadillo-43k.obj and dragon-50k.obj, Draco (DracoPy) on the same meshes at quantization 8
# to 16 in the same run, then the tables.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tests/libusb.sh
cargo build --release --bins
cargo run --release --bin experiment -- run experiments/anchors.toml
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/pip install --quiet -r experiments/requirements.txt
.venv/bin/python experiments/draco_anchor.py bunny armadillo-43k dragon-50k --quant 8 9 10 11 12 13 14 15 16
cargo run --release --bin experiment -- tables
