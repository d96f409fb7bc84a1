"""Same-basis race against G+Smo's gsBarrierPatch (issue 13).

For each shared G+Smo XML boundary in tests/data/gismo/xml/ and each refinement K:

* G+Smo (pygismo from PyPI): build the initial patch on the input basis, refine it K
  times uniformly (every knot span halved, `gsMultiPatch.uniformRefine(2^K - 1)`), run
  `gsBarrierPatch2(mp, True).compute()` with its default options (ParamMethod 0, the
  PDE method) and time `compute()` only. The result is written as G+Smo XML and judged
  by winslow's certificate (`winslow check FILE.xml --json`).
* winslow: `winslow solve FILE.xml --basis input --refine K -o out.json --json`, timed as
  a process (wall clock) and by the report's "seconds"; its verdict is the certificate's.

The initial G+Smo patch (pygismo's gsCoonsPatch binding cannot return its result: "return
_value_policy = copy, but type is non-copyable") is the Coons patch, built here exactly:
* four curves (BSpline): assigned to west, east, south, north (G+Smo box-side order as
  stored when the corners match, else the closest assignment, curves reversed as needed);
  opposite sides are brought to one degree (`gsBSpline.degreeElevate`) and one knot
  vector (the union after mapping each to [0, 1], `gsBSpline.insertKnot`), as winslow's
  input basis does; the Coons control net is
  P_ij = (1-v_j) S_i + v_j N_i + (1-u_i) W_j + u_i E_j - bilinear corners,
  with u_i, v_j the Greville abscissae (exact, as linear functions are reproduced);
* one patch (TensorBSpline2 / TensorNurbs2): its basis and weights are kept, its interior
  control points are replaced by the same Coons blend of its boundary control points.
A direction of degree 1 is elevated to 2 on both sides (winslow does so; G+Smo crashes
on a bilinear single element). winslow solves NURBS sides in its rational tensor basis
(interior weights: the Coons blend of the boundary weights, where G+Smo keeps the file's
interior weights; same functions), falls back to a fitted basis for interior C0 knots,
and its defect correction adds knots where the certificate finds a fold; the table then
shows different function counts (the "winslow basis" column says which basis was used
and how many repair rounds ran). Runs under 0.2 s are repeated five times on both sides
and the fastest is kept. The last column compares like for like: G+Smo's
`compute()` against the report's "seconds" (winslow's solve with its certificate and
report, inside the process), both without process start-up and file I/O.

With --multipatch, the shared G+Smo multipatch files (tests/data/gismo/xml/multipatch/)
instead, each with fixed and with free interfaces, at the same bases (the files' own,
K uniform refinements): G+Smo's `gsBarrierPatch2(mp, patchWise)` (patchWise = True:
every patch alone with its interfaces fixed; False: one problem over all patches with
the interfaces free, C0 at the interfaces), its initial patches the Coons blends of
their boundaries as above, against `winslow solve FILE.xml --refine K --interfaces
fixed|free`; both results judged by `winslow check` (every patch certified).

Usage: python scripts/bench_peers.py WINSLOW_BIN OUT_DIR [--refine 0,1,2] [--only a,b] [--multipatch]
"""

import argparse
import contextlib
import itertools
import json
import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np
import pygismo as gs

GEOMETRIES = ["butterfly", "duck", "male_rotor", "puzzle3", "puzzle4", "jigsaw01", "rotor_sector",
              "disk", "lake", "plate_with_hole", "flapping_beam", "cooks_membrane", "male_casing_ring"]
XML_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "gismo", "xml")
MULTIPATCH = ["TUDflame", "circleMP", "plateWithHoleMP"]
MP_DIR = os.path.join(XML_DIR, "multipatch")


# ---------------------------------------------------------------- reading the XML files
def numbers(text):
    return [float(x) for x in text.split()]


