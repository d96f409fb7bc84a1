#!/usr/bin/env bash
# The pygismo and splinepy conversions (crates/python/python/winslow/interop.py) tested
# with both packages installed: they go into the test venv of scripts/python-tests.sh
# (which must have run once), then pytest runs crates/python/tests/test_interop.py.
# Not part of scripts/test.sh: CI does not need either package (the tests skip without).
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-$PWD/target}"
venv="$target/python-venv"
if [ ! -x "$venv/bin/python" ]; then
  echo "error: no test venv at $venv: run scripts/python-tests.sh first" >&2
  exit 1
fi
# shellcheck disable=SC1091
source "$venv/bin/activate"
python -m pip install -q --disable-pip-version-check pygismo splinepy
maturin develop -q -m crates/python/Cargo.toml
python -m pytest -q -rs crates/python/tests/test_interop.py "$@"
