#!/usr/bin/env bash
# Puzzle necks and hair-thin gaps: solves N domains of the corpus families `jigsaw`
# (unit-square jigsaw pieces, one to three tabs per side, necks rounded at 1/30 to 1/8 of
# the tab radius, dense point clouds) and `pinched` (a channel pinched to a gap of 3e-4 of
# its length) with the given binary, each under a wall-clock limit of LIMIT seconds
# (default 60), and prints per domain the exit code, the verdict, the kinks found and
# kept, the rounded corners that are no kinks (`roundings`), the functions of the final
# basis (THB functions of a THB map), the wall time and the CPU time (user + system),
# then how many certified within 30 s. FAMILIES (default jigsaw,pinched) picks the families; extra arguments go to
# `winslow solve` (e.g. `--kinks none` or `--kinks 60`).
#
#   cargo build -p winslow-cli
#   N=8 bash scripts/jigsaw-bench.sh target/debug/winslow
#   N=8 FAMILIES=jigsaw bash scripts/jigsaw-bench.sh target/debug/winslow --kinks none
#
# Needs jq and timeout. A benchmark: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
shift
n=${N:-8}
limit=${LIMIT:-60}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" corpus --families "${FAMILIES:-jigsaw,pinched}" --per-family "$n" --seed "${SEED:-1}" -o "$tmp/in" -q
echo "| domain | exit | verdict | kinks kept/found | roundings | functions | s | CPU s |"
echo "|---|---:|---|---:|---:|---:|---:|---:|"
fast=0
total=0
for f in "$tmp"/in/*.json; do
  name=$(basename "$f" .json)
  rc=0
  start=$(date +%s.%N)
  TIMEFORMAT='%U %S'
  { time timeout "$limit" "$bin" solve "$f" -o "$tmp/$name.map.json" --json -q "$@" >"$tmp/$name.report.json" 2>/dev/null || rc=$?; } 2>"$tmp/$name.time"
  secs=$(echo "$(date +%s.%N) - $start" | bc)
  cpu=$(awk '{ printf "%.1f", $1 + $2 }' "$tmp/$name.time")
  total=$((total + 1))
  if [ ! -s "$tmp/$name.report.json" ]; then
    printf '| %s | %s | (no report%s) | | | | %.1f | %s |\n' "$name" "$rc" "$([ "$rc" = 124 ] && echo ", timed out")" "$secs" "$cpu"
    continue
  fi
  row=$(jq -r --arg name "$name" --arg rc "$rc" --arg s "$secs" --arg cpu "$cpu" '
    (.solve.kinks // .kinks // []) as $k |
    "| \($name) | \($rc) | \(.verdict) | \([$k[] | select(.kept)] | length)/\($k | length) | \((.solve.roundings // .roundings // []) | length) | \(.functions // .basis_functions // "-") | \($s | tonumber * 10 | round / 10) | \($cpu) |"' \
    "$tmp/$name.report.json")
  echo "$row"
  if [ "$rc" = 0 ] && jq -e '.verdict == "certified"' "$tmp/$name.report.json" >/dev/null &&
    [ "$(echo "$secs < 30" | bc)" = 1 ]; then
    fast=$((fast + 1))
  fi
done
echo
echo "certified within 30 s: $fast of $total"