def read_knots(basis):
    kv = basis.find("KnotVector")
    return int(kv.get("degree")), numbers(kv.text)


def read_coefs(geom):
    c = geom.find("coefs")
    dim = int(c.get("geoDim"))
    return np.array(numbers(c.text)).reshape(-1, dim)[:, :2]


def read_file(path):
    """('curves', [(degree, knots, coefs)]) or ('patch', dict)."""
    root = ET.parse(path).getroot()
    curves, patches = [], []
    for g in root.iter("Geometry"):
        t = g.get("type")
        if t == "BSpline":
            p, kv = read_knots(g.find("Basis"))
            curves.append((p, kv, read_coefs(g)))
        elif t in ("TensorBSpline2", "TensorNurbs2"):
            b = g.find("Basis")
            weights = None
            if t == "TensorNurbs2":
                weights = numbers(b.find("weights").text)
                b = b.find("Basis")
            dirs = sorted(b.findall("Basis"), key=lambda e: int(e.get("index", 0)))
            (p0, k0), (p1, k1) = read_knots(dirs[0]), read_knots(dirs[1])
            patches.append(dict(deg=(p0, p1), knots=(k0, k1), coefs=read_coefs(g), weights=weights))
        else:
            raise ValueError(f"{path}: unsupported geometry type {t}")
    if len(curves) == 4 and not patches:
        return "curves", curves
    if len(patches) == 1 and not curves:
        return "patch", patches[0]
    raise ValueError(f"{path}: expected four curves or one patch")


# ---------------------------------------------------------------- the initial patch
def reverse(curve):
    p, kv, c = curve
    a, b = kv[0], kv[-1]
    return p, [a + b - k for k in reversed(kv)], c[::-1].copy()


def assign_sides(curves):
    """[west, east, south, north], with west(0)=south(0), east(0)=south(1), west(1)=north(0),
    east(1)=north(1): the stored G+Smo box order when it fits, else the best assignment."""
    def gap(sides):
        w, e, s, n = (c[2] for c in sides)
        return max(np.linalg.norm(w[0] - s[0]), np.linalg.norm(e[0] - s[-1]),
                   np.linalg.norm(w[-1] - n[0]), np.linalg.norm(e[-1] - n[-1]))
    best = None
    for perm in itertools.permutations(range(4)):
        for mask in range(16):
            sides = [reverse(curves[i]) if mask >> k & 1 else curves[i] for k, i in enumerate(perm)]
            key = (gap(sides), bin(mask).count("1"), perm != (0, 1, 2, 3))
            if best is None or key < best[0]:
                best = (key, sides)
    return best[1]


def normalised(curve):
    p, kv, c = curve
    a, b = kv[0], kv[-1]
    return p, [(k - a) / (b - a) for k in kv], c


def to_gismo(curve):
    p, kv, c = curve
    return gs.nurbs.gsBSpline(gs.nurbs.gsKnotVector(kv, p), np.asarray(c, dtype=float))


def from_gismo(bs):
    kv = bs.knots()
    return kv.degree(), list(kv.get()), np.array(bs.coefs())


def unify(a, b):
    """Bring two opposite sides to one degree and one knot vector (exact operations)."""
    a, b = to_gismo(normalised(a)), to_gismo(normalised(b))
    p = max(a.degree(0), b.degree(0))
    for c in (a, b):
        if c.degree(0) < p:
            c.degreeElevate(p - c.degree(0), -1)
    for c, other in ((a, b), (b, a)):
        need = multiset(other.knots().get()) - multiset(c.knots().get())
        for knot, m in sorted(need.items()):
            c.insertKnot(knot, m)
    return from_gismo(a), from_gismo(b)


class multiset(dict):
    def __init__(self, values):
        super().__init__()
        for v in values:
            k = round(v, 14)
            self[k] = self.get(k, 0) + 1

    def __sub__(self, other):
        out = multiset([])
        for k, m in self.items():
            d = m - other.get(k, 0)
            if d > 0:
                out[k] = d
        return out


