#!/usr/bin/env bash
# The automatic layout of general domains (issue 31): the seeded corpus of
# `winslow corpus --general` (N-gons with curved sides, N = 3 ... 12; L, T, U, E and plus
# shapes with sharp or filleted reflex corners; plates with 1-5 holes; plane graphs:
# wiggly squares of 4-60 faces, motor-like sections of 6-48 slots) laid out and solved at the default
# settings: one line per domain (patches, cuts, patch corner angles, verdict, seconds of
# layout and solve together), a table per family and the pass rate (a domain passes when
# every patch is certified). Then the bundled domains of tests/data/domains, each solved
# three times, the best wall time.
#
#   cargo build --release -p winslow-cli
#   bash scripts/domain-bench.sh target/release/winslow [PER_FAMILY] [SEED]
#
# A benchmark: CI does not run it.
set -uo pipefail
bin=$(realpath "$1")
per=${2:-10}
seed=${3:-1}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" corpus --general --per-family "$per" --seed "$seed" --solve
echo
echo "| domain | patches | best of 3 s |"
echo "|---|---:|---:|"
for f in tests/data/domains/*.json; do
  name=$(basename "$f" .json)
  best=""
  for _ in 1 2 3; do
    t0=$(date +%s.%N)
    "$bin" solve "$f" -o "$tmp/$name.json" -q || true
    t1=$(date +%s.%N)
    t=$(echo "$t1 - $t0" | bc -l)
    if [ -z "$best" ] || [ "$(echo "$t < $best" | bc -l)" = 1 ]; then best=$t; fi
  done
  patches=$(grep -o '"face"' "$tmp/$name.json" | wc -l)
  printf "| %s | %s | %.3f |\n" "$name" "$patches" "$best"
done
