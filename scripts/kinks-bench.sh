#!/usr/bin/env bash
# `--kinks auto` against `--kinks none` on every shared geometry (tests/data,
# tests/data/gismo, tests/data/contours): verdict, basis and its size, time, the kinks
# found and kept, the largest deviation of the map's boundary at a kink (relative to the
# diameter) and the C0 route's own time. Prints a Markdown table; extra arguments go to
# `winslow solve` (both runs).
#
#   cargo build --release -p winslow-cli
#   bash scripts/kinks-bench.sh target/release/winslow
#   bash scripts/kinks-bench.sh target/release/winslow --basis fitted
#   LOCAL="1 2 3" bash scripts/kinks-bench.sh target/release/winslow
#     (instead: the C0 route's final Winslow minimisation on all control points
#     (--kinks-local all) against --kinks-local K, on the geometries with kinks: unknowns,
#     Winslow value, min scaled Jacobian, C0 route and total time)
#
# Needs jq. A benchmark: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
shift
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ -n "${LOCAL:-}" ]; then
  echo "| geometry | spans | verdict | unknowns | Winslow start | Winslow after | min scaled J | C0 route s | total s |"
  echo "|---|---|---|---:|---:|---:|---:|---:|---:|"
  for f in tests/data/notched_square.json tests/data/gismo/plate_with_hole.json tests/data/gismo/rotor_sector.json tests/data/contours/star8.json tests/data/contours/l_shape.json; do
    name=$(basename "$f" .json)
    for k in all $LOCAL; do
      "$bin" solve "$f" -o "$tmp/$name.json" --json -q --kinks-local "$k" "$@" >"$tmp/$name.report.json" 2>"$tmp/$name.log" || true
      jq -r --arg name "$name" --arg k "$k" '
        def f(n): if . == null then "-" else (. * pow(10; n) | round / pow(10; n) | tostring) end;
        "| \($name) | \($k) | \(.verdict) | \(.c0_route.unknowns) | \(.c0_route.winslow[0] | f(6)) | \(.c0_route.winslow[1] | f(6)) | \(.quality.scaled_jacobian.min | f(4)) | \(.c0_route.seconds | f(3)) | \(.seconds | f(3)) |"
      ' "$tmp/$name.report.json"
    done
  done
  exit 0
fi
echo "| geometry | none: verdict | basis | functions | s | auto: verdict | basis | functions | s | kinks kept / found | max deviation at a kink / diam | C0 route s |"
echo "|---|---|---|---:|---:|---|---|---:|---:|---|---:|---:|"
for f in tests/data/*.json tests/data/gismo/*.json tests/data/contours/*.json; do
  name=$(basename "$f" .json)
  row="| $name"
  for mode in none auto; do
    rc=0
    "$bin" solve "$f" -o "$tmp/$name.$mode.json" --kinks "$mode" --json -q "$@" >"$tmp/$name.$mode.report.json" 2>"$tmp/$name.log" || rc=$?
    if [ ! -s "$tmp/$name.$mode.report.json" ]; then
      row="$row | error (exit $rc) | | | "
      continue
    fi
    row="$row | $(jq -r '"\(.verdict) | \(.basis.used) | \(.basis_functions) | \(.seconds * 1000 | round / 1000)"' "$tmp/$name.$mode.report.json")"
  done
  if [ -s "$tmp/$name.auto.report.json" ]; then
    row="$row | $(jq -r '
      def e: if . == null then "-" else (. * 1e3 | round / 1e3 | tostring) end;
      "\([.kinks[] | select(.kept)] | length) / \(.kinks | length) | \(if (.kinks | length) == 0 then "-" else ([.kinks[].deviation] | max / $d | tostring) end) | \(.c0_route.seconds | e)"
    ' --argjson d "$(jq '.diameter' "$tmp/$name.auto.report.json")" "$tmp/$name.auto.report.json")"
  fi
  echo "$row |"
done
