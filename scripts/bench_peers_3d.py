"""Same-basis race against G+Smo in 3D (issue 33): volumes from their six boundary faces.

For each volume boundary of the test suite (tests/data/volumes/NAME.json) and each
refinement K:

* winslow: `winslow solve NAME.json --refine K -o OUT/NAME-rK-winslow.json --gismo
  OUT/NAME-rK-winslow.xml --json` (common bases of the faces, every element halved K
  times, trivariate Coons start, EGG or the Winslow functional, certificate), timed as a
  process (wall clock) and by the report's "seconds" (the solve with its certificate,
  inside the process).
* The same basis for G+Smo: the knot vectors, degrees and weights of winslow's result
  (its `TensorBSpline3`/`TensorNurbs3` file), whose six boundary layers of control points
  are the input faces on that basis (exact elevation and insertion; the solve keeps them
  fixed). From them:
  - the six faces as G+Smo surfaces (`TensorBSpline2`/`TensorNurbs2`, `geoDim="3"`) in
    G+Smo's side order (west, east, south, north, front, back = xi 0/1, eta 0/1, zeta 0/1,
    each parametrised by the two remaining directions in order);
  - the initial volume: the trivariate Coons patch of the boundary net (Boolean sum of
    the three linear blends at the Greville abscissae, in homogeneous coordinates, as
    winslow's start `solve::volume::coons`).
* G+Smo (pygismo from PyPI), each in a child process so that a crash is a row of the
  table, only `compute()` timed:
  - `gsBarrierPatch3(initial, True).compute()` with its default options (pygismo's
    `options()` returns a copy, so the defaults are the only reachable ones: ParamMethod
    0, the PDE patch with Anderson acceleration, then the H1 improvement);
  - `gsSpringPatch(faces).compute()`: G+Smo's linear 3D construction from the six faces
    (no bijectivity safeguard), the 3D method of pygismo that runs.
* Every result is judged by winslow's certificate (`winslow check FILE --json`).

Runs under 0.2 s are repeated five times on both sides and the fastest is kept.

Usage: python scripts/bench_peers_3d.py WINSLOW_BIN OUT_DIR [--refine 0,1,2] [--only a,b]
"""

import argparse
import json
import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np

GEOMETRIES = ["twisted-duct", "curved-pipe", "bulged-hex", "bracket", "blade-passage"]
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "volumes")


# ---------------------------------------------------------------- the basis of winslow's result
def numbers(text):
    return [float(x) for x in text.split()]


def read_volume(path):
    """(degrees, knots, net[k, j, i, 3], weights[k, j, i] or None) of a TensorBSpline3 /
    TensorNurbs3 file (xi fastest)."""
    g = ET.parse(path).getroot().find("Geometry")
    b = g.find("Basis")
    weights = None
    if g.get("type") == "TensorNurbs3":
        weights = np.array(numbers(b.find("weights").text))
        b = b.find("Basis")
    dirs = sorted(b.findall("Basis"), key=lambda e: int(e.get("index", 0)))
    deg = [int(d.find("KnotVector").get("degree")) for d in dirs]
    knots = [numbers(d.find("KnotVector").text) for d in dirs]
    n = [len(knots[d]) - deg[d] - 1 for d in range(3)]
    net = np.array(numbers(g.find("coefs").text)).reshape(n[2], n[1], n[0], 3)
    if weights is not None:
        weights = weights.reshape(n[2], n[1], n[0])
    return deg, knots, net, weights


def greville(p, kv):
    n = len(kv) - p - 1
    g = np.array([sum(kv[i + 1:i + p + 1]) / p for i in range(n)])
    return (g - g[0]) / (g[-1] - g[0])


def coons(net, weights, deg, knots):
    """The trivariate Coons patch of the boundary layers of `net` (homogeneous)."""
    w = np.ones(net.shape[:3]) if weights is None else weights
    h = np.concatenate([net * w[..., None], w[..., None]], axis=3)  # [k, j, i, 4]
    a, b, c = (greville(deg[d], knots[d]) for d in range(3))
    A = a[None, None, :, None]
    B = b[None, :, None, None]
    C = c[:, None, None, None]

    def p1(x):
        return (1 - A) * x[:, :, :1] + A * x[:, :, -1:]

    def p2(x):
        return (1 - B) * x[:, :1, :] + B * x[:, -1:, :]

    def p3(x):
        return (1 - C) * x[:1, :, :] + C * x[-1:, :, :]

    out = p1(h) + p2(h) + p3(h) - p1(p2(h)) - p1(p3(h)) - p2(p3(h)) + p1(p2(p3(h)))
    out[0], out[-1], out[:, 0], out[:, -1], out[:, :, 0], out[:, :, -1] = (
        h[0], h[-1], h[:, 0], h[:, -1], h[:, :, 0], h[:, :, -1])
    return out[..., :3] / out[..., 3:], (None if weights is None else out[..., 3])


