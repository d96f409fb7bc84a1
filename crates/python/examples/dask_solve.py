"""Solve shapes on a Dask cluster: `winslow.solve` mapped over the workers, the results
gathered as documents (a `Solution` pickles as its JSON text).

    python crates/python/examples/dask_solve.py [SCHEDULER_ADDRESS]

Without an address it starts a local cluster of two worker processes (one thread each)
and solves the bundled G+Smo shapes; with one (e.g. tcp://host:8786) it uses that
cluster, whose workers need the winslow package installed. Each worker solves with the
GIL released, so a worker with several threads solves that many shapes at once.

`solve_chunks` sends shapes in chunks, one task per chunk solved by `winslow.solve_many`:
where a shape takes milliseconds, one task per shape costs the scheduler and the
transfers more than the solve, and chunks of some tens of shapes make a worker as fast as
`solve_many` in one process (BENCHMARKS.md, "Dask with chunks"); `warm_start=True` solves
each chunk as a family chain (each shape from the previous one's map).
"""

import pathlib
import sys

from dask.distributed import Client, LocalCluster

import winslow

DATA = pathlib.Path(__file__).resolve().parents[3] / "tests" / "data" / "gismo"


def solve_one(text):
    """Solve one boundary given as its document's text: a `Solution`, or the error's
    kind and message (exceptions of one shape do not stop the others)."""
    try:
        return winslow.solve(winslow.parse(text))
    except winslow.WinslowError as e:
        return {"kind": e.kind, "message": e.message}


def solve_chunk(texts, warm_start=False):
    """Solve a chunk of shapes (their documents' texts) by `winslow.solve_many` on one
    thread: a list of `Solution`s, or the error's kind and message for a failing shape."""
    res = winslow.solve_many([winslow.parse(t) for t in texts], workers=1, warm_start=warm_start)
    return [r if isinstance(r, winslow.Solution) else {"kind": r.kind, "message": r.message} for r in res]


def solve_chunks(client, shapes, chunk=32, warm_start=False):
    """Solve `shapes` on the cluster of `client` in chunks of `chunk` shapes (one task
    each), the results in the order of `shapes`."""
    texts = [s.to_json() for s in shapes]
    parts = [texts[i : i + chunk] for i in range(0, len(texts), chunk)]
    futures = client.map(solve_chunk, parts, warm_start=warm_start, pure=False)
    return [r for part in client.gather(futures) for r in part]


def main(address=None, chunk=None):
    shapes = [winslow.read(p) for p in sorted(DATA.glob("*.json"))]
    shapes = [s for s in shapes if isinstance(s, winslow.Boundary)][:8]
    cluster = None if address else LocalCluster(n_workers=2, threads_per_worker=1, processes=True)
    with Client(address or cluster) as client:
        if chunk:
            results = solve_chunks(client, shapes, chunk)
        else:
            futures = client.map(solve_one, [s.to_json() for s in shapes], pure=False)
            results = client.gather(futures)
    if cluster is not None:
        cluster.close()
    for shape, r in zip(shapes, results):
        if isinstance(r, winslow.Solution):
            print(f"{shape.name}: {r.verdict}, {r.map.shape[0]}x{r.map.shape[1]} functions, {r.report['seconds']:.3f} s")
        else:
            print(f"{shape.name}: {r['kind']}: {r['message']}")
    return shapes, results


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
