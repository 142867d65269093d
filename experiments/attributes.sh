#!/usr/bin/env bash
# Regenerates paper-tables/attributes.md (and its checker renders) and appearance-levels.md:
# our lossless codecs with appearance on the shared meshes that have it (pm also with the
# appearance in its splits, emc and emc-ahead also with it in one unit after the last level),
# Draco (DracoPy) on the same meshes in the same run, then the tables.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tests/libusb.sh
cargo build --release --bins
cargo run --release --bin experiment -- run experiments/attributes.toml
cargo run --release --bin experiment -- run experiments/attributes-in-splits.toml
cargo run --release --bin experiment -- run experiments/attributes-unit.toml
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/pip install --quiet -r experiments/requirements.txt
.venv/bin/python experiments/draco_attributes.py bunny-10k-textured spot airplane-colored dragon-res3
cargo run --release --bin experiment -- tables
