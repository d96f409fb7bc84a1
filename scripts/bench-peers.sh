#!/usr/bin/env bash
# Same-basis race against G+Smo's gsBarrierPatch (issue 13): pygismo from PyPI in a venv,
# gsBarrierPatch2 (default options: the PDE method) against `winslow solve --basis input`
# on the identical basis (input basis, then 1 and 2 uniform refinements), both maps judged
# by winslow's certificate. Prints a Markdown table; see scripts/bench_peers.py for how the
# initial patch and the bases are built. A benchmark, run by hand: CI does not call it.
#   scripts/bench-peers.sh [WINSLOW_BIN] [OUT_DIR]
#   (REFINE=0,1 ONLY=duck,puzzle3 narrow the run; VENV= picks the environment;
#    MULTIPATCH=1 races the multipatch files, fixed and free interfaces, instead)
# Needs python3 with the venv module (Debian/Ubuntu: apt-get install python3-venv) and PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${1:-target/release/winslow}
OUT=${2:-out/bench-peers}
VENV=${VENV:-$HOME/.cache/winslow-peers-venv}
PYGISMO_VERSION=26.9.0
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV" || { echo "python3 -m venv failed: install the venv module (apt-get install python3-venv)" >&2; exit 1; }
fi
"$VENV/bin/python" -c "import pygismo" 2>/dev/null || "$VENV/bin/pip" install -q "pygismo==$PYGISMO_VERSION"
"$VENV/bin/python" scripts/bench_peers.py "$(realpath "$W")" "$OUT" ${REFINE:+--refine "$REFINE"} ${ONLY:+--only "$ONLY"} ${MULTIPATCH:+--multipatch}
