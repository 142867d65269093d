#!/usr/bin/env bash
# The test suite, from a clean clone: installs what it needs, then runs the Rust tests (unit,
# integration, property, doc) and the Open3D cross-check of the metrics.
set -euo pipefail
cd "$(dirname "$0")/.."

# Open3D's wheel links libusb; Debian ships it as libusb-1.0-0.
if ! ldconfig -p | grep -q 'libusb-1.0.so.0'; then
  as_root=""
  [ "$(id -u)" -eq 0 ] || as_root="sudo"
  $as_root apt-get update -qq
  $as_root apt-get install -y -qq libusb-1.0-0 >/dev/null
fi

cargo build --release --bins
cargo test --release

if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/pip install -q --disable-pip-version-check -r tests/requirements.txt
# -p no:dash: a pytest plugin pulled in by Open3D's dependencies, not used here.
.venv/bin/python -m pytest -q -p no:dash tests/