def greville(p, kv):
    n = len(kv) - p - 1
    return np.array([sum(kv[i + 1:i + p + 1]) / p for i in range(n)]) if p > 0 else np.linspace(0, 1, n)


def coons(south, north, west, east, gu, gv):
    """Coons control net (index [j][i], xi fastest) from boundary control rows."""
    u = (gu - gu[0]) / (gu[-1] - gu[0])
    v = (gv - gv[0]) / (gv[-1] - gv[0])
    P = np.zeros((len(v), len(u), 2))
    for j, vj in enumerate(v):
        for i, ui in enumerate(u):
            P[j, i] = ((1 - vj) * south[i] + vj * north[i] + (1 - ui) * west[j] + ui * east[j]
                       - (1 - ui) * (1 - vj) * south[0] - ui * (1 - vj) * south[-1]
                       - (1 - ui) * vj * north[0] - ui * vj * north[-1])
    return P


def initial_patch(path):
    kind, data = read_file(path)
    if kind == "curves":
        west, east, south, north = assign_sides(data)
        west, east = unify(west, east)
        south, north = unify(south, north)
        (pu, ku, s), (_, _, n) = south, north
        (pv, kv, w), (_, _, e) = west, east
        net = coons(s, n, w, e, greville(pu, ku), greville(pv, kv))
        return dict(deg=(pu, pv), knots=(ku, kv), coefs=net.reshape(-1, 2), weights=None)
    (pu, pv), (ku, kv) = data["deg"], data["knots"]
    nu, nv = len(ku) - pu - 1, len(kv) - pv - 1
    grid = data["coefs"].reshape(nv, nu, 2)
    net = coons(grid[0], grid[-1], grid[:, 0], grid[:, -1], greville(pu, ku), greville(pv, kv))
    return dict(data, coefs=net.reshape(-1, 2))


def patch_xml(patch):
    kv = "".join(f'<Basis type="BSplineBasis" index="{d}"><KnotVector degree="{patch["deg"][d]}">'
                 + " ".join(repr(float(k)) for k in patch["knots"][d]) + "</KnotVector></Basis>" for d in range(2))
    tensor = f'<Basis type="TensorBSplineBasis2" parDim="2">{kv}</Basis>'
    coefs = "\n".join(f"{float(x)!r} {float(y)!r}" for x, y in patch["coefs"])
    if patch["weights"] is None:
        return f'<xml><Geometry type="TensorBSpline2" id="0">{tensor}<coefs geoDim="2">{coefs}</coefs></Geometry></xml>'
    w = " ".join(repr(float(x)) for x in patch["weights"])
    return (f'<xml><Geometry type="TensorNurbs2" id="0"><Basis type="TensorNurbsBasis2">{tensor}'
            f'<weights>{w}</weights></Basis><coefs geoDim="2">{coefs}</coefs></Geometry></xml>')


