#!/usr/bin/env bash
# Mesh benchmarks of BENCHMARKS.md (issue 18): the Fig. 31 structured set-up and the
# unstructured 10^6-triangle meshes, each run REPS times; prints `winslow mesh`'s own
# stage times (meshing stages, quality, check + write) and /usr/bin/time's wall, user
# CPU and peak memory. A benchmark: CI does not run it.
#   cargo build --release -p winslow-cli
#   bash scripts/mesh-bench.sh target/release/winslow
set -euo pipefail
W=$(realpath "${1:-target/release/winslow}")
REPS=${REPS:-3}
cd "$(dirname "$0")/.."
OUT=${OUT:-out/mesh-bench}
mkdir -p "$OUT"
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
"$W" solve tests/data/rings/male_rotor_in_casing.json -o "$OUT/ring.json" -q > /dev/null
"$W" solve tests/data/spiral_channel.json -o "$OUT/spiral.json" -q > /dev/null
"$W" solve tests/data/wavy_lid.json -o "$OUT/lid.json" -q > /dev/null
run() {
  local name=$1
  shift
  for r in $(seq "$REPS"); do
    /usr/bin/time -f "  time: wall %e s, user %U s, sys %S s, max RSS %M kB" "$W" mesh "$@" > "$OUT/$name.log" 2> "$OUT/$name.time"
    echo "$name (run $r, load $(cut -d' ' -f1 /proc/loadavg)):"
    grep -E "nodes / cells|angle min|built in|meshing:" "$OUT/$name.log"
    cat "$OUT/$name.time"
  done
}
run ring-fig31 "$OUT/ring.json" -o "$OUT/ring-fig31.msh" --structured 35x400 --cluster xi:arctan:6
run spiral-fig31 "$OUT/spiral.json" -o "$OUT/spiral-fig31.msh" --structured 401x35 --cluster eta:arctan:6
run spiral-1e6 "$OUT/spiral.json" -o "$OUT/spiral-1e6.msh" --unstructured --size 0.004
run lid-1e6 "$OUT/lid.json" -o "$OUT/lid-1e6.msh" --unstructured --size 0.004
run spiral-curvature "$OUT/spiral.json" -o "$OUT/spiral-curv.msh" --structured 9x41 --equidistribute eta:curvature:1e-4
