#!/usr/bin/env bash
# Both bases on every shared spline geometry: `winslow solve --basis fitted` against
# `--basis input` (paper §5.2) and `--basis auto` (the default), and with VARIANTS=levels
# the input basis through its artificial hierarchy (§6.3) against a direct solve from the
# Coons patch (`--levels 1`; since bases of at most 1024 functions are solved directly,
# the two differ only above that); one table row per geometry and variant: functions,
# time, Newton iterations on the finest level, repair rounds, verdict, Winslow value, min
# scaled Jacobian, boundary deviation relative to the diameter.
#   cargo build --release -p winslow-cli && bash scripts/bench-basis.sh [target/release/winslow]
#   (REFINE=2 adds --refine 2 to every solve)
# Needs jq. A benchmark: CI does not run it.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/winslow}
out=$(mktemp -d)
echo "| geometry | basis asked | start | basis used | functions | seconds | finest-level iterations | repairs | verdict | Winslow | min scaled Jacobian | boundary deviation / diameter |"
echo "|---|---|---|---|---:|---:|---:|---:|---|---:|---:|---:|"
for f in tests/data/gismo/*.json; do
  name=$(basename "$f" .json)
  if [ "${VARIANTS:-}" = levels ]; then variants=("input hierarchy" "input direct"); else variants=("fitted hierarchy" "input hierarchy" "auto hierarchy"); fi
  for variant in "${variants[@]}"; do
    set -- $variant
    basis=$1; start=$2
    extra=(); [ "$start" = direct ] && extra=(--levels 1)
    [ -n "${REFINE:-}" ] && extra+=(--refine "$REFINE")
    "$bin" solve "$f" -o "$out/$name.json" --basis "$basis" "${extra[@]}" --json 2>/dev/null >"$out/r.json" || true
    jq -r --arg n "$name" --arg b "$basis" --arg s "$start" '"| \($n) | \($b) | \($s) | \(.basis.used) | \(.basis_functions) | \(.seconds*1000|round/1000) | \(.levels[-1].iterations) | \(.repairs) | \(.verdict) | \(if .winslow then (.winslow*10000|round/10000) else "-" end) | \(.quality.scaled_jacobian.min*10000|round/10000) | \((.boundary_deviation|max) / .diameter) |"' "$out/r.json"
  done
done
rm -rf "$out"
