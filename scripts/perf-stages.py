#!/usr/bin/env python3
"""CPU seconds per stage of a 2D EGG solve, split between the thread that runs the
command and the pool's other threads, and the wall time the samples imply on an idle
machine with as many cores as threads, from `perf script` output of a `perf record
--call-graph dwarf` run (BENCHMARKS.md, "10^6 unknowns on 2 cores: where the time goes"):

    perf record -F 99 --call-graph dwarf,16384 -o qa6.perf winslow bench tests/data/quarter_annulus.json --refinements 6 --linear multigrid --json
    perf script -i qa6.perf -F comm,tid,time,ip,sym --no-inline > qa6.txt
    python3 scripts/perf-stages.py qa6.txt [HZ]

A sample goes to the first stage (in the order of STAGES) one of whose patterns names a
frame of its stack. The work a pool thread steals has no caller frames above the pool:
such a sample goes to the stage of the command thread's sample nearest in time (within
30 ms). A stage whose samples are nearly all on the command thread runs on one core. The
wall-time estimate adds, over 50 and 100 ms windows, the samples of the busiest thread of
the window: what the run would take if no other process took the cores (a loaded machine
stretches the windows, not the samples).
"""
import bisect
import collections
import re
import sys

STAGES = [
    ("fit, levels planned", "Pipeline::plan"),
    ("certificate", "verify::certificate::certify"),
    ("report: quality pass", "verify::quality"),
    ("report: other", "report::Solution::new"),
    ("level finish", "FixedBasisSolve::finish"),
    ("prolongation of the map", "TensorSpline::refined"),
    ("det J of the start", "initial::det_j_min"),
    ("elasticity initial guess", "elasticity"),
    ("GMRES (V-cycles, Jacobian products)", "NonlinearSolver::newton_solve"),
    ("K assembly and hand-over", "take_preconditioner"),
    ("V-cycle set-up", "factor_operator"),
    ("V-cycle set-up", "release_multigrid"),
    ("Jacobian: f32 pack", "Stencil32::pack"),
    ("Jacobian assembly (with F)", "jacobian_operator"),
    ("Jacobian assembly (with F)", "NonlinearSolver::linear_step"),
    ("line-search residual", "NonlinearSolver::newton_step"),
    ("initial residual of a level", "NonlinearSolver::new"),
    ("level set-up", "FixedBasisSolve"),
    ("other Newton", "NonlinearSolver"),
]


def samples(path):
    cur = hdr = None
    for line in open(path):
        if not line.strip():
            if cur is not None:
                yield hdr, cur
            cur = None
        elif not line[0].isspace():
            hdr, cur = line.split(), []
        elif cur is not None:
            parts = line.strip().split(None, 1)
            # generic arguments removed: `NonlinearSolver<P>::step` -> `NonlinearSolver::step`
            frame = parts[1] if len(parts) > 1 else ""
            for _ in range(3):
                frame = re.sub(r"<[^<>]*>", "", frame)
            cur.append(frame)
    if cur:
        yield hdr, cur


def stage(stack):
    return next((name for name, pat in STAGES if any(pat in fr for fr in stack)), None)


def main():
    hz = float(sys.argv[2]) if len(sys.argv) > 2 else 99.0
    recs = sorted(((float(h[2].rstrip(":")), h[1], s) for h, s in samples(sys.argv[1])), key=lambda r: r[0])
    if not recs:
        sys.exit("no samples")
    command = collections.Counter(tid for _, tid, _ in recs).most_common(1)[0][0]
    times, names = [], []
    for t, tid, s in recs:
        name = stage(s) if tid == command else None
        if name:
            times.append(t)
            names.append(name)
    counts = collections.defaultdict(lambda: [0, 0])
    for t, tid, s in recs:
        name = stage(s) if tid == command else None
        if name is None:
            i = bisect.bisect_left(times, t)
            near = [j for j in (i - 1, i) if 0 <= j < len(times)]
            j = min(near, key=lambda j: abs(times[j] - t)) if near else None
            name = names[j] if j is not None and abs(times[j] - t) < 0.03 else "unattributed"
        counts[name][0 if tid == command else 1] += 1
    n = len(recs)
    print(f"{'stage':40s} {'CPU s':>6s} {'share':>6s} {'command thread':>14s} {'other threads':>13s}")
    for name, (a, b) in sorted(counts.items(), key=lambda kv: -sum(kv[1])):
        print(f"{name:40s} {(a + b) / hz:6.2f} {100 * (a + b) / n:5.1f}% {a:14d} {b:13d}")
    print(f"{'total':40s} {n / hz:6.2f}")
    for w in (0.05, 0.1):
        win = collections.defaultdict(collections.Counter)
        for t, tid, _ in recs:
            win[int((t - recs[0][0]) / w)][tid] += 1
        est = sum(max(c.values()) for c in win.values()) / hz
        print(f"wall on idle cores, {1000 * w:.0f} ms windows: {est:.2f} s (samples span {recs[-1][0] - recs[0][0]:.1f} s)")


if __name__ == "__main__":
    main()
