#!/usr/bin/env bash
# Similarity invariance of the whole pipeline (issue: reliability): every bundled JSON
# geometry is solved as given, translated by 1e9 times its diameter, and scaled by
# 1e150 and 1e-150 (control points and point clouds mapped by jq; the transformed file
# is the input, rounding included), and the verdicts and Newton iterations per level are
# compared with the original's. Prints a Markdown table; exits 1 on any difference.
#
#   cargo build --release --workspace && bash scripts/invariance.sh target/release/winslow /tmp/inv
#
# Needs jq. A development tool: CI runs the same check on three geometries in
# tests/invariance.rs.
set -euo pipefail
bin=$(realpath "$1")
out=$2
cd "$(dirname "$0")/.."
mkdir -p "$out"
transform() { # file ax ay s
  jq --argjson ax "$2" --argjson ay "$3" --argjson s "$4" '
    def pt: [.[0] * $s + $ax, .[1] * $s + $ay];
    walk(if type == "object" and has("control_points") then .control_points |= map(pt)
         elif type == "object" and has("points") then .points |= map(pt) else . end)' "$1"
}
summary() { # map.json -> "verdict its"
  jq -r '[.report.verdict, ([.report.levels[].newton_iterations] | map(tostring) | join("/"))] | join(" ")' "$1"
}
fail=0
echo "| geometry | diameter | as given | translated 1e9 d | scaled 1e150 | scaled 1e-150 |"
echo "|---|---|---|---|---|---|"
for f in tests/data/*.json tests/data/gismo/*.json; do
  name=$(basename "$f" .json)
  "$bin" solve "$f" -o "$out/$name.map.json" >/dev/null 2>&1 || true
  [ -f "$out/$name.map.json" ] || { echo "| $name | | solve failed | | | |"; fail=1; continue; }
  d=$(jq '.report.diameter' "$out/$name.map.json")
  base=$(summary "$out/$name.map.json")
  row="| $name | $(printf %.3g "$d") | $base |"
  for case in "t $(jq -n "1e9 * $d") $(jq -n "-2e9 * $d") 1" "up 0 0 1e150" "down 0 0 1e-150"; do
    set -- $case
    transform "$f" "$2" "$3" "$4" >"$out/$name.$1.json"
    rm -f "$out/$name.$1.map.json"
    "$bin" solve "$out/$name.$1.json" -o "$out/$name.$1.map.json" >/dev/null 2>"$out/$name.$1.log" || true
    if [ -f "$out/$name.$1.map.json" ]; then
      got=$(summary "$out/$name.$1.map.json")
    else
      got="error: $(tail -1 "$out/$name.$1.log")"
    fi
    if [ "$got" = "$base" ]; then row="$row same |"; else row="$row **$got** |"; fail=1; fi
  done
  echo "$row"
done
exit $fail
