"""Benchmarks of the Python package (BENCHMARKS.md, "Python package and batch runs").

1. A family of N perturbed ducks (tests/data/gismo/duck.json, 12 shape parameters: a
   smooth displacement field applied to the control points of the four sides) solved
   and certified through `winslow.solve_many` on `--workers` threads, against N
   invocations of the CLI (`winslow solve`, `--workers` at a time) and one
   `winslow batch --jobs workers`.
   `--warm` instead: the family through `solve_many` cold and with `warm_start=True`
   (each shape from the previous shape's map, `workers` chains), and `winslow batch`
   with and without `--warm-start`.
   `--dask` instead: the family's throughput per worker on a local `dask.distributed`
   cluster of `--workers` single-threaded worker processes (`winslow.solve` mapped over
   the shapes' documents, then `solve_many` over chunks of `--chunk` shapes per task),
   against one thread of `solve_many` (issue 34: within 20 %).
2. The Python call overhead of `winslow.solve` on a 100-function map
   (cooks_membrane: 10 x 10 functions): the wall time of the call against the wall
   time of the pipeline inside it (`Solution.pipeline_seconds`), summed over 200 calls.

Usage: python scripts/bench_python.py --winslow PATH/TO/winslow [--shapes 1000] [--workers 2] [--warm | --dask [--chunk 50]]
"""

import argparse
import json
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import winslow

ROOT = pathlib.Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"


