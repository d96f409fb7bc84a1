#!/usr/bin/env bash
# The Python package's tests: a virtual environment from the Python registry (maturin,
# numpy, pytest, meshio, dask[distributed]), the extension built into it by `maturin develop` (the dev
# profile, in cargo's target folder), then pytest on crates/python/tests. The CLI is built
# too (WINSLOW_BIN): tests check the package's results against the command line's JSON.
# Installs python3 and its venv module when they are missing and we are root.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! { command -v python3 >/dev/null 2>&1 && python3 -c "import venv, ensurepip" >/dev/null 2>&1; }; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "== installing python3 and python3-venv =="
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 python3-venv >/dev/null
  else
    echo "error: python3 with its venv module is missing and we are not root to install it" >&2
    exit 1
  fi
fi

target="${CARGO_TARGET_DIR:-$PWD/target}"
venv="$target/python-venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
# shellcheck disable=SC1091
source "$venv/bin/activate"
python -m pip install -q --disable-pip-version-check "maturin>=1.9,<2" numpy pytest meshio "dask[distributed]"
maturin develop -q -m crates/python/Cargo.toml
if [ -z "${WINSLOW_BIN:-}" ]; then
  cargo build -q -p winslow-cli
  export WINSLOW_BIN="$target/debug/winslow"
fi
python -m pytest -q -rs crates/python/tests "$@"
