"""Every kind of bad input is a WinslowError naming its kind."""

import json

import numpy as np
import pytest

import winslow

K = np.array([0.0, 0.0, 1.0, 1.0])
CPS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])


def kind_of(f):
    with pytest.raises(winslow.WinslowError) as e:
        f()
    assert e.value.message == str(e.value)
    return e.value.kind


def test_spline_errors():
    assert kind_of(lambda: winslow.Map((K[::-1], K), (1, 1), CPS)) == "knots"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS[:3])) == "length"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS, [1, 1, -1, 1])) == "weight"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS * np.nan)) == "non_finite"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS.ravel())) == "invalid"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS).evaluate([1.5], [0.5])) == "range"
    assert kind_of(lambda: winslow.Map((K, K), (1, 1), CPS).det_j([0.5, 0.5], [0.5])) == "invalid"


def test_boundary_errors(tmp_path, data):
    t = np.linspace(0, 1, 11)
    sides = [np.stack([t, 0 * t], 1), np.stack([1 + 0 * t, t], 1), np.stack([t, 1 + 0 * t], 1), np.stack([0 * t, t], 1)]
    gap = [s.copy() for s in sides]
    gap[1][:, 0] += 0.1
    assert kind_of(lambda: winslow.solve(winslow.Boundary(gap))) == "corner_gap"
    flipped = [sides[3], sides[2], sides[1], sides[0]]  # south <-> west: clockwise
    assert kind_of(lambda: winslow.solve(winslow.Boundary(flipped))) == "clockwise"
    assert winslow.solve(winslow.Boundary(flipped), reorient=True).certified
    assert kind_of(lambda: winslow.Boundary(sides[:3])) == "invalid"


def test_option_errors(data):
    b = data / "quarter_annulus.json"
    assert kind_of(lambda: winslow.solve(b, tol=-1.0)) == "invalid"
    assert kind_of(lambda: winslow.solve(b, no_such_option=1)) == "invalid"
    assert kind_of(lambda: winslow.solve(b, operator="quadratic")) == "invalid"
    assert kind_of(lambda: winslow.solve(b, growth=0.5)) == "invalid"
    assert kind_of(lambda: winslow.solve_many([b], tol=float("nan"))) == "invalid"


def test_file_errors(tmp_path, data):
    assert kind_of(lambda: winslow.read(tmp_path / "missing.json")) == "io"
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    assert kind_of(lambda: winslow.read(bad)) == "json"
    assert kind_of(lambda: winslow.parse("<xml><unclosed></xml>")) == "xml"
    m = winslow.read(data / "maps" / "skewed_square.json")
    assert kind_of(lambda: winslow.write(tmp_path / "m.png", m)) == "extension"
    ring = winslow.read(data / "rings" / "eccentric_annulus.json")
    assert isinstance(ring, winslow.Document) and ring.kind == "ring"
    assert kind_of(lambda: winslow.check(ring)) == "document_kind"
    graph = tmp_path / "graph.json"
    # a graph document without its vertices is malformed; a triangle reads as a graph
    graph.write_text(json.dumps({"graph": {}}))
    assert kind_of(lambda: winslow.read(graph)) == "json"
    edges = [{"from": 0, "to": 1}, {"from": 1, "to": 2}, {"from": 2, "to": 0}]
    graph.write_text(json.dumps({"name": "g", "graph": {"vertices": [[0, 0], [1, 0], [1, 1]], "edges": edges}}))
    g = winslow.read(graph)
    assert isinstance(g, winslow.Document) and g.kind == "graph"
    with pytest.raises(TypeError):
        winslow.check(42)


def test_solve_many_keeps_failures_in_place(data, tmp_path):
    t = np.linspace(0, 1, 11)
    sides = [np.stack([t, 0 * t], 1), np.stack([1.1 + 0 * t, t], 1), np.stack([t, 1 + 0 * t], 1), np.stack([0 * t, t], 1)]
    out = winslow.solve_many([data / "quarter_annulus.json", winslow.Boundary(sides), tmp_path / "none.json"], workers=2)
    assert isinstance(out[0], winslow.Solution) and out[0].certified
    assert isinstance(out[1], winslow.WinslowError) and out[1].kind == "corner_gap"
    assert isinstance(out[2], winslow.WinslowError) and out[2].kind == "io"
    # a volume's faces are for winslow.solve, one at a time: that shape's error names its kind
    vol = winslow.solve_many([data / "volumes" / "twisted-duct.json", data / "quarter_annulus.json"])
    assert isinstance(vol[0], winslow.WinslowError) and vol[0].kind == "document_kind"
    assert isinstance(vol[1], winslow.Solution) and vol[1].certified
