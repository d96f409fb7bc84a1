"""pygismo and splinepy conversions (skipped, and said so, when the package is not
installed; scripts/python-interop.sh installs both): round trips give the same arrays bit
for bit, and the other library evaluates the map as winslow does."""

import numpy as np
import pytest

import winslow


@pytest.fixture
def duck_map(data):
    return winslow.solve(data / "gismo" / "duck.json").map


@pytest.fixture
def rational_map():
    """A quarter annulus as an exact NURBS (degree 2 in v)."""
    r = np.sqrt(0.5)
    ku, kv = np.array([0, 0, 1, 1.0]), np.array([0, 0, 0, 1, 1, 1.0])
    P, w = [], []
    for (x, y), wj in [((1, 0), 1), ((1, 1), r), ((0, 1), 1)]:
        for rad in (1.0, 2.0):
            P.append([rad * x, rad * y])
            w.append(wj)
    return winslow.Map((ku, kv), (1, 2), np.array(P), np.array(w), name="annulus")


def same_arrays(a, b):
    assert a.degrees == b.degrees and a.shape == b.shape
    assert all(np.array_equal(x, y) for x, y in zip(a.knots, b.knots))
    assert np.array_equal(a.control_points, b.control_points)
    assert (a.weights is None) == (b.weights is None)
    if a.weights is not None:
        assert np.array_equal(a.weights, b.weights)


def random_params(n=200, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1, n), rng.uniform(0, 1, n)


def test_gismo_round_trip(duck_map):
    gs = pytest.importorskip("pygismo", reason="pygismo is not installed (scripts/python-interop.sh)")
    g = duck_map.to_gismo()
    assert isinstance(g, gs.nurbs.gsTensorBSpline2)
    back = winslow.Map.from_gismo(g)
    same_arrays(back, duck_map)
    u, v = random_params()
    assert np.array_equal(back.evaluate(u, v), duck_map.evaluate(u, v))
    # G+Smo evaluates the same map (its own algorithm: equal up to rounding)
    xg = g.eval(np.stack([u, v]))
    np.testing.assert_allclose(xg.T, duck_map.evaluate(u, v), rtol=0, atol=1e-12)


def test_gismo_multipatch(data):
    gs = pytest.importorskip("pygismo", reason="pygismo is not installed (scripts/python-interop.sh)")
    sol = winslow.solve(data / "domains" / "l_bracket.json")
    mp = winslow.interop.to_gismo(sol)
    assert isinstance(mp, gs.core.gsMultiPatch) and mp.nPatches() == len(sol.maps)
    for a, b in zip(winslow.interop.from_gismo(mp), sol.maps):
        same_arrays(a, b)


def test_gismo_refuses_a_rational_map(rational_map):
    pytest.importorskip("pygismo", reason="pygismo is not installed (scripts/python-interop.sh)")
    with pytest.raises(ValueError, match="rational"):
        rational_map.to_gismo()


@pytest.mark.parametrize("which", ["duck", "rational"])
def test_splinepy_round_trip(which, duck_map, rational_map):
    splinepy = pytest.importorskip("splinepy", reason="splinepy is not installed (scripts/python-interop.sh)")
    m = duck_map if which == "duck" else rational_map
    s = m.to_splinepy()
    assert isinstance(s, splinepy.NURBS if m.weights is not None else splinepy.BSpline)
    back = winslow.Map.from_splinepy(s)
    same_arrays(back, m)
    u, v = random_params()
    assert np.array_equal(back.evaluate(u, v), m.evaluate(u, v))
    np.testing.assert_allclose(s.evaluate(np.stack([u, v], 1)), m.evaluate(u, v), rtol=0, atol=1e-12)
    if which == "rational":
        # the exact annulus: |x| is 1 + u on the whole map
        np.testing.assert_allclose(np.linalg.norm(s.evaluate(np.stack([u, v], 1)), axis=1), 1 + u, atol=1e-14)


def test_missing_package_is_an_import_error(duck_map, monkeypatch):
    import importlib

    real = importlib.import_module

    def fake(name, *a, **k):
        if name in ("pygismo", "splinepy"):
            raise ImportError(name)
        return real(name, *a, **k)

    monkeypatch.setattr(importlib, "import_module", fake)
    with pytest.raises(ImportError, match="pip install pygismo"):
        duck_map.to_gismo()
    with pytest.raises(ImportError, match="pip install splinepy"):
        duck_map.to_splinepy()