# ---------------------------------------------------------------- G+Smo XML
def kv_xml(p, kv, index):
    return (f'<Basis type="BSplineBasis" index="{index}"><KnotVector degree="{p}">'
            + " ".join(repr(float(k)) for k in kv) + "</KnotVector></Basis>")


def geometry_xml(gid, deg, knots, coefs, weights):
    """A TensorBSpline2/3 (or TensorNurbs2/3) of `coefs` (first direction fastest)."""
    dim = len(deg)
    tensor = (f'<Basis type="TensorBSplineBasis{dim}">'
              + "".join(kv_xml(deg[d], knots[d], d) for d in range(dim)) + "</Basis>")
    pts = "\n".join(" ".join(repr(float(x)) for x in row) for row in coefs.reshape(-1, 3))
    if weights is None:
        return f'<Geometry type="TensorBSpline{dim}" id="{gid}">{tensor}<coefs geoDim="3">{pts}</coefs></Geometry>'
    w = " ".join(repr(float(x)) for x in weights.reshape(-1))
    return (f'<Geometry type="TensorNurbs{dim}" id="{gid}"><Basis type="TensorNurbsBasis{dim}">{tensor}'
            f'<weights>{w}</weights></Basis><coefs geoDim="3">{pts}</coefs></Geometry>')


def faces_xml(deg, knots, net, weights):
    """The six boundary layers as surfaces, in G+Smo's side order, each parametrised by
    the two remaining directions in order (the first fastest)."""
    out = []
    for side in range(6):
        d, end = side // 2, side % 2
        rest = [x for x in range(3) if x != d]
        sl = [slice(None)] * 3
        sl[2 - d] = -1 if end else 0  # net is [k, j, i]: axis 2 - d is direction d
        layer = net[tuple(sl)]
        wl = None if weights is None else weights[tuple(sl)]
        out.append(geometry_xml(side, [deg[r] for r in rest], [knots[r] for r in rest], layer, wl))
    return "<xml>" + "".join(out) + "</xml>"


# ---------------------------------------------------------------- the runs
def certify(winslow, path):
    r = subprocess.run([winslow, "check", path, "--json"], capture_output=True, text=True)
    if not r.stdout.strip():
        return "error: " + (r.stderr.strip().splitlines() or ["?"])[-1][:80]
    v = json.loads(r.stdout)["certificate"]["verdict"]
    return v["kind"] + (f" (det J >= {v['lower_bound']:.3g})" if v["kind"] == "certified" else "")


def run_winslow(winslow, name, refine, out):
    base = os.path.join(out, f"{name}-r{refine}-winslow")
    cmd = [winslow, "solve", os.path.join(DATA, name + ".json"), "--refine", str(refine),
           "-o", base + ".json", "--gismo", base + ".xml", "-q", "--json"]
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if not r.stdout.strip():
        raise RuntimeError(f"winslow failed on {name}: {r.stderr.strip()[-200:]}")
    rep = json.loads(r.stdout)["report"]
    return dict(wall=wall, seconds=rep["seconds"], method=rep["method"], unknowns=rep["unknowns"],
                shape=rep["shape"], verdict=certify(winslow, base + ".json"), xml=base + ".xml")


def gismo_child(kind, path, result):
    """In the child process: G+Smo's `kind` on `path`, the result saved to `result`
    (G+Smo adds .xml); prints the seconds of compute()."""
    import pygismo as gs
    fd = gs.io.gsFileData(path)
    mp = gs.core.gsMultiPatch()
    for p in fd.getAll():
        mp.addPatch(p)
    saved = os.dup(1)  # G+Smo's progress goes to C++ stdout: keep it out of the answer
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    try:
        if kind == "barrier":
            bp = gs.modelling.gsBarrierPatch3(mp, True)
            t = time.perf_counter()
            bp.compute()
            seconds = time.perf_counter() - t
            res = bp.result()
        else:
            sp = gs.modelling.gsSpringPatch(mp)
            t = time.perf_counter()
            geo = sp.compute()
            seconds = time.perf_counter() - t
            res = gs.core.gsMultiPatch()
            res.addPatch(geo)
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
    out = gs.io.gsFileData()
    out.add(res)
    out.save(result)
    print(json.dumps(seconds))


