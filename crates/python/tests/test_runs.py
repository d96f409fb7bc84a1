"""improve, compare, sweep and layouts from Python: each the core entry of its command,
checked against the command line's JSON on the same input (WINSLOW_BIN, which
scripts/python-tests.sh builds) and against the mathematics."""

import json
import os
import subprocess

import numpy as np
import pytest

import winslow


@pytest.fixture
def cli():
    path = os.environ.get("WINSLOW_BIN")
    if not path or not os.path.exists(path):
        pytest.skip("WINSLOW_BIN (the winslow binary) is not set: scripts/python-tests.sh sets it")

    def run(*args):
        out = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        assert out.returncode in (0, 3), out.stderr
        return json.loads(out.stdout)

    return run


def test_compare_rows_match_the_cli(data, cli):
    b = data / "quarter_annulus.json"
    cmp = winslow.compare(b, ["egg", "vhm", "qc"])
    ref = cli("compare", b, "--methods", "egg,vhm,qc", "--json", "-q")
    assert [r["method"] for r in cmp["rows"]] == [r["method"] for r in ref["rows"]] == ["egg", "vhm", "qc"]
    assert cmp["basis"] == ref["basis"] and cmp["degree"] == ref["degree"]
    for a, r in zip(cmp["rows"], ref["rows"]):
        assert a["iterations"] == r["iterations"] and a["converged"] == r["converged"], a["method"]
        am, rm = a["measures"], r["measures"]
        assert am["verdict"] == rm["verdict"] and am["shape"] == rm["shape"]
        for k in ["winslow", "liao", "area_orthogonality", "scaled_jacobian_min"]:
            assert am[k] == pytest.approx(rm[k], rel=1e-9, abs=1e-12), (a["method"], k)
        assert isinstance(a["map"], winslow.Map) and a["map"].shape == tuple(rm["shape"])
    # EGG's row is the map x_G: its det J is positive on a sample
    u = np.linspace(0, 1, 30)
    U, V = np.meshgrid(u, u)
    assert cmp["rows"][0]["map"].det_j(U, V).min() > 0


def test_compare_options_are_validated(data):
    with pytest.raises(winslow.WinslowError) as e:
        winslow.compare(data / "quarter_annulus.json", ["egg", "nope"])
    assert e.value.kind == "invalid" and "nope" in e.value.message
    with pytest.raises(winslow.WinslowError):
        winslow.compare(data / "quarter_annulus.json", eps=2.0)
    with pytest.raises(winslow.WinslowError):
        winslow.compare(data / "quarter_annulus.json", qc_hessian="sideways")


def test_sweep_frames(data):
    events = []
    frames = winslow.sweep(data / "rings" / "eccentric_annulus.json", rotate_inner=2.0, steps=3, progress=events.append)
    assert len(frames) == 4 and [f["report"]["frame"] for f in frames] == [0, 1, 2, 3]
    assert len(events) == 4
    m0 = frames[0]["map"]
    for f in frames:
        assert f["report"]["verdict"] == "certified"
        # every frame on frame 0's basis
        assert f["map"].shape == m0.shape
    assert frames[3]["report"]["angle_degrees"] == pytest.approx(6.0)
    # the outer contour (xi = 1) stays; the inner one turned by 6 degrees about its centroid
    v = np.linspace(0, 1, 50, endpoint=False)
    np.testing.assert_allclose(frames[3]["map"].evaluate(1 + 0 * v, v), m0.evaluate(1 + 0 * v, v), atol=1e-12)
    with pytest.raises(winslow.WinslowError):
        winslow.sweep(data / "rings" / "eccentric_annulus.json", rotate_inner=1.0)


