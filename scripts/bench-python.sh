#!/usr/bin/env bash
# The Python package's benchmarks (BENCHMARKS.md, "Python package and batch runs"): the
# extension and the CLI built with the dev profile (or PROFILE=release), then
# scripts/bench_python.py in the test venv (scripts/python-tests.sh makes it).
# Usage: bash scripts/bench-python.sh [--shapes 1000] [--workers 2]
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-$PWD/target}"
profile="${PROFILE:-dev}"
dir=$([ "$profile" = dev ] && echo debug || echo "$profile")
cargo build -q --profile "$profile" -p winslow-cli
# shellcheck disable=SC1091
source "$target/python-venv/bin/activate"
if [ "$profile" = dev ]; then maturin develop -q -m crates/python/Cargo.toml; else maturin develop -q --release -m crates/python/Cargo.toml; fi
python scripts/bench_python.py --winslow "$target/$dir/winslow" "$@"
