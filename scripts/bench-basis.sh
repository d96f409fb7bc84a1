#!/usr/bin/env bash
# Both bases on every shared spline geometry: `winslow solve --basis fitted` against
# `--basis input` (paper §5.2), one table row per geometry and basis: functions, time,
# verdict, Winslow value, min scaled Jacobian, boundary deviation relative to the diameter.
#   cargo build --release -p winslow-cli && bash scripts/bench-basis.sh [target/release/winslow]
# Needs jq. A benchmark: CI does not run it.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/winslow}
out=$(mktemp -d)
echo "| geometry | basis asked | basis used | functions | seconds | verdict | Winslow | min scaled Jacobian | boundary deviation / diameter |"
echo "|---|---|---|---:|---:|---|---:|---:|---:|"
for f in tests/data/gismo/*.json; do
  name=$(basename "$f" .json)
  for basis in fitted input; do
    "$bin" solve "$f" -o "$out/$name.json" --basis "$basis" --json 2>/dev/null >"$out/r.json" || true
    jq -r --arg n "$name" --arg b "$basis" '"| \($n) | \($b) | \(.basis.used) | \(.basis_functions) | \(.seconds*1000|round/1000) | \(.verdict) | \(if .winslow then (.winslow*10000|round/10000) else "-" end) | \(.quality.scaled_jacobian.min*10000|round/10000) | \((.boundary_deviation|max) / .diameter) |"' "$out/r.json"
  done
done
rm -rf "$out"
