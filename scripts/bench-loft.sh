#!/usr/bin/env bash
# Volumes from slices (BENCHMARKS.md, issue 16, paper §11.1 Fig. 23): the rotor/casing
# ring swept at the paper's 0.003 rad per step to 126 frames, lofted (linear and cubic in
# z) into one volume and certified by the trivariate certificate; prints each command's
# own report and /usr/bin/time's wall, CPU and peak memory. A benchmark: CI does not run it.
#   cargo build --release -p winslow-cli
#   bash scripts/bench-loft.sh target/release/winslow
set -euo pipefail
W=$(realpath "${1:-target/release/winslow}")
cd "$(dirname "$0")/.."
OUT=${OUT:-out/loft-bench}
mkdir -p "$OUT"
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
T='  time: wall %e s, user %U s, sys %S s, max RSS %M kB'
/usr/bin/time -f "$T" "$W" sweep tests/data/rings/male_rotor_in_casing.json --rotate-inner 0.171887 --steps 125 \
  --fit-tol 1e-3 -o "$OUT/frames" --quiet
for interp in linear cubic; do
  echo "loft, $interp:"
  /usr/bin/time -f "$T" "$W" loft "$OUT"/frames/frame_*.json --dz 0.01 --interpolation "$interp" -o "$OUT/rotor-$interp.json"
  echo "check, $interp:"
  /usr/bin/time -f "$T" "$W" check "$OUT/rotor-$interp.json"
done
