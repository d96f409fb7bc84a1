#!/usr/bin/env bash
# Similarity invariance of the whole pipeline (issues: reliability, 30): every bundled
# document kind is solved as given, translated by 1e9 times its diameter, and scaled by
# 1e150 and 1e-150 (control points and point clouds mapped by jq, G+Smo XML control
# points by scripts/similar_xml.py; the transformed file is the input, rounding
# included), and the verdicts and Newton iterations are compared with the original's:
#   - every four-sided JSON geometry (tests/data, tests/data/gismo): per level;
#   - every ring (tests/data/rings): per level;
#   - every multipatch layout (tests/data/gismo/xml/multipatch), fixed and free
#     interfaces: every patch's verdict and levels, and the free stage's iterations;
#   - a sliding-grid sweep of a ring (centre of rotation mapped too): every frame's
#     verdict, Newton iterations and linear solves; and the volume lofted from its
#     frames (heights mapped too): its verdict, shape and rounds.
# Prints a Markdown table per kind; exits 1 on any difference.
#
#   cargo build --release --workspace && bash scripts/invariance.sh target/release/winslow /tmp/inv
#
# Needs jq and python3. A development tool: CI runs the same check on smaller cases in
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

# compare NAME BASE DIR CMD...: run CMD for each case (its output path is $out/NAME.CASE.*),
# summarise with the shell function in $summarise
cases() { # diameter -> the three transformations as "name ax ay s"
  echo "t $(jq -n "1e9 * $1") $(jq -n "-2e9 * $1") 1"
  echo "up 0 0 1e150"
  echo "down 0 0 1e-150"
}

echo
echo "| ring | diameter | as given | translated 1e9 d | scaled 1e150 | scaled 1e-150 |"
echo "|---|---|---|---|---|---|"
for f in tests/data/rings/*.json; do
  name=ring_$(basename "$f" .json)
  "$bin" solve "$f" -o "$out/$name.map.json" >/dev/null 2>&1 || true
  [ -f "$out/$name.map.json" ] || { echo "| $name | | solve failed | | | |"; fail=1; continue; }
  d=$(jq '.report.diameter' "$out/$name.map.json")
  base=$(summary "$out/$name.map.json")
  row="| $name | $(printf %.3g "$d") | $base |"
  while read -r c ax ay s; do
    transform "$f" "$ax" "$ay" "$s" >"$out/$name.$c.json"
    rm -f "$out/$name.$c.map.json"
    "$bin" solve "$out/$name.$c.json" -o "$out/$name.$c.map.json" >/dev/null 2>"$out/$name.$c.log" || true
    if [ -f "$out/$name.$c.map.json" ]; then got=$(summary "$out/$name.$c.map.json"); else got="error: $(tail -1 "$out/$name.$c.log")"; fi
    if [ "$got" = "$base" ]; then row="$row same |"; else row="$row **$got** |"; fail=1; fi
  done < <(cases "$d")
  echo "$row"
done

mp_summary() { # multipatch result -> "verdicts its free-its"
  jq -r '[(.report.verdicts | join(",")), ([.patches[].report.solve.levels[]?.newton_iterations] | map(tostring) | join("/")),
          (.report.free.iterations // "-" | tostring)] | join(" ")' "$1"
}
echo
echo "| layout | interfaces | as given | translated 1e9 d | scaled 1e150 | scaled 1e-150 |"
echo "|---|---|---|---|---|---|"
for f in tests/data/gismo/xml/multipatch/*.xml; do
  for it in fixed free; do
    name=mp_$(basename "$f" .xml)_$it
    "$bin" solve "$f" --interfaces "$it" -o "$out/$name.map.json" >/dev/null 2>&1 || true
    [ -f "$out/$name.map.json" ] || { echo "| $name | $it | solve failed | | | |"; fail=1; continue; }
    d=$(jq '.report.layout.diameter' "$out/$name.map.json")
    base=$(mp_summary "$out/$name.map.json")
    row="| $name | $it | $base |"
    while read -r c ax ay s; do
      python3 scripts/similar_xml.py "$f" "$ax" "$ay" "$s" >"$out/$name.$c.xml"
      rm -f "$out/$name.$c.map.json"
      "$bin" solve "$out/$name.$c.xml" --interfaces "$it" -o "$out/$name.$c.map.json" >/dev/null 2>"$out/$name.$c.log" || true
      if [ -f "$out/$name.$c.map.json" ]; then got=$(mp_summary "$out/$name.$c.map.json"); else got="error: $(tail -1 "$out/$name.$c.log")"; fi
      if [ "$got" = "$base" ]; then row="$row same |"; else row="$row **$got** |"; fail=1; fi
    done < <(cases "$d")
    echo "$row"
  done
done

# a sliding grid of the eccentric annulus (inner circle about (0.25, 0.1)) and its loft
sweep_summary() { # sweep dir -> frames "verdict its solves;..."
  jq -r '[.frames[] | "\(.verdict) \(.newton_iterations) \(.linear_solves)"] | join(";")' "$1/sweep.json"
}
loft_summary() {
  jq -r '[.report.verdict, (.report.shape | map(tostring) | join("x")), ([.report.rounds[] | "\(.verdict)/\(.offending_elements)/\(.inserted_z | length)"] | join(";"))] | join(" ")' "$1"
}
sweep_case() { # NAME FILE ax ay s
  local name=$1 f=$2 ax=$3 ay=$4 s=$5
  rm -rf "$out/$name.sweep" "$out/$name.loft.json"
  "$bin" sweep "$f" --rotate-inner 3 --steps 6 --fit-tol 1e-3 --center "$(jq -n "0.25 * $s + $ax"),$(jq -n "0.1 * $s + $ay")" \
    -o "$out/$name.sweep" --quiet 2>"$out/$name.sweep.log" || true
  [ -f "$out/$name.sweep/sweep.json" ] || { echo "error: $(tail -1 "$out/$name.sweep.log")"; return; }
  "$bin" loft "$out/$name.sweep"/frame_*.json --dz "$(jq -n "0.05 * $s")" --z0 "$(jq -n "1e9 * $s")" \
    -o "$out/$name.loft.json" --quiet 2>"$out/$name.loft.log" || true
  local loft="error: $(tail -1 "$out/$name.loft.log")"
  [ -f "$out/$name.loft.json" ] && loft=$(loft_summary "$out/$name.loft.json")
  echo "$(sweep_summary "$out/$name.sweep"), loft: $loft"
}
echo
echo "| sweep and loft | as given | translated 1e9 d | scaled 1e150 | scaled 1e-150 |"
echo "|---|---|---|---|---|"
f=tests/data/rings/eccentric_annulus.json
base=$(sweep_case sweep_base "$f" 0 0 1)
row="| eccentric_annulus, 6 steps of 3 degrees | $base |"
while read -r c ax ay s; do
  transform "$f" "$ax" "$ay" "$s" >"$out/sweep.$c.json"
  got=$(sweep_case "sweep_$c" "$out/sweep.$c.json" "$ax" "$ay" "$s")
  if [ "$got" = "$base" ]; then row="$row same |"; else row="$row **$got** |"; fail=1; fi
done < <(cases 2)
echo "$row"
exit $fail
