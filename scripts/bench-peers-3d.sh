#!/usr/bin/env bash
# Same-basis race against G+Smo in 3D (issue 33): pygismo from PyPI in a venv,
# gsBarrierPatch3 (default options) and gsSpringPatch against `winslow solve` of the five
# volume boundaries of tests/data/volumes, on winslow's basis (the faces' common basis,
# then 1 and 2 uniform refinements), every result judged by winslow's certificate.
# Prints a Markdown table; see scripts/bench_peers_3d.py for how the faces and the
# initial volume are built. A benchmark, run by hand: CI does not call it.
#   scripts/bench-peers-3d.sh [WINSLOW_BIN] [OUT_DIR]
#   (REFINE=0,1 ONLY=twisted-duct,bracket narrow the run; VENV= picks the environment)
# Needs python3 with the venv module (Debian/Ubuntu: apt-get install python3-venv) and PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${1:-target/release/winslow}
OUT=${2:-out/bench-peers-3d}
VENV=${VENV:-$HOME/.cache/winslow-peers-venv}
PYGISMO_VERSION=26.9.0
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV" || { echo "python3 -m venv failed: install the venv module (apt-get install python3-venv)" >&2; exit 1; }
fi
"$VENV/bin/python" -c "import pygismo" 2>/dev/null || "$VENV/bin/pip" install -q "pygismo==$PYGISMO_VERSION"
"$VENV/bin/python" scripts/bench_peers_3d.py "$(realpath "$W")" "$OUT" ${REFINE:+--refine "$REFINE"} ${ONLY:+--only "$ONLY"}
