#!/usr/bin/env bash
# The C0 route on kinked CAD sides: solves the three bundled files tests/data/cad_kinks/*.json
# and N domains of the corpus family `cad-kinks` (degree-2 spline sides with rectangular
# steps and V-notches at C0 knots, `winslow corpus --families cad-kinks`) with the given
# binary and prints, per domain, the exit code, the verdict, the kinks kept of those
# found, the C0 route's continuation (damped solves, refinement rounds, fraction of the
# boundary displacement reached) and the time, then the pass rate: exit 0, certified and
# every kink kept. The domains are written by GEN (default: the binary itself; give a
# newer one to measure an older binary that lacks the family). Extra arguments go to
# `winslow solve`.
#
#   cargo build -p winslow-cli
#   bash scripts/cad-kinks-bench.sh target/debug/winslow
#   N=48 GEN=target/debug/winslow bash scripts/cad-kinks-bench.sh /tmp/winslow-before
#
# Needs jq. A benchmark: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
shift
gen=$(realpath "${GEN:-$bin}")
n=${N:-24}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$gen" corpus --families cad-kinks --per-family "$n" --seed "${SEED:-1}" -o "$tmp/in" -q
echo "| domain | exit | verdict | kinks kept | damped solves | refinements | alpha | s |"
echo "|---|---:|---|---:|---:|---:|---:|---:|"
pass=0
total=0
for f in tests/data/cad_kinks/*.json "$tmp"/in/*.json; do
  name=$(basename "$f" .json)
  rc=0
  "$bin" solve "$f" -o "$tmp/$name.map.json" --json -q "$@" >"$tmp/$name.report.json" 2>/dev/null || rc=$?
  total=$((total + 1))
  if [ ! -s "$tmp/$name.report.json" ]; then
    echo "| $name | $rc | (no report) | | | | | |"
    continue
  fi
  row=$(jq -r --arg name "$name" --arg rc "$rc" '
    (.kinks // []) as $k | (.c0_route // {}) as $c |
    "| \($name) | \($rc) | \(.verdict) | \([$k[] | select(.kept)] | length)/\($k | length) | \($c.continuation_steps // "-") | \($c.refinements // "-") | \(($c.alpha // 0) * 1000 | round / 1000) | \(.seconds * 100 | round / 100) |"' \
    "$tmp/$name.report.json")
  echo "$row"
  if [ "$rc" = 0 ] && jq -e '.verdict == "certified" and ((.kinks // []) | all(.kept))' "$tmp/$name.report.json" >/dev/null; then
    pass=$((pass + 1))
  fi
done
echo
echo "kept and certified: $pass of $total"
