#!/usr/bin/env bash
# Regenerates paper-tables/came-vd.md: CAME's view-dependent fronts on far, middle and near
# views of bunny.ply, dragon-50k and the million-triangle mesh, and along the fly-through, beside
# meshoptimizer's simplifier (PyPI, in .venv) at the tolerance of each view, in the same run.
# Run from the repository: bash experiments/came-vd.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --bins
cargo run --release --bin experiment -- came-fly
cargo run --release --bin experiment -- came-vd
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/pip install --quiet -r experiments/requirements.txt
(cd experiments && ../.venv/bin/python meshopt_vd.py)
cargo run --release --bin experiment -- tables
