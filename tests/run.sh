#!/usr/bin/env bash
# The test suite, from a clean clone: installs what it needs, then runs the Rust tests (unit,
# integration, property, doc), the WebAssembly package's tests in Node, the Python package's
# suite and examples, and the Open3D and Dask checks.
set -euo pipefail
cd "$(dirname "$0")/.."

bash tests/libusb.sh

# The Python side's environment installs beside the Rust build (it is mostly unpacking wheels).
python_log=$(mktemp)
(
  if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
  fi
  .venv/bin/pip install -q --disable-pip-version-check -r tests/requirements.txt
) >"$python_log" 2>&1 &
python_env=$!

# Builds the binaries too (the integration tests and the Python checks below run them); a
# separate `cargo build` first would compile the dependencies twice (the tests' dev-dependencies
# unify other features). Examples are left to clippy's check (.ci/run): the tests do not run them.
cargo test --release --lib --bins --tests
cargo test --release --doc

# The WebAssembly package, built as a user builds it (installing its toolchain), decodes every
# golden stream in Node exactly as the native decoder just built does.
bash web/build.sh
bash tests/chromium.sh
node --test web/test/

if ! wait "$python_env"; then
  cat "$python_log" >&2
  exit 1
fi
# The Python package, built as a user builds it (maturin, release, in this workspace's target/).
.venv/bin/pip install -q --disable-pip-version-check ./python
# -p no:dash: a pytest plugin pulled in by Open3D's dependencies, not used here.
.venv/bin/python -m pytest -q -p no:dash tests/ python/tests/
