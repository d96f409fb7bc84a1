#!/usr/bin/env bash
# The hard corpus's puzzle and gap (clearance) families, tensor repair (the default) versus
# THB refinement (issue 35): every shape solved with `winslow solve F -o OUT --json` and with
# `--refinement thb` added; one table row per shape and refinement: functions of the final
# map, wall seconds, verdict. Runs longer than ${TIMEOUT:-600} s are cut (verdict "timeout").
#   cargo build -p winslow-cli && bash scripts/thb-corpus.sh [target/debug/winslow] [tensor|thb|both]
# Needs jq and bc. A benchmark: CI does not run it.
set -uo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-target/debug/winslow}")
which=${2:-both}
out=$(mktemp -d)
"$bin" corpus -o "$out/corpus" --families puzzle,clearance --per-family 6 -q
echo "| shape | refinement | functions | wall s | verdict |"
echo "|---|---|---|---|---|"
for f in "$out"/corpus/puzzle-*.json "$out"/corpus/clearance-*.json; do
  n=$(basename "$f" .json)
  for r in tensor thb; do
    [ "$which" = both ] || [ "$which" = "$r" ] || continue
    extra=()
    [ "$r" = thb ] && extra=(--refinement thb)
    s=$(date +%s.%N)
    timeout "${TIMEOUT:-600}" "$bin" solve "$f" -o "$out/${n}_$r.json" "${extra[@]}" --json >"$out/$n-$r.report" 2>/dev/null
    rc=$?
    t=$(echo "$(date +%s.%N) - $s" | bc)
    if [ $rc -eq 124 ]; then
      echo "| $n | $r | | $(printf %.1f "$t") | timeout |"
      continue
    fi
    jq -r --arg n "$n" --arg r $r --arg t "$t" \
      '"| \($n) | \($r) | \(.functions // .basis_functions) | \($t | tonumber * 10 | round / 10) | \(.verdict) |"' \
      "$out/$n-$r.report" 2>/dev/null || echo "| $n | $r | | $(printf %.1f "$t") | exit $rc |"
  done
done
rm -rf "$out"
