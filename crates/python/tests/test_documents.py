"""Documents <-> numpy <-> files, bit for bit; evaluation against finite differences and
closed forms."""

import numpy as np
import pytest

import winslow


def bilinear(a, b, c, d, name="quad"):
    """The bilinear map of the quadrilateral a, b, c, d (counter-clockwise) as a degree
    (1, 1) map: x(u, v) = (1-u)(1-v) a + u(1-v) b + uv c + (1-u)v d."""
    k = np.array([0.0, 0.0, 1.0, 1.0])
    cps = np.array([a, b, d, c], dtype=float)  # u fastest: (0,0), (1,0), (0,1), (1,1)
    return winslow.Map((k, k), (1, 1), cps, name=name)


def random_map(seed=1, rational=True):
    """A degree (2, 3) map with an interior knot per direction, random control points
    near a grid and random weights in [0.5, 2] (not bijective in general)."""
    rng = np.random.default_rng(seed)
    ku = np.array([0, 0, 0, 0.3, 1, 1, 1], float)
    kv = np.array([0, 0, 0, 0, 0.6, 1, 1, 1, 1], float)
    nu, nv = len(ku) - 3, len(kv) - 4
    g = np.stack(np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 2, nv)), -1).reshape(-1, 2)
    cps = g + 0.05 * rng.standard_normal(g.shape)
    w = rng.uniform(0.5, 2.0, nu * nv) if rational else None
    return winslow.Map((ku, kv), (2, 3), cps, w, name="random")


def same_map(a, b):
    assert a.name == b.name
    assert a.degrees == b.degrees and a.shape == b.shape
    for x, y in zip(a.knots, b.knots):
        assert x.tobytes() == y.tobytes()
    assert a.control_points.tobytes() == b.control_points.tobytes()
    if a.weights is None:
        assert b.weights is None
    else:
        assert a.weights.tobytes() == b.weights.tobytes()


@pytest.mark.parametrize("ext", ["json", "xml"])
@pytest.mark.parametrize("rational", [False, True])
def test_map_round_trip_bit_for_bit(tmp_path, ext, rational):
    m = random_map(rational=rational)
    path = tmp_path / f"m.{ext}"
    winslow.write(path, m)
    back = winslow.read(path)
    assert isinstance(back, winslow.Map)
    if ext == "xml":  # G+Smo XML has no name: the file stem names it
        assert back.name == "m"
        back = winslow.Map(back.knots, back.degrees, back.control_points, back.weights, name=m.name)
    same_map(m, back)


def test_arrays_in_and_out(tmp_path):
    m = random_map()
    again = winslow.Map(m.knots, m.degrees, m.control_points, m.weights, name=m.name)
    same_map(m, again)
    # the knot vectors are given on any interval: they are mapped to [0, 1]
    ku, kv = m.knots
    scaled = winslow.Map((3 * ku - 1, 2 * kv), m.degrees, m.control_points, m.weights, name=m.name)
    np.testing.assert_allclose(scaled.knots[0], ku, atol=1e-15)


def test_read_files_round_trip(tmp_path, data):
    """Every document kind read from the test data, written and read again, writes the
    same bytes a second time."""
    files = [
        data / "maps" / "quarter_annulus_nurbs.json",
        data / "maps" / "skewed_square.xml",
        data / "maps" / "skewed_square.igs",
        data / "quarter_annulus.json",
        data / "gismo" / "duck.json",
        data / "rings" / "eccentric_annulus.json",
        data / "domains" / "l_bracket.json",
    ]
    for f in files:
        doc = winslow.read(f)
        a, b = tmp_path / f"a_{f.stem}.json", tmp_path / f"b_{f.stem}.json"
        winslow.write(a, doc)
        again = winslow.read(a)
        assert type(again) is type(doc)
        winslow.write(b, again)
        assert a.read_bytes() == b.read_bytes(), f
        assert winslow.parse(a.read_text()).name == again.name


def test_boundary_from_arrays(tmp_path):
    t = np.linspace(0, 1, 21)
    south = np.stack([t, 0 * t], 1)
    east = np.stack([1 + 0 * t, t], 1)
    north = np.stack([t, 1 + 0.2 * np.sin(np.pi * t)], 1)
    west = np.stack([0 * t, t], 1)
    b = winslow.Boundary([south, east, north, west], name="lid")
    for given, side in zip([south, east, north, west], b.sides):
        assert given.tobytes() == side.tobytes()
    b.write(tmp_path / "lid.json")
    back = winslow.read(tmp_path / "lid.json")
    assert isinstance(back, winslow.Boundary)
    for x, y in zip(b.sides, back.sides):
        assert x.tobytes() == y.tobytes()
    s = winslow.solve(back)
    assert s.certified
    # the solved map interpolates the corners
    c = s.map.evaluate(np.array([0.0, 1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0]))
    np.testing.assert_allclose(c, [[0, 0], [1, 0], [1, 1], [0, 1]], atol=1e-12)


