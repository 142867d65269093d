#!/usr/bin/env bash
# Every CAME result and table: the harness's runs of came-paper and came (experiments/came.toml),
# what the tables need beyond them (a mesh of over a million triangles, VRML sizes, came-paper
# streams at 3 and 5 bits per component), then the view-dependent fly-through and views beside
# meshoptimizer (experiments/came-vd.sh), which ends with paper-tables/.
# Run from the repository: bash experiments/came.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --bin experiment -- run experiments/came.toml
cargo run --release --bin experiment -- came-extras
bash experiments/came-vd.sh