# ---------------------------------------------------------------- the two runs
@contextlib.contextmanager
def c_stdout_to(path):
    """Send file descriptor 1 (where G+Smo's gsInfo writes) to a log file for a while."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(path, "a") as log:
        os.dup2(log.fileno(), 1)
        try:
            yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def certify(winslow, path):
    r = subprocess.run([winslow, "check", path, "--json"], capture_output=True, text=True)
    if r.returncode != 0 and not r.stdout.strip():
        return "error: " + (r.stderr.strip().splitlines() or ["?"])[-1][:80]
    return json.loads(r.stdout)["certificate"]["verdict"]["kind"]


def run_gismo(_winslow, name, refine, out):
    """G+Smo on the refined input basis: (number of functions, seconds of compute())."""
    init = os.path.join(out, f"{name}-init.xml")
    patch = initial_patch(os.path.join(XML_DIR, name + ".xml"))
    with open(init, "w") as f:
        f.write(patch_xml(patch))
    mp = gs.core.gsMultiPatch()
    mp.addPatch(gs.io.gsFileData(init).getAll()[0])
    for d in range(2):  # winslow elevates sides of degree 1 to 2 (cooks_membrane); so does this
        if patch["deg"][d] < 2:
            mp.degreeElevate(2 - patch["deg"][d], d)
    if refine:
        mp.uniformRefine(2 ** refine - 1)
    functions = mp.basis(0).size()
    bp = gs.modelling.gsBarrierPatch2(mp, True)
    with c_stdout_to(os.path.join(out, "gismo.log")):  # G+Smo's progress goes to C++ stdout
        t = time.perf_counter()
        bp.compute()
        seconds = time.perf_counter() - t
    fd = gs.io.gsFileData()
    fd.add(bp.result())
    fd.save(os.path.join(out, f"{name}-r{refine}-gismo"))
    return functions, seconds


def run_gismo_isolated(winslow, name, refine, out):
    """run_gismo in a child process, so that a crash of G+Smo (it dies with SIGFPE on a
    basis without interior functions, cooks_membrane's bilinear element) is a row of the
    table, not the end of the run."""
    r = subprocess.run([sys.executable, os.path.abspath(__file__), "--gismo-case", name, str(refine), out],
                       capture_output=True, text=True)
    lines = r.stdout.strip().splitlines()
    if r.returncode != 0 or not lines:
        detail = (r.stderr.strip().splitlines() or [""])[-1][:60]
        why = f"crashed (signal {-r.returncode})" if r.returncode < 0 else f"failed (exit {r.returncode})"
        return "-", None, f"G+Smo {why}{': ' + detail if detail else ''}"
    functions, seconds = json.loads(lines[-1])
    return functions, seconds, certify(winslow, os.path.join(out, f"{name}-r{refine}-gismo.xml"))


def run_winslow(winslow, name, refine, out):
    result = os.path.join(out, f"{name}-r{refine}-winslow.json")
    cmd = [winslow, "solve", os.path.join(XML_DIR, name + ".xml"), "--basis", "input",
           "--refine", str(refine), "-o", result, "-q", "--json"]
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if r.returncode != 0 and not r.stdout.strip():
        return None, wall, None, "error: " + (r.stderr.strip().splitlines() or ["?"])[-1][:80], "-"
    rep = json.loads(r.stdout)
    verdict = certify(winslow, result) if os.path.exists(result) else rep["verdict"]
    basis = rep["basis"]["used"]
    if rep.get("repair_rounds"):
        basis += f" + {len(rep['repair_rounds'])} repair rounds"
    return rep["basis_functions"], wall, rep["seconds"], verdict, basis


# ---------------------------------------------------------------- multipatch files
def multipatch_init(name, out):
    """The G+Smo file with every patch's interior replaced by the Coons blend of its
    boundary (basis and weights kept): the initial multipatch of the race."""
    tree = ET.parse(os.path.join(MP_DIR, name + ".xml"))
    root = tree.getroot()
    for g in root.iter("Geometry"):
        b = g.find("Basis")
        if g.get("type") == "TensorNurbs2":
            b = b.find("Basis")
        dirs = sorted(b.findall("Basis"), key=lambda e: int(e.get("index", 0)))
        (pu, ku), (pv, kv) = read_knots(dirs[0]), read_knots(dirs[1])
        nu, nv = len(ku) - pu - 1, len(kv) - pv - 1
        grid = read_coefs(g).reshape(nv, nu, 2)
        net = coons(grid[0], grid[-1], grid[:, 0], grid[:, -1], greville(pu, ku), greville(pv, kv))
        g.find("coefs").text = "\n".join(f"{float(x)!r} {float(y)!r}" for x, y in net.reshape(-1, 2)) + "\n"
        g.find("coefs").set("geoDim", "2")
    mp_id = int(root.find("MultiPatch").get("id"))
    path = os.path.join(out, f"{name}-init.xml")
    tree.write(path)
    return path, mp_id


def run_gismo_mp(name, refine, free, out):
    """G+Smo's multipatch gsBarrierPatch2: (functions, seconds of compute())."""
    path, mp_id = multipatch_init(name, out)
    mp = gs.core.gsMultiPatch()
    gs.io.gsFileData(path).getId(mp_id, mp)
    if refine:
        mp.uniformRefine(2 ** refine - 1)
    functions = sum(mp.basis(k).size() for k in range(mp.nPatches()))
    bp = gs.modelling.gsBarrierPatch2(mp, not free)
    with c_stdout_to(os.path.join(out, "gismo.log")):
        t = time.perf_counter()
        bp.compute()
        seconds = time.perf_counter() - t
    fd = gs.io.gsFileData()
    fd.add(bp.result())
    fd.save(os.path.join(out, f"{name}-r{refine}-{'free' if free else 'fixed'}-gismo"))
    return functions, seconds


def run_gismo_mp_isolated(winslow, name, refine, free, out):
    r = subprocess.run([sys.executable, os.path.abspath(__file__), "--gismo-mp-case", name, str(refine),
                        "1" if free else "0", out], capture_output=True, text=True)
    lines = r.stdout.strip().splitlines()
    if r.returncode != 0 or not lines:
        detail = (r.stderr.strip().splitlines() or [""])[-1][:60]
        return "-", None, f"G+Smo failed (exit {r.returncode}){': ' + detail if detail else ''}"
    functions, seconds = json.loads(lines[-1])
    result = os.path.join(out, f"{name}-r{refine}-{'free' if free else 'fixed'}-gismo.xml")
    return functions, seconds, certify_layout(winslow, result)


def certify_layout(winslow, path):
    r = subprocess.run([winslow, "check", path, "--json"], capture_output=True, text=True)
    if not r.stdout.strip():
        return "error: " + (r.stderr.strip().splitlines() or ["?"])[-1][:80]
    rep = json.loads(r.stdout)
    bad = [p["name"] for p in rep["patches"] if p["verdict"] not in ("certified", "degenerate-corner")]
    return rep["verdict"] + (f" ({', '.join(bad)})" if bad else "")


def run_winslow_mp(winslow, name, refine, free, out):
    result = os.path.join(out, f"{name}-r{refine}-{'free' if free else 'fixed'}-winslow.json")
    cmd = [winslow, "solve", os.path.join(MP_DIR, name + ".xml"), "--refine", str(refine),
           "--interfaces", "free" if free else "fixed", "-o", result, "-q", "--json"]
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if not r.stdout.strip():
        return None, wall, None, "error: " + (r.stderr.strip().splitlines() or ["?"])[-1][:80]
    rep = json.loads(r.stdout)
    return rep["basis_functions"], wall, rep["seconds"], certify_layout(winslow, result)


def main_multipatch(args):
    print("| geometry | interfaces | refine | functions (G+Smo / winslow) | G+Smo s | G+Smo verdict "
          "| winslow s (wall / report) | winslow verdict | ratio (G+Smo s / winslow wall s) "
          "| ratio in-process (G+Smo s / winslow report s) |")
    print("|---|---|---:|---:|---:|---|---:|---|---:|---:|")
    names = [n for n in args.only.split(",") if n in MULTIPATCH] if args.only != ",".join(GEOMETRIES) else MULTIPATCH
    for name in names:
        for free in (False, True):
            for k in (int(x) for x in args.refine.split(",")):
                gf, gsec, gver = run_gismo_mp_isolated(args.winslow, name, k, free, args.out)
                wf, wwall, wsec, wver = run_winslow_mp(args.winslow, name, k, free, args.out)
                if gsec is not None and gsec < 0.2:
                    for _ in range(4):
                        t = run_gismo_mp_isolated(args.winslow, name, k, free, args.out)[1]
                        gsec = min(gsec, t) if t is not None else gsec
                if wsec is not None and wwall < 0.2:
                    for _ in range(4):
                        r = run_winslow_mp(args.winslow, name, k, free, args.out)
                        wwall, wsec = min(wwall, r[1]), min(wsec, r[2]) if r[2] is not None else wsec
                ratio = f"{gsec / wwall:.1f}" if gsec is not None and wwall else "-"
                inproc = f"{gsec / wsec:.1f}" if gsec is not None and wsec else "-"
                gtxt = f"{gsec:.3f}" if gsec is not None else "-"
                wtxt = f"{wwall:.3f} / {wsec:.3f}" if wsec is not None else f"{wwall:.3f} / -"
                mode = "free" if free else "fixed"
                print(f"| {name} | {mode} | {k} | {gf} / {wf} | {gtxt} | {gver} | {wtxt} | {wver} | {ratio} | {inproc} |",
                      flush=True)


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--gismo-case":  # the child of run_gismo_isolated
        print(json.dumps(run_gismo(None, sys.argv[2], int(sys.argv[3]), sys.argv[4])))
        return
    if len(sys.argv) == 6 and sys.argv[1] == "--gismo-mp-case":  # the child of run_gismo_mp_isolated
        print(json.dumps(run_gismo_mp(sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1", sys.argv[5])))
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("winslow")
    ap.add_argument("out")
    ap.add_argument("--refine", default="0,1,2")
    ap.add_argument("--only", default=",".join(GEOMETRIES))
    ap.add_argument("--multipatch", action="store_true", help="race the multipatch files instead")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    print(f"pygismo {gs.__version__}; winslow {args.winslow}", file=sys.stderr, flush=True)
    if args.multipatch:
        main_multipatch(args)
        return
    print("| geometry | refine | functions (G+Smo / winslow) | winslow basis | G+Smo s | G+Smo verdict "
          "| winslow s (wall / report) | winslow verdict | ratio (G+Smo s / winslow wall s) "
          "| ratio in-process (G+Smo s / winslow report s) |")
    print("|---|---:|---:|---|---:|---|---:|---|---:|---:|")
    for name in args.only.split(","):
        for k in (int(x) for x in args.refine.split(",")):
            gf, gsec, gver = run_gismo_isolated(args.winslow, name, k, args.out)
            wf, wwall, wsec, wver, wbasis = run_winslow(args.winslow, name, k, args.out)
            # runs under 0.2 s are at the mercy of the scheduler: repeat both sides (same
            # inputs, same verdicts) and keep the fastest of five
            if gsec is not None and gsec < 0.2:
                for _ in range(4):
                    t = run_gismo_isolated(args.winslow, name, k, args.out)[1]
                    gsec = min(gsec, t) if t is not None else gsec
            if wsec is not None and wwall < 0.2:
                for _ in range(4):
                    r = run_winslow(args.winslow, name, k, args.out)
                    wwall, wsec = min(wwall, r[1]), min(wsec, r[2]) if r[2] is not None else wsec
            ratio = f"{gsec / wwall:.1f}" if gsec is not None and wwall else "-"
            # like for like: G+Smo's compute() against winslow's solve (hierarchy, Newton,
            # certificate and report) inside the process, both without start-up and I/O
            inproc = f"{gsec / wsec:.1f}" if gsec is not None and wsec else "-"
            gtxt = f"{gsec:.3f}" if gsec is not None else "-"
            wtxt = f"{wwall:.3f} / {wsec:.3f}" if wsec is not None else f"{wwall:.3f} / -"
            print(f"| {name} | {k} | {gf} / {wf} | {wbasis} | {gtxt} | {gver} | {wtxt} | {wver} | {ratio} | {inproc} |",
                  flush=True)


if __name__ == "__main__":
    main()
