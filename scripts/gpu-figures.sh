#!/bin/bash
# The GPU figures of BENCHMARKS.md ("GPU quadrature", real GPU): the quadrature kernels
# against the CPU assembler at 10^4-10^6 unknowns (f64 element and per-entry Jacobian
# kernels, f32), and the solver end to end on both back ends at refinement 5.
#   bash scripts/gpu-figures.sh BIN OUTDIR
# BIN: a winslow binary; OUTDIR: where the tables go (one file per run). Needs a Vulkan
# adapter (WGPU_BACKEND=vulkan is set here); on lavapipe the 10^6 rows take many minutes.
set -u
B=${1:?usage: gpu-figures.sh BIN OUTDIR}
O=${2:?usage: gpu-figures.sh BIN OUTDIR}
mkdir -p "$O"
export WGPU_BACKEND=vulkan
run() {
  local name=$1 t=$2
  shift 2
  echo "## $*" | tee -a "$O/$name.txt"
  (time timeout "$t" "$@") >>"$O/$name.txt" 2>&1
  echo "rc=$?" >>"$O/$name.txt"
  tail -12 "$O/$name.txt"
}
run quad 200 "$B" bench --backend gpu --sizes 10000,100000,1000000
run quad_entry 80 "$B" bench --backend gpu --gpu-kernel entry --sizes 1000000
run quad_f32 80 "$B" bench --backend gpu --precision f32 --sizes 1000000
G="tests/data/quarter_annulus.json tests/data/wavy_lid.json tests/data/gismo/male_rotor.json tests/data/gismo/puzzle4.json"
# shellcheck disable=SC2086
run e2e_gpu 110 "$B" bench $G --refinements 5 --backend gpu
# shellcheck disable=SC2086
run e2e_cpu 90 "$B" bench $G --refinements 5 --backend cpu
