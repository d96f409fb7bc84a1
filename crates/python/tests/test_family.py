"""Shape families: the previous map as the start of the next shape (solve(start=...),
solve_many(warm_start=True)): the same certified verdict and, on the same basis, the same
discrete map as a cold solve within the solver's tolerance."""

import numpy as np
import pytest

import winslow
from test_solve import perturbed_ducks


def diameter(m):
    p = m.control_points
    return np.ptp(p, 0).max()


def test_warm_start_gives_the_cold_map(data):
    family = perturbed_ducks(data, 3, seed=11)
    first = winslow.solve(family[0])
    assert first.certified
    for b in family[1:]:
        cold = winslow.solve(b)
        warm = winslow.solve(b, start=first)
        assert warm.report["warm_start"] == {"used": True}, warm.report.get("warm_start")
        assert warm.verdict == cold.verdict == "certified"
        # the same basis, and the same discrete EGG map within the nonlinear tolerance
        assert warm.map.shape == cold.map.shape == first.map.shape
        assert all(np.array_equal(a, b) for a, b in zip(warm.map.knots, cold.map.knots))
        d = np.abs(warm.map.control_points - cold.map.control_points).max()
        assert d <= 1e-6 * diameter(cold.map), d
        # the boundary is the input's: the sides' points where they sit
        u = np.linspace(0, 1, 41)
        for side, (uu, vv) in zip(b.sides, [(u, 0 * u), (1 + 0 * u, u), (u, 1 + 0 * u), (0 * u, u)]):
            t = side.knots[0] + u * (side.knots[-1] - side.knots[0])
            np.testing.assert_allclose(warm.map.evaluate(uu, vv), side.evaluate(t), rtol=0,
                                       atol=1e-12 * diameter(cold.map))
        # the warm solve took no more Newton steps than the cold solve's finest level
        assert warm.report["solve"]["iterations"] <= cold.report["levels"][-1]["iterations"]


def test_a_start_that_does_not_apply_is_solved_cold(data):
    duck = perturbed_ducks(data, 1)[0]
    other = winslow.solve(data / "quarter_annulus.json")
    s = winslow.solve(duck, start=other.map)
    assert s.report["warm_start"]["used"] is False
    assert "basis" in s.report["warm_start"]["reason"]
    assert s.certified and "levels" in s.report
    ring = winslow.solve(data / "rings" / "eccentric_annulus.json", start=other)
    assert ring.report["warm_start"]["used"] is False and ring.certified


def test_solve_many_warm_start_chains(data):
    family = perturbed_ducks(data, 6, seed=3)
    cold = winslow.solve_many(family, workers=2)
    warm = winslow.solve_many(family, workers=2, warm_start=True)
    used = [("warm_start" in r.report and r.report["warm_start"]["used"]) for r in warm]
    # two chains of three: the first of each cold, the others from the previous map
    assert used == [False, True, True, False, True, True], used
    for c, w in zip(cold, warm):
        assert c.verdict == w.verdict == "certified"
        assert c.map.shape == w.map.shape
        assert np.abs(c.map.control_points - w.map.control_points).max() <= 1e-6 * diameter(c.map)
    # same_basis and warm_start together: one basis, every map from the previous one
    both = winslow.solve_many(family, workers=1, warm_start=True, same_basis=True)
    assert [r.report.get("warm_start", {}).get("used", False) for r in both] == [False] + [True] * 5


def test_solve_many_takes_a_generator_of_a_family(data):
    """A Python generator of shapes (a family produced on the fly) gives the list's
    results bit for bit; one path is not an iterable of shapes."""
    family = perturbed_ducks(data, 4, seed=5)
    listed = winslow.solve_many(family, workers=2, warm_start=True)
    generated = winslow.solve_many((b for b in family), workers=2, warm_start=True)
    assert len(generated) == len(listed) == 4
    for a, b in zip(listed, generated):
        assert a.verdict == b.verdict
        assert np.array_equal(a.map.control_points, b.map.control_points)
    with pytest.raises(winslow.WinslowError) as e:
        winslow.solve_many(str(data / "gismo" / "duck.json"))
    assert e.value.kind == "invalid"
