#!/usr/bin/env bash
# Coverage-guided fuzzing of the readers and the validator (fuzz/README.md).
#
#   scripts/fuzz.sh [-r RUNS] [-t SECONDS] [TARGET ...]
#
# Installs what it needs (a C++ compiler for libFuzzer, cargo-fuzz), builds the targets
# of fuzz/ with the pinned *stable* toolchain (`--sanitizer none`: sanitizer coverage
# only, no -Z flags, no nightly), seeds each target's corpus from tests/data, then runs
# the targets one after the other, single job, each until RUNS executions (default
# 1000000) or SECONDS seconds (default 3600), whichever comes first. Prints the
# executions libFuzzer reports per target; logs go to fuzz/logs/, crashing inputs to
# fuzz/artifacts/TARGET/. Exits non-zero when a target crashed.
set -euo pipefail
cd "$(dirname "$0")/.."

RUNS=1000000
SECONDS_MAX=3600
while getopts "r:t:h" opt; do
  case $opt in
    r) RUNS=$OPTARG ;;
    t) SECONDS_MAX=$OPTARG ;;
    *) sed -n '2,12p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
ALL=(json_boundary json_contour json_map gismo_xml iges point_cloud validate)
TARGETS=("${@:-${ALL[@]}}")

if ! command -v c++ >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "== installing g++ (libFuzzer is C++) =="
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq g++ >/dev/null
  else
    echo "error: a C++ compiler is needed to build libFuzzer" >&2
    exit 1
  fi
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
  echo "== installing cargo-fuzz =="
  cargo install cargo-fuzz --locked
fi

echo "== building the fuzz targets ($(rustc --version)) =="
cargo fuzz build --sanitizer none

# Seeds: the valid files of tests/data for each reader (small ones: libFuzzer mutates
# small inputs faster), plus the regression inputs of earlier crashes.
seeds() {
  case $1 in
    json_boundary) ls tests/data/*.json tests/data/gismo/*.json ;;
    json_contour) ls tests/data/contours/*.json ;;
    json_map) ls tests/data/maps/*.json ;;
    gismo_xml) ls tests/data/gismo/xml/*.xml tests/data/maps/*.xml ;;
    iges) ls tests/data/maps/*.igs ;;
    *) ;;
  esac
  if [ -d "tests/data/fuzz/$1" ]; then ls "tests/data/fuzz/$1"/*; fi
}

mkdir -p fuzz/logs
declare -A EXECS TIME STATUS
crashed=0
for t in "${TARGETS[@]}"; do
  corpus=fuzz/corpus/$t
  mkdir -p "$corpus" "fuzz/artifacts/$t"
  for f in $(seeds "$t"); do
    if [ "$(stat -c %s "$f")" -le 16384 ]; then cp -n "$f" "$corpus/" 2>/dev/null || true; fi
  done
  echo "== $t: up to $RUNS executions or ${SECONDS_MAX}s =="
  start=$(date +%s)
  set +e
  RAYON_NUM_THREADS=1 cargo fuzz run --sanitizer none "$t" "$corpus" -- \
    -runs="$RUNS" -max_total_time="$SECONDS_MAX" -max_len=16384 -timeout=20 -rss_limit_mb=4096 \
    -print_final_stats=1 -artifact_prefix="fuzz/artifacts/$t/" >"fuzz/logs/$t.log" 2>&1
  rc=$?
  set -e
  TIME[$t]=$(($(date +%s) - start))
  EXECS[$t]=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "fuzz/logs/$t.log" | grep -o '[0-9]*$' | tail -1)
  if [ -z "${EXECS[$t]}" ]; then
    EXECS[$t]=$(grep -oE '^#[0-9]+' "fuzz/logs/$t.log" | tail -1 | tr -d '#')
  fi
  if [ $rc = 0 ]; then
    STATUS[$t]=ok
  else
    STATUS[$t]="CRASH (exit $rc, see fuzz/logs/$t.log and fuzz/artifacts/$t/)"
    crashed=1
  fi
  grep -E '^Done|stat::number_of_executed_units|SUMMARY|panicked' "fuzz/logs/$t.log" || true
done

echo
echo "== executions per target (libFuzzer's stat::number_of_executed_units) =="
printf '%-15s %12s %8s  %s\n' target executions seconds result
for t in "${TARGETS[@]}"; do
  printf '%-15s %12s %8s  %s\n' "$t" "${EXECS[$t]:-?}" "${TIME[$t]}" "${STATUS[$t]}"
done
exit $crashed
