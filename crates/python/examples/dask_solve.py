"""Solve shapes on a Dask cluster: `winslow.solve` mapped over the workers, the results
gathered as documents (a `Solution` pickles as its JSON text).

    python crates/python/examples/dask_solve.py [SCHEDULER_ADDRESS]

Without an address it starts a local cluster of two worker processes (one thread each)
and solves the bundled G+Smo shapes; with one (e.g. tcp://host:8786) it uses that
cluster, whose workers need the winslow package installed. Each worker solves with the
GIL released, so a worker with several threads solves that many shapes at once.
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


def main(address=None):
    shapes = [winslow.read(p) for p in sorted(DATA.glob("*.json"))]
    shapes = [s for s in shapes if isinstance(s, winslow.Boundary)][:8]
    cluster = None if address else LocalCluster(n_workers=2, threads_per_worker=1, processes=True)
    with Client(address or cluster) as client:
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
