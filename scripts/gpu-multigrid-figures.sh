#!/bin/bash
# The figures of BENCHMARKS.md "The multigrid cycle and the Jacobian product on the GPU"
# and "The Newton Jacobian stays on the GPU" on a real GPU: seconds per V-cycle and per
# Jacobian product, CPU against GPU, at 256, 512 and 1000 elements per direction (the
# `multigrid_cycle` example; 1000: 10^6 unknowns per cycle, 2 x 10^6 per product); the
# bytes over the bus of one small solve (quarter_annulus `--refine 3`, `report.backend`,
# with the Jacobian assembled on the device and, `--gpu-jacobian host`, read back and
# uploaded again); and the solver end to end at `--refinements 6` of quarter_annulus and
# male_rotor with `--linear multigrid` on `--backend gpu` (device Jacobian, then
# `--gpu-jacobian host`) and `--backend cpu` (V-cycles, Jacobian products and bytes
# counted in the rows' `backend`).
#   bash scripts/gpu-multigrid-figures.sh BIN EXAMPLE OUTDIR
# BIN: a winslow binary; EXAMPLE: the `multigrid_cycle` example binary
# (`cargo build -p winslow-cli -p winslow-gpu --example multigrid_cycle`:
# $CARGO_TARGET_DIR/debug/examples/multigrid_cycle); OUTDIR: where the tables go (one
# text file per run, the command on its first line, `rc=` on its last; end-to-end runs
# as JSON rows of `winslow bench --json` and a table made from them). Every command
# runs under `timeout` (about 6 minutes in all); one that times out leaves `rc=124` and
# the others still run. Needs a Vulkan adapter with SHADER_F64 (WGPU_BACKEND=vulkan is
# set here); on lavapipe the 1000 row and refinement 6 take many minutes.
set -u
B=${1:?usage: gpu-multigrid-figures.sh BIN EXAMPLE OUTDIR}
X=${2:?usage: gpu-multigrid-figures.sh BIN EXAMPLE OUTDIR}
O=${3:?usage: gpu-multigrid-figures.sh BIN EXAMPLE OUTDIR}
mkdir -p "$O"
export WGPU_BACKEND=vulkan
{
  date -u
  uptime
  nproc
  nvidia-smi -L 2>/dev/null || true
} >"$O/machine.txt" 2>&1
run() {
  local name=$1 t=$2
  shift 2
  echo "## $*" >"$O/$name.txt"
  (/usr/bin/time -f "%e s wall %U s user %S s sys %M KB" timeout "$t" "$@") >>"$O/$name.txt" 2>&1
  echo "rc=$?" >>"$O/$name.txt"
  tail -14 "$O/$name.txt"
}
# a markdown table of the bench rows in $O/$1.txt (JSON lines)
table() {
  python3 - "$O/$1.txt" >"$O/$1.md" <<'PY' || true
import json, sys
keys = ["geometry", "refine", "dofs", "newton", "krylov_mean", "krylov_max", "assembly_s", "solve_s",
        "factor_s", "total_s", "peak_mib", "verdict", "winslow", "scaled_jacobian_min", "backend"]
print("| " + " | ".join(keys) + " |")
print("|" + "---|" * len(keys))
for line in open(sys.argv[1]):
    line = line.strip()
    if not line.startswith("{"):
        continue
    r = json.loads(line)
    print("| " + " | ".join(str(round(r[k], 4)) if isinstance(r.get(k), float) else str(r.get(k)) for k in keys) + " |")
PY
  cat "$O/$1.md"
}
run cycle 90 "$X" 256 512 1000
for jac in device host; do
  run "bus_$jac" 30 "$B" solve tests/data/quarter_annulus.json -o "$O/bus_$jac.json" --refine 3 \
    --backend gpu --linear multigrid --gpu-jacobian "$jac" --json
done
G="tests/data/quarter_annulus.json tests/data/gismo/male_rotor.json"
for be in gpu-device gpu-host cpu; do
  # shellcheck disable=SC2086
  run "e2e_${be}_r6" 75 "$B" bench $G --refinements 6 --backend "${be%%-*}" \
    --gpu-jacobian "$([ "$be" = gpu-host ] && echo host || echo device)" --linear multigrid --json
  table "e2e_${be}_r6"
done
