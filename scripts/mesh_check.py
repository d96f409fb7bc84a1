#!/usr/bin/env python3
"""Measure a 2D SU2 mesh the way a solver's reader sees it (pure Python, no winslow
code): points and distinct points, markers, the first-cell heights at each marker
(the length of a cell edge that leaves a marker edge), the largest aspect ratio
(longest over shortest edge), the largest non-orthogonality (angle between an internal
edge's normal and the line joining the two cell centroids; centroids about each cell's
first corner) and the internal edges at 90 degrees or more.

    python3 scripts/mesh_check.py MESH.su2 [MESH.su2 ...]

With meshio installed (a venv, `pip install meshio`), `--meshio` also reads each file
with meshio and prints its point count and distinct points.
"""
import math
import sys


def read_su2(path):
    lines = [l.split("%")[0].strip() for l in open(path)]
    lines = [l for l in lines if l]
    at = 0
    cells, pts, markers = [], [], {}
    while at < len(lines):
        key, _, val = lines[at].partition("=")
        key, val = key.strip(), val.strip()
        at += 1
        if key == "NELEM":
            for l in lines[at:at + int(val)]:
                v = [int(t) for t in l.split()]
                k = {5: 3, 9: 4}[v[0]]
                cells.append(v[1:1 + k])
            at += int(val)
        elif key == "NPOIN":
            for l in lines[at:at + int(val.split()[0])]:
                v = l.split()
                pts.append((float(v[0]), float(v[1])))
            at += int(val.split()[0])
        elif key == "MARKER_TAG":
            n = int(lines[at].partition("=")[2])
            markers[val] = [tuple(int(t) for t in l.split()[1:3]) for l in lines[at + 1:at + 1 + n]]
            at += 1 + n
    return pts, cells, markers


def centroid(p):
    ox, oy = p[0]
    a = cx = cy = 0.0
    for k in range(1, len(p) - 1):
        ux, uy = p[k][0] - ox, p[k][1] - oy
        vx, vy = p[k + 1][0] - ox, p[k + 1][1] - oy
        w = ux * vy - uy * vx
        a += w
        cx += (ux + vx) * w
        cy += (uy + vy) * w
    return ox + cx / (3 * a), oy + cy / (3 * a)


def measure(path):
    pts, cells, markers = read_su2(path)
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    diam = math.hypot(max(xs) - min(xs), max(ys) - min(ys))
    exact = len(set(pts))
    tol = 1e-13 * diam
    close = len({(round(x / tol), round(y / tol)) for x, y in pts})
    print(f"{path}: {len(pts)} points, {exact} distinct (exact), {close} distinct (1e-13 of the diameter), {len(cells)} cells")
    edges = {}
    aspect = 0.0
    for c, v in enumerate(cells):
        ls = []
        for e in range(len(v)):
            a, b = v[e], v[(e + 1) % len(v)]
            edges.setdefault((min(a, b), max(a, b)), []).append((c, a, b))
            ls.append(math.dist(pts[a], pts[b]))
        aspect = max(aspect, max(ls) / min(ls) if min(ls) > 0 else math.inf)
    cen = [centroid([pts[i] for i in v]) for v in cells]
    worst, over = 0.0, 0
    for key, cs in edges.items():
        if len(cs) != 2:
            continue
        (c0, a, b), (c1, _, _) = cs
        nx, ny = pts[b][1] - pts[a][1], -(pts[b][0] - pts[a][0])
        dx, dy = cen[c1][0] - cen[c0][0], cen[c1][1] - cen[c0][1]
        den = math.hypot(nx, ny) * math.hypot(dx, dy)
        ang = 90.0 if den == 0 else math.degrees(math.acos(max(-1.0, min(1.0, (nx * dx + ny * dy) / den))))
        worst = max(worst, ang)
        over += ang >= 90.0
    print(f"  max aspect ratio {aspect:.4g}; non-orthogonality max {worst:.2f} deg, {over} internal edges at 90 deg or more")
    open_edges = sum(1 for cs in edges.values() if len(cs) == 1)
    print(f"  edges with one cell {open_edges}, on markers {sum(len(m) for m in markers.values())}")
    for name, es in markers.items():
        wall = {(min(a, b), max(a, b)) for a, b in es}
        hs = []
        for a, b in es:
            (c, _, _), = edges[(min(a, b), max(a, b))]
            v = cells[c]
            for e in range(len(v)):
                p, q = v[e], v[(e + 1) % len(v)]
                k = (min(p, q), max(p, q))
                if k not in wall and (p in (a, b)) != (q in (a, b)):
                    hs.append(math.dist(pts[p], pts[q]))
        print(f"  marker {name}: {len(es)} edges, first height min {min(hs):.4g} max {max(hs):.4g}")


def with_meshio(path):
    import meshio
    m = meshio.read(path)
    distinct = len({tuple(p[:2]) for p in m.points.tolist()})
    print(f"  meshio: {len(m.points)} points, {distinct} distinct; " + ", ".join(f"{b.type} {len(b.data)}" for b in m.cells))


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--meshio"]
    for f in args:
        measure(f)
        if "--meshio" in sys.argv:
            with_meshio(f)
