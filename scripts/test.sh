#!/usr/bin/env bash
# Runs every test of the workspace on a fresh Debian machine with only Rust installed.
# Installs what the suite needs when it is missing and we are root (Mesa's lavapipe
# Vulkan driver for the GPU tests), then: format check, clippy, the docs (no broken
# intra-doc links), the whole test suite, then the Python package's tests in a virtual
# environment (scripts/python-tests.sh; installs python3-venv when missing).
set -euo pipefail
cd "$(dirname "$0")/.."

have_lavapipe() { ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; }
if ! have_lavapipe; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "== installing mesa-vulkan-drivers (lavapipe) =="
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers >/dev/null
  else
    echo "error: Mesa's lavapipe (mesa-vulkan-drivers) is missing and we are not root to install it" >&2
    exit 1
  fi
fi
# wgpu otherwise falls back to GL, which has no f64 in shaders.
export WGPU_BACKEND=vulkan
# GPU tests fail (not skip) when no adapter is found.
export WINSLOW_REQUIRE_GPU=1

echo "== cargo fmt --check =="
cargo fmt --all -- --check
echo "== cargo clippy =="
cargo clippy --workspace --all-targets -- -D warnings
echo "== cargo doc (no broken intra-doc links) =="
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet
echo "== cargo test =="
cargo test --workspace
echo "== Python package (pytest) =="
bash scripts/python-tests.sh
