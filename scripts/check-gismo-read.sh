#!/usr/bin/env bash
# G+Smo reads winslow's multipatch XML (issue 17): every shared multipatch file solved
# with free interfaces and written as G+Smo XML, then read by pygismo (PyPI, in the venv
# of scripts/bench-peers.sh): patches, interfaces and boundary sides as stored, and
# G+Smo's own computeTopology from the geometry (tolerance 1e-9) finds the same counts.
# A check by hand, not CI (it needs Python and PyPI).
#   bash scripts/check-gismo-read.sh [WINSLOW_BIN]
set -euo pipefail
cd "$(dirname "$0")/.."
W=$(realpath "${1:-target/release/winslow}")
VENV=${VENV:-$HOME/.cache/winslow-peers-venv}
PYGISMO_VERSION=${PYGISMO_VERSION:-26.9.0}
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -c "import pygismo" 2>/dev/null || "$VENV/bin/pip" install -q "pygismo==$PYGISMO_VERSION"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for f in tests/data/gismo/xml/multipatch/*.xml; do
  name=$(basename "$f" .xml)
  "$W" solve "$f" --interfaces free -o "$tmp/$name.xml" -q >/dev/null
  "$VENV/bin/python" - "$tmp/$name.xml" "$name" <<'PY'
import re, sys
import pygismo as gs
path, name = sys.argv[1], sys.argv[2]
mp_id = int(re.search(r'<MultiPatch[^>]*id="(\d+)"', open(path).read()).group(1))
fd = gs.io.gsFileData(path)
stored = gs.core.gsMultiPatch()
fd.getId(mp_id, stored)
computed = gs.core.gsMultiPatch()
fd.getId(mp_id, computed)
ok = computed.computeTopology(1e-9, False, False)
a = (stored.nPatches(), len(stored.interfaces()), len(stored.boundaries()))
b = (computed.nPatches(), len(computed.interfaces()), len(computed.boundaries()))
print(f"{name}: pygismo read {a[0]} patches, {a[1]} interfaces, {a[2]} boundary sides; "
      f"computeTopology {'agrees' if ok and a == b else 'DIFFERS: ' + str(b)}")
sys.exit(0 if ok and a == b else 1)
PY
done
