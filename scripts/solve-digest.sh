#!/usr/bin/env bash
# Runs every bundled input through the given `winslow` binary and keeps what it wrote,
# so that the outputs of two builds can be compared byte for byte (a refactor must not
# change results):
#   - every four-sided geometry (tests/data, tests/data/contours, tests/data/gismo,
#     tests/data/gismo/xml), solved with the given extra flags;
#   - every ring (tests/data/rings), solved;
#   - every multipatch layout (tests/data/gismo/xml/multipatch), with fixed and with free
#     interfaces;
#   - every general domain and plane graph (tests/data/domains), laid out automatically;
#   - every volume boundary (tests/data/volumes), a THB map converted (tests/data/thb) and
#     a solve with THB defect correction (`--refinement thb`, puzzle4);
#   - a map improved on its own basis (`solve --start`, Winslow);
#   - the comparison of methods on one basis (`compare --json`);
#   - a short sliding-grid sweep of a ring and the volume lofted from its frames.
# Each JSON output is written with the time-dependent fields (every key ending in
# "seconds") removed and keys sorted (NAME.digest.json); the exit code goes to NAME.exit;
# the progress on stderr goes to NAME.log (timings differ from run to run):
#
#   cargo build -p winslow-cli && cp target/debug/winslow /tmp/winslow-before
#   bash scripts/solve-digest.sh /tmp/winslow-before /tmp/before
#   ... change, rebuild ...
#   bash scripts/solve-digest.sh target/debug/winslow /tmp/after
#   diff -r -x "*.log" /tmp/before /tmp/after && echo identical
#
# Needs jq. A development tool: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
out=$(realpath -m "$2")
shift 2
cd "$(dirname "$0")/.."
mkdir -p "$out"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

digest() { # JSON file -> NAME.digest.json
  jq -S 'walk(if type == "object" then with_entries(select(.key | test("seconds$") | not)) else . end)' \
    "$1" >"$out/$2.digest.json"
}

# run NAME ARGS...: the command's exit code to NAME.exit, stderr to NAME.log, stdout to
# NAME.stdout (kept only for --json commands, whose stdout is the result)
run() {
  local name=$1
  shift
  local rc=0
  "$bin" "$@" >"$scratch/$name.stdout" 2>"$out/$name.log" || rc=$?
  echo "$rc" >"$out/$name.exit"
  echo "$name: exit $rc"
}

solve_to_digest() { # NAME INPUT [FLAGS...]
  local name=$1 input=$2
  shift 2
  run "$name" solve "$input" -o "$scratch/$name.json" "$@"
  [ -f "$scratch/$name.json" ] && digest "$scratch/$name.json" "$name"
  return 0
}

for f in tests/data/*.json tests/data/contours/*.json tests/data/gismo/*.json tests/data/gismo/xml/*.xml; do
  name=$(basename "$f")
  name=${name%.*}
  case "$f" in
    *.xml) name="xml_$name" ;;
    */contours/*) name="contour_$name" ;;
  esac
  solve_to_digest "$name" "$f" "$@"
done

for f in tests/data/rings/*.json; do
  name=$(basename "$f" .json)
  solve_to_digest "ring_$name" "$f" "$@"
done

for f in tests/data/gismo/xml/multipatch/*.xml; do
  name=$(basename "$f" .xml)
  for interfaces in fixed free; do
    solve_to_digest "mp_${name}_$interfaces" "$f" --interfaces "$interfaces" "$@"
  done
done

# general domains and plane graphs, laid out automatically (default settings)
for f in tests/data/domains/*.json; do
  solve_to_digest "domain_$(basename "$f" .json)" "$f"
done

# volumes from their six boundary faces
for f in tests/data/volumes/*.json; do
  solve_to_digest "volume_$(basename "$f" .json)" "$f"
done

# a THB map converted to its exact tensor map (certified again)
run thb_sector convert tests/data/thb/sector_thb.json -o "$scratch/thb_sector.json"
[ -f "$scratch/thb_sector.json" ] && digest "$scratch/thb_sector.json" thb_sector

# the THB defect correction of puzzle4 (it folds without repair): the THB map with its report
solve_to_digest thb_puzzle4 tests/data/gismo/puzzle4.json --refinement thb

# a map improved on its own basis from the certified EGG map of wavy_lid
if [ -f "$scratch/wavy_lid.json" ]; then
  solve_to_digest improve_wavy_lid "$scratch/wavy_lid.json" --start "$scratch/wavy_lid.json" --method winslow
  # the start's path is the scratch folder's, different in every run
  [ -f "$out/improve_wavy_lid.digest.json" ] &&
    jq -S 'del(.report.start)' "$out/improve_wavy_lid.digest.json" >"$scratch/improve.json" &&
    mv "$scratch/improve.json" "$out/improve_wavy_lid.digest.json"
fi

run compare_quarter_annulus compare tests/data/quarter_annulus.json --json
digest "$scratch/compare_quarter_annulus.stdout" compare_quarter_annulus

run sweep_annulus sweep tests/data/rings/eccentric_annulus.json --rotate-inner 3 --steps 6 --fit-tol 1e-3 \
  -o "$scratch/sweep" --quiet
for f in "$scratch"/sweep/*.json; do
  [ -f "$f" ] && digest "$f" "sweep_$(basename "$f" .json)"
done
run loft_annulus loft "$scratch"/sweep/frame_*.json --dz 0.05 -o "$scratch/loft.json"
[ -f "$scratch/loft.json" ] && digest "$scratch/loft.json" loft_annulus
exit 0