def test_layout_matches_the_cli(data, cli):
    d = data / "domains" / "l_bracket.json"
    layout, report = winslow.layout(d)
    ref = cli("layout", d, "--json", "-q")
    assert layout.kind == "multipatch layout"
    assert report["patches"] == ref["patches"] == len(layout.patches())
    assert all(isinstance(p, winslow.Boundary) for p in layout.patches())
    sol = winslow.solve(d)
    assert isinstance(sol, winslow.LayoutSolution) and sol.certified
    assert len(sol.maps) == ref["patches"]
    assert sol.report["auto_layout"]["patches"] == ref["patches"]
    # the layout document solves to the same maps
    again = winslow.solve(layout)
    for a, b in zip(sol.maps, again.maps):
        np.testing.assert_array_equal(a.control_points, b.control_points)
    with pytest.raises(winslow.WinslowError) as e:
        winslow.layout(data / "quarter_annulus.json")
    assert e.value.kind == "document_kind"


def test_layout_solution_round_trip(data, tmp_path):
    sol = winslow.solve(data / "domains" / "l_bracket.json")
    sol.write(tmp_path / "l.json")
    doc = winslow.read(tmp_path / "l.json")
    assert doc.kind == "multipatch result"
    for a, b in zip(doc.maps(), sol.maps):
        np.testing.assert_array_equal(a.control_points, b.control_points)


def test_solve_many_takes_layouts_domains_and_boundaries(data):
    """Layouts and domains among the shapes of solve_many: each result is what
    winslow.solve gives for it, in the order of the inputs; with same_basis=True a layout
    is a WinslowError of its own and the boundaries are still solved."""
    domain = data / "domains" / "l_bracket.json"
    layout, _ = winslow.layout(domain)
    inputs = [domain, data / "quarter_annulus.json", layout]
    seen = []
    many = winslow.solve_many(inputs, workers=2, on_result=lambda i, r: seen.append((i, type(r).__name__)))
    assert [type(r).__name__ for r in many] == ["LayoutSolution", "Solution", "LayoutSolution"]
    assert sorted(seen) == [(0, "LayoutSolution"), (1, "Solution"), (2, "LayoutSolution")]
    for got, one in zip(many, [winslow.solve(i) for i in inputs]):
        assert got.verdict == one.verdict
        maps = got.maps if isinstance(got, winslow.LayoutSolution) else [got.map]
        ones = one.maps if isinstance(one, winslow.LayoutSolution) else [one.map]
        assert len(maps) == len(ones)
        for a, b in zip(maps, ones):
            np.testing.assert_array_equal(a.control_points, b.control_points)
    assert many[0].certified and many[0].report["auto_layout"]["patches"] == len(many[0].maps)
    same = winslow.solve_many([domain, data / "quarter_annulus.json"], same_basis=True)
    assert isinstance(same[0], winslow.WinslowError) and same[0].kind == "invalid"
    assert isinstance(same[1], winslow.Solution) and same[1].certified
    # a warm-started family passes a layout by cold, and goes on after it
    warm = winslow.solve_many([data / "quarter_annulus.json", domain, data / "quarter_annulus.json"],
                              workers=1, warm_start=True)
    assert [type(r).__name__ for r in warm] == ["Solution", "LayoutSolution", "Solution"]


def test_improve_lowers_the_winslow_value(data):
    s = winslow.solve(data / "gismo" / "duck.json")
    imp = winslow.improve(s, method="winslow", boundary=data / "gismo" / "duck.json")
    r = imp.report
    assert imp.certified and r["method"] == "winslow"
    i = r["improvement"]
    assert i["after"]["winslow"] <= i["before"]["winslow"]
    # the boundary control points are the start's (fixed)
    nu, nv = s.map.shape
    P0, P1 = s.map.control_points.reshape(nv, nu, 2), imp.map.control_points.reshape(nv, nu, 2)
    for a, b in [(P0[0], P1[0]), (P0[-1], P1[-1]), (P0[:, 0], P1[:, 0]), (P0[:, -1], P1[:, -1])]:
        np.testing.assert_array_equal(a, b)
    assert max(r["boundary_deviation"]) < 1e-3
    with pytest.raises(winslow.WinslowError):
        winslow.improve(s, method="newton")