def boundary_kept(net, result):
    """Whether the boundary layers of G+Smo's result are the faces given (to 1e-9 of the
    bounding box diagonal)."""
    other = read_volume(result)[2]
    if other.shape != net.shape:
        return False
    m = np.zeros(net.shape[:3], bool)
    m[0] = m[-1] = m[:, 0] = m[:, -1] = m[:, :, 0] = m[:, :, -1] = True
    diam = np.linalg.norm(net.reshape(-1, 3).max(axis=0) - net.reshape(-1, 3).min(axis=0))
    return float(np.abs(other[m] - net[m]).max()) <= 1e-9 * diam


def run_gismo(winslow, kind, path, result, net):
    """(seconds or None, verdict or why it failed)."""
    r = subprocess.run([sys.executable, os.path.abspath(__file__), "--gismo-case", kind, path, result],
                       capture_output=True, text=True)
    lines = r.stdout.strip().splitlines()
    if r.returncode != 0 or not lines:
        detail = (r.stderr.strip().splitlines() or [""])[-1][:60]
        why = f"crashed (signal {-r.returncode})" if r.returncode < 0 else f"failed (exit {r.returncode})"
        return None, why + (f": {detail}" if detail else "")
    verdict = certify(winslow, result + ".xml")
    if not boundary_kept(net, result + ".xml"):
        verdict += ", faces NOT kept"
    return json.loads(lines[-1]), verdict


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--gismo-case":
        gismo_child(sys.argv[2], sys.argv[3], sys.argv[4])
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("winslow")
    ap.add_argument("out")
    ap.add_argument("--refine", default="0,1,2")
    ap.add_argument("--only", default=",".join(GEOMETRIES))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    import pygismo as gs
    print(f"pygismo {gs.__version__}; winslow {args.winslow}", file=sys.stderr, flush=True)
    print("| geometry | refine | basis (control points) | unknowns | winslow method | winslow s (wall / report) "
          "| winslow verdict | gsBarrierPatch3 | gsSpringPatch s | gsSpringPatch verdict "
          "| ratio (spring s / winslow report s) |")
    print("|---|---:|---|---:|---|---:|---|---|---:|---|---:|")
    for name in args.only.split(","):
        for k in (int(x) for x in args.refine.split(",")):
            w = run_winslow(args.winslow, name, k, args.out)
            if w["wall"] < 0.2:
                for _ in range(4):
                    r = run_winslow(args.winslow, name, k, args.out)
                    w["wall"], w["seconds"] = min(w["wall"], r["wall"]), min(w["seconds"], r["seconds"])
            deg, knots, net, weights = read_volume(w["xml"])
            stem = os.path.join(args.out, f"{name}-r{k}")
            with open(stem + "-faces.xml", "w") as f:
                f.write(faces_xml(deg, knots, net, weights))
            init, iw = coons(net, weights, deg, knots)
            with open(stem + "-init.xml", "w") as f:
                f.write("<xml>" + geometry_xml(0, deg, knots, init, iw) + "</xml>")
            bsec, bver = run_gismo(args.winslow, "barrier", stem + "-init.xml", stem + "-barrier-gismo", net)
            ssec, sver = run_gismo(args.winslow, "spring", stem + "-faces.xml", stem + "-spring-gismo", net)
            if ssec is not None and ssec < 0.2:
                for _ in range(4):
                    t = run_gismo(args.winslow, "spring", stem + "-faces.xml", stem + "-spring-gismo", net)[0]
                    ssec = min(ssec, t) if t is not None else ssec
            btxt = f"{bsec:.3f} s, {bver}" if bsec is not None else bver
            stxt = f"{ssec:.4f}" if ssec is not None else "-"
            ratio = f"{ssec / w['seconds']:.2f}" if ssec is not None and w["seconds"] else "-"
            shape = "x".join(str(s) for s in w["shape"])
            print(f"| {name} | {k} | {shape} | {w['unknowns']} | {w['method']} | {w['wall']:.3f} / {w['seconds']:.3f} "
                  f"| {w['verdict']} | {btxt} | {stxt} | {sver} | {ratio} |", flush=True)


if __name__ == "__main__":
    main()
