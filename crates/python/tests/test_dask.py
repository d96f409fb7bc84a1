"""The Dask example (crates/python/examples/dask_solve.py) on a local cluster of two
worker processes: the gathered solutions are the maps of local solves."""

import importlib.util
import pathlib

import numpy as np
import pytest

import winslow

pytest.importorskip("dask.distributed", reason="dask[distributed] is not installed")

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_solve.py"


@pytest.mark.parametrize("chunk", [None, 3])
def test_dask_example_gathers_the_local_maps(chunk):
    """One task per shape, and chunks of three shapes per task (the last one shorter):
    every result is the local solve's, in the order of the shapes."""
    spec = importlib.util.spec_from_file_location("dask_solve", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    shapes, results = mod.main(chunk=chunk)
    assert len(shapes) >= 4 and len(results) == len(shapes)
    for shape, r in zip(shapes, results):
        assert isinstance(r, winslow.Solution), r
        local = winslow.solve(shape)
        assert r.verdict == local.verdict and r.map.shape == local.map.shape
        np.testing.assert_allclose(r.map.control_points, local.map.control_points, rtol=0, atol=1e-9)
