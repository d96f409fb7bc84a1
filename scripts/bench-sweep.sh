#!/usr/bin/env bash
# Sliding-grid benchmark of BENCHMARKS.md (issue 16, paper §11.1, Fig. 22): the male
# rotor turning inside its casing at the paper's 0.003 rad per step for STEPS frames
# (default 1000), each predicted by 5th-order extrapolation, solved by Newton and
# certified, with every 100th frame also solved cold (--cold-every); then the same on
# the Fig. 16-like rotor_lobes_in_circle ring, and the ray seam (the paper's literal
# eta = 0 choice) on the rotor. Prints the per-run summaries and the frames that needed
# more than one Newton iteration. A benchmark: CI does not run it.
#   cargo build --release -p winslow-cli
#   bash scripts/bench-sweep.sh target/release/winslow
set -euo pipefail
W=$(realpath "${1:-target/release/winslow}")
STEPS=${STEPS:-1000}
cd "$(dirname "$0")/.."
OUT=${OUT:-out/sweep-bench}
mkdir -p "$OUT"
DEG=0.17188733853924698 # 0.003 rad
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
run() {
  local name=$1 ring=$2
  shift 2
  rm -rf "${OUT:?}/$name"
  echo "== $name: $ring $*"
  /usr/bin/time -f "  time: wall %e s, user %U s, max RSS %M kB" "$W" sweep "$ring" --rotate-inner "$DEG" \
    --steps "$STEPS" --every 100 --quiet -o "$OUT/$name" "$@" || echo "  (exit $?: some frames not certified or not converged)"
  # frames from 6 on that took more than one Newton iteration
  awk -F, 'NR > 7 && $5 > 1 { n++ } END { printf "  frames >= 6 with more than one Newton iteration: %d\n", n }' "$OUT/$name/sweep.csv"
  awk -F, 'NR > 7 { if ($7 > m) m = $7 } END { printf "  largest residual of a prediction (frames >= 6): %s\n", m }' "$OUT/$name/sweep.csv"
}
run rotor tests/data/rings/male_rotor_in_casing.json --fit-tol 1e-3 --cold-every 100
run lobes tests/data/rings/rotor_lobes_in_circle.json --fit-tol 1e-3 --cold-every 100 --apng "$OUT/lobes.png"
STEPS=${RAY_STEPS:-300} run rotor-ray tests/data/rings/male_rotor_in_casing.json --fit-tol 1e-3 --seam ray