def test_bilinear_closed_form():
    a, b, c, d = np.array([0.0, 0.0]), np.array([2.0, 0.1]), np.array([2.5, 1.7]), np.array([-0.2, 1.0])
    m = bilinear(a, b, c, d)
    rng = np.random.default_rng(3)
    u, v = rng.random((2, 7, 5))
    x = m.evaluate(u, v)
    assert x.shape == (7, 5, 2)
    U, V = u[..., None], v[..., None]
    exact = (1 - U) * (1 - V) * a + U * (1 - V) * b + U * V * c + (1 - U) * V * d
    np.testing.assert_allclose(x, exact, atol=1e-14)
    J = m.jacobian(u, v)
    xu = (1 - V) * (b - a) + V * (c - d)
    xv = (1 - U) * (d - a) + U * (c - b)
    np.testing.assert_allclose(J[..., :, 0], xu, atol=1e-14)
    np.testing.assert_allclose(J[..., :, 1], xv, atol=1e-14)
    np.testing.assert_allclose(m.det_j(u, v), xu[..., 0] * xv[..., 1] - xu[..., 1] * xv[..., 0], atol=1e-14)


@pytest.mark.parametrize("which", ["random", "nurbs-file", "solved"])
def test_jacobian_and_det_j_against_finite_differences(which, data):
    if which == "random":
        m = random_map()
    elif which == "nurbs-file":
        m = winslow.read(data / "maps" / "quarter_annulus_nurbs.json")
    else:
        m = winslow.solve(data / "gismo" / "duck.json").map
    rng = np.random.default_rng(7)
    # away from the knots (C^{p-1} there) and from the domain's edges
    u, v = rng.uniform(0.01, 0.99, (2, 200))
    h = 1e-6
    fu = (m.evaluate(u + h, v) - m.evaluate(u - h, v)) / (2 * h)
    fv = (m.evaluate(u, v + h) - m.evaluate(u, v - h)) / (2 * h)
    J = m.jacobian(u, v)
    scale = np.abs(J).max()
    np.testing.assert_allclose(J[:, :, 0], fu, atol=1e-6 * scale)
    np.testing.assert_allclose(J[:, :, 1], fv, atol=1e-6 * scale)
    det_fd = fu[:, 0] * fv[:, 1] - fu[:, 1] * fv[:, 0]
    np.testing.assert_allclose(m.det_j(u, v), det_fd, atol=1e-5 * scale**2)
    np.testing.assert_allclose(m.det_j(u, v), np.linalg.det(J), atol=1e-12 * scale**2)


def test_curve_evaluate_closed_form():
    # the quadratic Bezier curve B(t) = (1-t)^2 P0 + 2t(1-t) P1 + t^2 P2
    p = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 0.5]])
    c = winslow.Curve([0, 0, 0, 1, 1, 1], 2, p)
    t = np.linspace(0, 1, 11)
    T = t[:, None]
    np.testing.assert_allclose(c.evaluate(t), (1 - T) ** 2 * p[0] + 2 * T * (1 - T) * p[1] + T**2 * p[2], atol=1e-14)


def test_mesh_points_lie_on_the_map(data):
    s = winslow.solve(data / "quarter_annulus.json")
    arrays = winslow.mesh(s, structured=(9, 7), meshio=False)
    assert arrays["cells"].shape == (8 * 6, 4) and arrays["cell_type"] == "quad"
    prm = arrays["params"]
    np.testing.assert_allclose(arrays["points"], s.map.evaluate(prm[:, 0], prm[:, 1]), atol=1e-13)
    tri = winslow.mesh(s.map, size=0.2, meshio=False)
    assert tri["cell_type"] == "triangle" and tri["cells"].max() < len(tri["points"])


def test_meshio_mesh_when_installed(data):
    meshio = pytest.importorskip("meshio", reason="meshio is not installed: the arrays are tested instead")
    s = winslow.solve(data / "quarter_annulus.json")
    m = winslow.mesh(s, structured=(5, 4))
    assert isinstance(m, meshio.Mesh) and m.cells[0].type == "quad"


def test_check_certifies_and_finds_folds(data):
    s = winslow.solve(data / "gismo" / "duck.json")
    assert winslow.check(s.map)["verdict"] == "certified"
    # swapping two interior control points folds the map
    cps = s.map.control_points.copy()
    nu, nv = s.map.shape
    i, j = (nv // 2) * nu + 2, (nv // 2) * nu + nu - 3
    cps[[i, j]] = cps[[j, i]]
    folded = winslow.Map(s.map.knots, s.map.degrees, cps, s.map.weights, name="folded")
    c = winslow.check(folded)
    assert c["verdict"] == "folded"
    assert c["certificate"]["min_value_found"] < 0


def test_pickle_round_trip_bit_for_bit(data):
    import pickle

    m = random_map()
    same_map(m, pickle.loads(pickle.dumps(m)))
    s = winslow.solve(data / "quarter_annulus.json")
    back = pickle.loads(pickle.dumps(s))
    assert back.verdict == s.verdict and back.report == s.report
    same_map(s.map, back.map)
    b = winslow.read(data / "quarter_annulus.json")
    assert pickle.loads(pickle.dumps(b)).to_json() == b.to_json()
