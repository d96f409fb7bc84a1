#!/usr/bin/env python3
"""The volume boundary test geometries of tests/data/volumes (formats.md, "Volume
boundary"), made from closed forms (deterministic; no randomness, so no seed needed):

  twisted-duct      a square duct twisted by 90 degrees along its axis
  curved-pipe       a bent pipe of annular-sector cross-section: exact NURBS (a circular
                    arc of the cross-section revolved by 60 degrees)
  bulged-hex        the unit cube with its top face strongly bulged up
  bracket           a block whose top face has a deep concave groove
  blade-passage     a turbine-blade-like passage between two cambered blades, three
                    slices with growing stagger and twist interpolated linearly in z
                    (a linear loft), given by the six faces of that volume

Each is a trivariate net P(i, j, k) (with weights W(i, j, k)) on knot vectors per
direction; the faces are its six boundary layers, so shared edges agree exactly.

  python3 scripts/volume-geometries.py tests/data/volumes

Not bundled, for the size benchmark (BENCHMARKS.md, issue 33), written when named:

  twisted-duct-fine the twisted duct on 3 x 3 x 8 elements: --refine 3 gives
                    24 x 24 x 64 elements, 112,320 unknowns

  python3 scripts/volume-geometries.py out twisted-duct-fine
"""
import json
import math
import os
import sys


def open_knots(p, n_el):
    return [0.0] * (p + 1) + [k / n_el for k in range(1, n_el)] + [1.0] * (p + 1)


def greville(kv, p):
    n = len(kv) - p - 1
    return [sum(kv[i + 1:i + p + 1]) / p for i in range(n)]


SIDES = [("west", 0, 0), ("east", 0, 1), ("south", 1, 0), ("north", 1, 1), ("bottom", 2, 0), ("top", 2, 1)]


def faces_of(degrees, knots, point, weight=None):
    """Six faces of the net point(i, j, k) (weights weight(i, j, k) or none)."""
    n = [len(knots[d]) - degrees[d] - 1 for d in range(3)]
    out = {}
    for name, d, v in SIDES:
        ps, pt = [x for x in range(3) if x != d]
        cps, ws = [], []
        for jt in range(n[pt]):
            for is_ in range(n[ps]):
                ijk = [0, 0, 0]
                ijk[d] = 0 if v == 0 else n[d] - 1
                ijk[ps], ijk[pt] = is_, jt
                cps.append(list(point(*ijk)))
                if weight:
                    ws.append(weight(*ijk))
        out[name] = {
            "degree": [degrees[ps], degrees[pt]],
            "knots": [knots[ps], knots[pt]],
            "control_points": cps,
            "weights": ws if weight and any(w != 1.0 for w in ws) else None,
        }
    return out


def sampled(degrees, elements, f):
    """The net of the map f(u, v, w) at the Greville points."""
    knots = [open_knots(degrees[d], elements[d]) for d in range(3)]
    g = [greville(knots[d], degrees[d]) for d in range(3)]
    return degrees, knots, lambda i, j, k: f(g[0][i], g[1][j], g[2][k])


def twisted_duct():
    def f(u, v, w):
        a, b, t = 2 * u - 1, 2 * v - 1, 0.5 * math.pi * w
        return (a * math.cos(t) - b * math.sin(t), a * math.sin(t) + b * math.cos(t), 4 * w)
    return faces_of(*sampled([2, 2, 3], [2, 2, 6], f))


def twisted_duct_fine():
    def f(u, v, w):
        a, b, t = 2 * u - 1, 2 * v - 1, 0.5 * math.pi * w
        return (a * math.cos(t) - b * math.sin(t), a * math.sin(t) + b * math.cos(t), 4 * w)
    return faces_of(*sampled([2, 2, 3], [3, 3, 8], f))


def curved_pipe():
    h = math.sqrt(0.5)
    arc = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]  # quarter circle, weights 1, h, 1
    aw = [1.0, h, 1.0]
    beta = math.pi / 3  # bend: 60 degrees, middle control point at 1/cos(30)
    c = math.cos(beta / 2)
    # turning clockwise seen from +z, so that (radius, arc, bend) is right-handed
    bend = [(1.0, 0.0), (1.0, -math.tan(beta / 2)), (math.cos(beta), -math.sin(beta))]
    bw = [1.0, c, 1.0]
    radii = [0.5, 1.0]
    r0 = 3.0

    def point(i, j, k):
        a = r0 + radii[i] * arc[j][0]
        b = radii[i] * arc[j][1]
        return (a * bend[k][0], a * bend[k][1], b)

    def weight(i, j, k):
        return aw[j] * bw[k]

    knots = [open_knots(1, 1), open_knots(2, 1), open_knots(2, 1)]
    return faces_of([1, 2, 2], knots, point, weight)


def bulged_hex():
    def f(u, v, w):
        bump = 16 * u * (1 - u) * v * (1 - v)
        return (u, v, w * (1 + 1.2 * bump))
    return faces_of(*sampled([2, 2, 2], [2, 2, 1], f))


def bracket():
    def f(u, v, w):
        groove = 0.7 * math.exp(-((u - 0.5) / 0.18) ** 2)
        return (3 * u, v + 0.1 * w * math.sin(math.pi * u), w * (1 - groove))
    return faces_of(*sampled([3, 2, 2], [8, 2, 2], f))


def blade_passage():
    # three slices at z = 0, 1, 2: the passage between two blades (camber lines) at
    # pitch 1, stagger and camber growing with z; linear in z between slices
    def slice_point(u, v, s):
        stagger = 0.3 + 0.25 * s
        camber = 0.35 + 0.15 * s
        x = 2 * u
        y0 = camber * math.sin(math.pi * u) + stagger * x
        return (x, y0 + v, 0.0)

    degrees, knots = [3, 2, 1], [open_knots(3, 6), open_knots(2, 2), open_knots(1, 2)]
    g = [greville(knots[d], degrees[d]) for d in range(2)]

    def point(i, j, k):
        x, y, _ = slice_point(g[0][i], g[1][j], k / 2)
        return (x, y, float(k))

    return faces_of(degrees, knots, point)


GEOMETRIES = {
    "twisted-duct": twisted_duct,
    "curved-pipe": curved_pipe,
    "bulged-hex": bulged_hex,
    "bracket": bracket,
    "blade-passage": blade_passage,
}

BENCHMARK_GEOMETRIES = {
    "twisted-duct-fine": twisted_duct_fine,
}


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/data/volumes"
    os.makedirs(out, exist_ok=True)
    named = sys.argv[2:]
    every = {**GEOMETRIES, **BENCHMARK_GEOMETRIES}
    unknown = [n for n in named if n not in every]
    if unknown:
        sys.exit(f"unknown geometry {unknown[0]!r}: one of {', '.join(every)}")
    chosen = {n: every[n] for n in named} if named else GEOMETRIES
    for name, make in chosen.items():
        doc = {"name": name, "volume_boundary": make()}
        with open(os.path.join(out, name + ".json"), "w") as fh:
            json.dump(doc, fh)
            fh.write("\n")


if __name__ == "__main__":
    main()
