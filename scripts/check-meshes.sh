#!/usr/bin/env bash
# Open winslow's mesh files in a reference reader (meshio, from PyPI, in a venv): solve
# the shared geometries, write .msh/.vtu/.su2 (structured, unstructured, curved) and
# load each with meshio, printing its point and cell counts and distinct points (a ring's
# seam is merged: as many distinct points as points; the cut ring male_casing_ring is
# refused for its coinciding nodes); multipatch results as one mesh (distinct points =
# points: the interfaces are merged) and a lofted volume's hexahedra. Run by hand, not by CI.
#   scripts/check-meshes.sh [WINSLOW_BINARY]
set -euo pipefail
W=${1:-./target/release/winslow}
OUT=${OUT:-out/check-meshes}
VENV=${VENV:-/tmp/winslow-meshio-venv}
mkdir -p "$OUT"
[ -x "$VENV/bin/python" ] || { python3 -m venv "$VENV" && "$VENV/bin/pip" install -q meshio; }
for g in tests/data/spiral_channel.json tests/data/wavy_lid.json tests/data/quarter_annulus.json \
         tests/data/gismo/male_casing_ring.json tests/data/gismo/puzzle3.json \
         tests/data/rings/male_rotor_in_casing.json; do
  n=$(basename "$g" .json)
  "$W" solve "$g" -o "$OUT/$n.json" -q > /dev/null || { echo "$n: solve failed, skipped"; continue; }
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-s.msh" --structured 101x33 --cluster eta:arctan:6 > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-s.su2" --structured 101x33 --cluster eta:arctan:6 > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-s.vtu" --structured 101x33 --cluster eta:arctan:6 > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-q2.msh" --structured 41x17 --order 2 > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-q3.vtu" --structured 41x17 --order 3 > /dev/null || echo "  (refused, see the error above)"
  size=$("$VENV/bin/python" -c "import json,math;m=json.load(open('$OUT/$n.json'))['map']['control_points'];xs=[p[0] for p in m];ys=[p[1] for p in m];print(math.hypot(max(xs)-min(xs),max(ys)-min(ys))/60)")
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-u.msh" --unstructured --size "$size" > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-u.su2" --unstructured --size "$size" > /dev/null || echo "  (refused, see the error above)"
  "$W" mesh "$OUT/$n.json" -o "$OUT/$n-t3.msh" --unstructured --size "$size" --order 3 > /dev/null || echo "  (refused, see the error above)"
done
# multipatch results (one conforming mesh, groups per patch and outer side) and a volume
for g in tests/data/gismo/xml/multipatch/plateWithHoleMP.xml tests/data/gismo/xml/multipatch/TUDflame.xml; do
  n=$(basename "$g" .xml)
  "$W" solve "$g" -o "$OUT/$n.json" -q > /dev/null || { echo "$n: solve failed, skipped"; continue; }
  for f in msh su2 vtu; do
    "$W" mesh "$OUT/$n.json" -o "$OUT/$n-mp.$f" --structured 33x33 > /dev/null || echo "  (refused, see the error above)"
  done
done
qa=tests/data/maps/quarter_annulus_nurbs.json
"$W" loft "$qa" "$qa" --dz 1 -o "$OUT/qa-volume.json" -q
for f in msh vtu; do "$W" mesh "$OUT/qa-volume.json" -o "$OUT/qa-volume.$f" --structured 9x17x5 > /dev/null; done
"$VENV/bin/python" - "$OUT" <<'PY'
import sys, glob, meshio
for f in sorted(glob.glob(sys.argv[1] + "/*.msh") + glob.glob(sys.argv[1] + "/*.vtu") + glob.glob(sys.argv[1] + "/*.su2")):
    m = meshio.read(f)
    cells = ", ".join(f"{b.type} {len(b.data)}" for b in m.cells)
    tags = sorted(m.field_data) if m.field_data else []
    distinct = len({tuple(p) for p in m.points.tolist()})
    print(f"{f}: {len(m.points)} points ({distinct} distinct); {cells}" + (f"; groups {tags}" if tags else ""))
PY
