"""solve and solve_many: the same maps as one at a time, the GIL released, progress,
stopping."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import winslow


def test_solve_matches_the_report(data):
    events = []
    s = winslow.solve(data / "gismo" / "duck.json", progress=events.append)
    assert s.verdict == "certified" and s.certified
    stages = [e["stage"] for e in events]
    assert stages[0] == "fitted" and "level_started" in stages and stages[-1] == "level_finished"
    r = s.report
    assert r["verdict"] == "certified"
    # the pipeline's own time is within the call's, and holds the solver's
    assert r["seconds"] <= s.pipeline_seconds
    # the last level's unknowns: two per free control point
    nu, nv = s.map.shape
    assert r["levels"][-1]["shape"] == [nu, nv]
    # the report's det J minimum is a sampled value of the map's det J
    assert r["det_j_min"] > 0
    u = np.linspace(0, 1, 50)
    U, V = np.meshgrid(u, u)
    assert s.map.det_j(U, V).min() >= r["certificate"]["lower_bound"] - 1e-12


def test_progress_can_stop(data):
    calls = []

    def stop_at_first_iterate(e):
        calls.append(e["stage"])
        return e["stage"] != "iterate"

    with pytest.raises(winslow.WinslowError) as e:
        winslow.solve(data / "gismo" / "duck.json", progress=stop_at_first_iterate)
    assert e.value.kind == "cancelled"
    assert calls[-1] == "iterate" and calls.count("iterate") == 1


def test_progress_exception_propagates(data):
    def boom(e):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError):
        winslow.solve(data / "quarter_annulus.json", progress=boom)


def test_solve_many_equals_solve(data):
    files = [data / "gismo" / f for f in ["duck.json", "cooks_membrane.json", "flapping_beam.json"]] + [
        data / "quarter_annulus.json",
        data / "rings" / "eccentric_annulus.json",
    ]
    one = [winslow.solve(f, levels=3) for f in files]
    seen = []
    many = winslow.solve_many(files, workers=2, on_result=lambda i, r: seen.append(i), levels=3)
    assert sorted(seen) == list(range(len(files)))
    for a, b in zip(one, many):
        assert isinstance(b, winslow.Solution)
        assert a.name == b.name and a.verdict == b.verdict
        assert a.map.shape == b.map.shape
        np.testing.assert_allclose(a.map.control_points, b.map.control_points, rtol=0, atol=1e-9)


def ticks_during(f):
    """How often a second Python thread ran its loop while f() ran, and f's seconds."""
    stop, ticks = threading.Event(), []

    def spin():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=spin)
    t.start()
    time.sleep(0.02)
    t0 = time.perf_counter()
    f()
    t1 = time.perf_counter()
    stop.set()
    t.join()
    return sum(t0 < x < t1 for x in ticks), t1 - t0


def test_the_gil_is_released_during_a_solve(data):
    # puzzle3: a few tenths of a second of solving
    n, seconds = ticks_during(lambda: winslow.solve(data / "gismo" / "puzzle3.json"))
    # the second thread wakes every millisecond; with the GIL held it would run at most
    # when the solve hands it back at its end
    assert n > 0.25 * seconds / 0.001 * 0.2, (n, seconds)
    n, seconds = ticks_during(lambda: winslow.solve_many([data / "gismo" / "puzzle3.json"] * 2, workers=2))
    assert n > 0.25 * seconds / 0.001 * 0.2, (n, seconds)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to oneself needs POSIX")
@pytest.mark.parametrize("many", [False, True])
def test_ctrl_c_stops_a_solve(data, many):
    big = data / "gismo" / "male_casing_ring.json"  # seconds of solving
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        if many:
            winslow.solve_many([big] * 4, workers=2)
        else:
            winslow.solve(big)
    timer.join()
    # stopped at the next event, well before the solve's end
    assert time.perf_counter() - t0 < 3.0


def perturbed_ducks(data, n, eps=0.02, seed=5):
    """n ducks whose side control points are moved by a smooth random field: the sides
    keep their knot vectors."""
    duck = winslow.read(data / "gismo" / "duck.json")
    rng = np.random.default_rng(seed)
    allp = np.concatenate([s.control_points for s in duck.sides])
    lo, L = allp.min(0), np.ptp(allp, 0).max()
    out = []
    for i in range(n):
        c = rng.uniform(-1, 1, (2, 2))
        sides = []
        for s in duck.sides:
            q = (s.control_points - lo) / L
            field = np.stack([np.sin(np.pi * q[:, 0]), np.sin(np.pi * q[:, 1])], 1) @ c
            sides.append(winslow.Curve(s.knots, s.degree, s.control_points + eps * L * field, s.weights))
        out.append(winslow.Boundary(sides, name=f"duck{i}"))
    return out


def test_same_basis_family(data):
    family = perturbed_ducks(data, 4)
    res = winslow.solve_many(family, workers=2, same_basis=True)
    assert all(isinstance(r, winslow.Solution) and r.certified for r in res)
    k0 = res[0].map.knots
    for r in res:
        assert r.report["basis"]["used"] == "input"
        assert all(np.array_equal(a, b) for a, b in zip(r.map.knots, k0))
    # the coefficients differ by the shape: a family of maps on one basis
    assert np.abs(res[1].map.control_points - res[0].map.control_points).max() > 0
    # a shape on another basis (a quarter annulus of other sides) is refused, the rest kept
    mixed = winslow.solve_many(family[:2] + [winslow.read(data / "quarter_annulus.json")], same_basis=True)
    assert isinstance(mixed[0], winslow.Solution) and isinstance(mixed[1], winslow.Solution)
    assert isinstance(mixed[2], winslow.WinslowError) and mixed[2].kind == "invalid"
    with pytest.raises(winslow.WinslowError):
        winslow.solve_many(family, same_basis=True, basis="fitted")
