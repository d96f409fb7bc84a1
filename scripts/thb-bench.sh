#!/usr/bin/env bash
# Local defect correction, tensor versus THB refinement (issue 35): every input solved with
# `--refinement tensor` and `--refinement thb` (both `--repair ${REPAIR:-10}`); one table
# row per input and refinement: functions of the final map, repair rounds, verdict, wall
# time. Inputs: puzzle3, puzzle4, jigsaw01, male_casing_ring and the hard corpus's puzzle
# family (six seeds).
#   cargo build -p winslow-cli && bash scripts/thb-bench.sh [target/debug/winslow]
# Needs jq and bc. A benchmark: CI does not run it.
set -uo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-target/debug/winslow}")
out=$(mktemp -d)
"$bin" corpus -o "$out/corpus" --families puzzle --per-family 6 -q
echo "| input | refinement | functions | rounds | verdict | wall s |"
echo "|---|---|---|---|---|---|"
for f in tests/data/gismo/{puzzle3,puzzle4,jigsaw01,male_casing_ring}.json "$out"/corpus/puzzle-*.json; do
  n=$(basename "$f" .json)
  for r in tensor thb; do
    s=$(date +%s.%N)
    "$bin" solve "$f" -o "$out/${n}_$r.json" --refinement $r --repair "${REPAIR:-10}" --json >"$out/$n-$r.report" 2>/dev/null
    t=$(echo "$(date +%s.%N) - $s" | bc)
    jq -r --arg n "$n" --arg r $r --arg t "$t" \
      '"| \($n) | \($r) | \(.functions // .basis_functions) | \(.thb_rounds // null | if . == null then "" else length end)\(if $r == "tensor" then .repairs else "" end) | \(.verdict) | \($t | tonumber * 100 | round / 100) |"' \
      "$out/$n-$r.report"
  done
done
rm -rf "$out"
