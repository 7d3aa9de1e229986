#!/usr/bin/env bash
# The Python package (python/): built into a virtual environment with the
# dev profile and this repository's target folder (so the library's build
# is shared with `cargo test`), then its pytest suite against the `study`
# command of the same build, and the notebook-style example run end to end.
# Usage: scripts/python-tests.sh   (after `cargo build`; needs PyPI for
# maturin, numpy, polars, pytest, matplotlib and scipy on the first run)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
venv="$root/target/python-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check -r "$root/python/requirements-dev.txt"
# maturin builds into the workspace's target folder; --uv is not assumed.
VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" \
    maturin develop --quiet --manifest-path "$root/python/Cargo.toml"
cd "$root"
"$venv/bin/python" -m pytest -q python/tests
"$venv/bin/python" python/examples/drag_sweep.py "$root/target/drag_sweep.png"