def family(n, seed=0, eps=0.02):
    """n ducks, each with a displacement d(x) = eps L sum_k c_k psi_k(s, t) of 12
    coefficients c_k ~ U(-1, 1) over six smooth modes in each coordinate."""
    duck = winslow.read(DATA / "gismo" / "duck.json")
    sides = duck.sides
    allp = np.concatenate([s.control_points for s in sides])
    lo, hi = allp.min(0), allp.max(0)
    L = (hi - lo).max()
    rng = np.random.default_rng(seed)

    def modes(p):
        s, t = ((p - lo) / L).T
        return np.stack([np.sin(np.pi * s), np.sin(np.pi * t), np.sin(2 * np.pi * s), np.sin(2 * np.pi * t),
                         np.sin(np.pi * s) * np.sin(np.pi * t), np.cos(np.pi * s) * np.cos(np.pi * t)], 1)

    out = []
    for i in range(n):
        c = rng.uniform(-1, 1, (6, 2))
        new = []
        for s in sides:
            p = s.control_points
            q = p + eps * L * modes(p) @ c
            new.append(winslow.Curve(s.knots, s.degree, q, s.weights))
        out.append(winslow.Boundary(new, name=f"duck_{i:04d}"))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--winslow", required=True, help="the winslow binary")
    ap.add_argument("--shapes", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--overhead-only", action="store_true")
    ap.add_argument("--warm", action="store_true", help="cold against warm-started family solves only")
    ap.add_argument("--dask", action="store_true", help="throughput per worker on a local Dask cluster only")
    ap.add_argument("--chunk", type=int, default=50, help="shapes per Dask task in the chunked run of --dask")
    a = ap.parse_args()
    if a.dask:
        dask_rows(a)
        return
    if a.warm:
        warm_rows(a)
        return
    if not a.overhead_only:
        family_rows(a)
    overhead()


def solve_text(text):
    """Solve one shape given as its document's text (on a Dask worker): its verdict."""
    return winslow.solve(winslow.parse(text)).verdict


def solve_chunk_text(texts):
    """Solve a chunk of shapes (their documents' texts) by one thread of solve_many (on
    a Dask worker): their verdicts."""
    res = winslow.solve_many([winslow.parse(t) for t in texts], workers=1)
    return [r.verdict if isinstance(r, winslow.Solution) else "error" for r in res]


def dask_rows(a):
    """Shapes per second per worker: one thread of solve_many, then a local Dask cluster
    of `workers` single-threaded processes mapping `winslow.solve` over the documents,
    one task per shape, then `solve_many` over chunks of `--chunk` shapes per task."""
    from dask.distributed import Client, LocalCluster

    shapes = family(a.shapes)
    t0 = time.perf_counter()
    res = winslow.solve_many(shapes, workers=1)
    alone = len(shapes) / (time.perf_counter() - t0)
    ok = sum(isinstance(r, winslow.Solution) and r.certified for r in res)
    print(f"solve_many, 1 worker: {alone:.2f} shapes/s ({ok} of {len(shapes)} bijective)")
    texts = [s.to_json() for s in shapes]
    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        # the workers import winslow and solve one shape each before the clock starts
        client.gather(client.map(solve_text, texts[: a.workers], pure=False))
        t0 = time.perf_counter()
        verdicts = client.gather(client.map(solve_text, texts, pure=False))
        dt = time.perf_counter() - t0
        parts = [texts[i : i + a.chunk] for i in range(0, len(texts), a.chunk)]
        t0 = time.perf_counter()
        chunked = [v for part in client.gather(client.map(solve_chunk_text, parts, pure=False)) for v in part]
        dt_chunked = time.perf_counter() - t0
    for what, dt, verdicts in (("one task per shape", dt, verdicts),
                               (f"chunks of {a.chunk} shapes per task", dt_chunked, chunked)):
        per_worker = len(shapes) / dt / a.workers
        ok = sum(v in ("certified", "degenerate-corner") for v in verdicts)
        print(f"Dask, {a.workers} worker processes, {what}: {len(shapes) / dt:.2f} shapes/s, {per_worker:.2f} "
              f"per worker ({per_worker / alone:.2f} of one solve_many thread; {ok} bijective)")
    print(f"load average: {os.getloadavg()}")


def warm_rows(a):
    """The family cold and warm-started, through solve_many and winslow batch."""
    shapes = family(a.shapes)
    for warm in (False, True):
        t0 = time.perf_counter()
        res = winslow.solve_many(shapes, workers=a.workers, warm_start=warm)
        dt = time.perf_counter() - t0
        ok = sum(isinstance(r, winslow.Solution) and r.certified for r in res)
        used = sum(isinstance(r, winslow.Solution) and r.report.get("warm_start", {}).get("used", False) for r in res)
        print(f"solve_many(warm_start={warm}): {len(shapes)} shapes on {a.workers} workers: {dt:.2f} s, "
              f"{ok} bijective, {used} warm-started")
        if warm:
            errs = [np.abs(c.map.control_points - w.map.control_points).max() / np.ptp(c.map.control_points, 0).max()
                    for c, w in zip(cold, res) if c.map.shape == w.map.shape]
            print(f"  largest distance warm - cold map (relative to the size): {max(errs):.2e} "
                  f"over {len(errs)} shapes on the same basis")
        cold = res
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        lines = [json.dumps({"name": s.name, "document": json.loads(s.to_json())}) for s in shapes]
        (tmp / "family.jsonl").write_text("\n".join(lines) + "\n")
        for warm in (False, True):
            t0 = time.perf_counter()
            subprocess.run([a.winslow, "batch", "--manifest", str(tmp / "family.jsonl"), "--jobs", str(a.workers),
                            "-q", "-o", str(tmp / f"batch-{warm}")] + (["--warm-start"] if warm else []), check=False)
            print(f"winslow batch --jobs {a.workers}{' --warm-start' if warm else ''}: {time.perf_counter() - t0:.2f} s")
    print(f"load average: {os.getloadavg()}")


def family_rows(a):
    shapes = family(a.shapes)
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        t0 = time.perf_counter()
        res = winslow.solve_many(shapes, workers=a.workers)
        rows["solve_many"] = time.perf_counter() - t0
        ok = sum(isinstance(r, winslow.Solution) and r.certified for r in res)
        print(f"solve_many: {len(shapes)} shapes on {a.workers} workers: {rows['solve_many']:.2f} s, {ok} bijective")
        inputs = tmp / "in"
        inputs.mkdir()
        for s in shapes:
            s.write(inputs / f"{s.name}.json")
        files = sorted(str(p) for p in inputs.iterdir())
        outs = tmp / "cli"
        outs.mkdir()
        t0 = time.perf_counter()
        running = []
        for f in files:
            out = outs / pathlib.Path(f).name
            running.append(subprocess.Popen([a.winslow, "solve", f, "-o", str(out), "-q"]))
            if len(running) >= a.workers:
                running.pop(0).wait()
        for p in running:
            p.wait()
        rows["cli"] = time.perf_counter() - t0
        cli_ok = sum(json.loads((outs / pathlib.Path(f).name).read_text())["report"]["verdict"]
                     in ("certified", "degenerate-corner") for f in files if (outs / pathlib.Path(f).name).exists())
        print(f"CLI: {len(files)} invocations, {a.workers} at a time: {rows['cli']:.2f} s, {cli_ok} bijective")
        t0 = time.perf_counter()
        subprocess.run([a.winslow, "batch", *files, "--jobs", str(a.workers), "-q", "-o", str(tmp / "batch")],
                       check=False)
        rows["batch"] = time.perf_counter() - t0
        print(f"winslow batch --jobs {a.workers}: {rows['batch']:.2f} s")
        print(f"solve_many vs CLI invocations: {rows['cli'] / rows['solve_many']:.2f}x")
        print(f"load average: {os.getloadavg()}")


def overhead():
    """The call overhead on a 100-function map."""
    b = winslow.read(DATA / "gismo" / "cooks_membrane.json")
    s = winslow.solve(b)
    wall, inside = 0.0, 0.0
    for _ in range(200):
        t0 = time.perf_counter()
        s = winslow.solve(b)
        wall += time.perf_counter() - t0
        inside += s.pipeline_seconds
    nu, nv = s.map.shape
    print(f"overhead on a {nu}x{nv}-function map: solve {wall / 200 * 1e3:.3f} ms per call, "
          f"pipeline {inside / 200 * 1e3:.3f} ms: overhead {100 * (wall - inside) / inside:.2f} %")
    print(f"load average: {os.getloadavg()}")


if __name__ == "__main__":
    main()
