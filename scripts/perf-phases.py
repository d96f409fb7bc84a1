#!/usr/bin/env python3
"""Share of CPU samples per phase of a 3D solve, from `perf script` output of a
`perf record --call-graph dwarf` run (BENCHMARKS.md, "The EGG Newton step without the
Jacobian"):

    perf record -F 97 --call-graph dwarf,16384 -o perf.data winslow solve ... -q
    perf script -i perf.data -F comm,tid,ip,sym --no-inline > perf.txt
    python3 scripts/perf-phases.py perf.txt

Each sample goes to the first phase whose pattern names a frame of its stack, from the
leaf up; samples without one are listed by their leaf (e.g. faer's `gemm` kernels,
whose stacks are not unwound). The EGG element's samples are then split by the first
kernel named on their stack (the sum-factorised passes, the per-point work).
"""
import collections
import sys

PHASES = [
    ("certificate", "certificate"),
    ("Winslow energy", "WinslowVolume::"),
    ("sparse Cholesky of K", "LinearSolver::cholesky"),
    ("GMRES", "krylov::gmres"),
    ("EGG element", "EggVolume::element"),
    ("addition into the pattern", "VolumeDiscretization::assemble"),
    ("discretization set-up", "VolumeDiscretization::new"),
    ("pattern matrix", "pattern_matrix"),
]


KERNELS = [
    "tensor_points::values",
    "tensor_points::stiffness",
    "tensor_points::integrals",
    "metric::linearised",
    "metric::residual",
    "EggVolume::element_points",
]


def samples(path):
    cur = None
    for line in open(path):
        if not line.strip():
            if cur is not None:
                yield cur
            cur = None
        elif not line[0].isspace():
            cur = []
        elif cur is not None:
            parts = line.strip().split(None, 1)
            cur.append(parts[1] if len(parts) > 1 else "")
    if cur:
        yield cur


def main():
    phases, leaves, kernels, n = collections.Counter(), collections.Counter(), collections.Counter(), 0
    for s in samples(sys.argv[1]):
        n += 1
        name = next((k for fr in s for k, pat in PHASES if pat in fr), None)
        if name is None:
            leaves[s[0] if s else "?"] += 1
            name = "other"
        if name == "EGG element":
            kernels[next((k for fr in s for k in KERNELS if k in fr), "the rest (gathers, allocation)")] += 1
        phases[name] += 1
    for k, v in phases.most_common():
        print(f"{k:32s} {v:7d} {100 * v / n:5.1f} %")
    print(f"{'samples':32s} {n:7d}")
    print("\nEGG element, by kernel:")
    for k, v in kernels.most_common():
        print(f"{k:32s} {v:7d} {100 * v / n:5.1f} %")
    print("\nother, by leaf:")
    for k, v in leaves.most_common(15):
        print(f"{v:7d} {k[:90]}")


if __name__ == "__main__":
    main()
