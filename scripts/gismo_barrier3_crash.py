"""Reproduces the crash of pygismo's gsBarrierPatch3 (issue 33; docs/volumes.md, "Against
G+Smo in 3D"): a sheared unit cube, one quadratic patch of 4 x 4 x 4 control points, no
fold anywhere, given to `gsBarrierPatch3(mp, False).compute()` with the option given on
the command line (e.g. `ParamMethod=2`). With pygismo 26.9.0, 25.7.0, 25.1.0 and 24.8.0
from PyPI the process dies with SIGSEGV right after "Anderson Acceleration SOLVER:
parameter settings", for ParamMethod 0-3, AAPreconditionType 0-2, InitialMethod 0-1,
quRule 1-2 and needPDEH1 off alike; under gdb the fault is a free() of an invalid pointer
called from gismo::gsBarrierCore<3, double>::computePDEPatch, which compute() runs first
whatever the method. gsBarrierPatch2 works in the same installs with patchWise = True
(scripts/bench-peers.sh) and dies the same way with patchWise = False on one patch.
A benchmark helper run by hand in a venv:
    python3 -m venv /tmp/pg && /tmp/pg/bin/pip install pygismo==26.9.0
    /tmp/pg/bin/python scripts/gismo_barrier3_crash.py ParamMethod=2; echo "exit $?"
prints OK and exits 0 where gsBarrierPatch3 works, exits 139 where it crashes."""
import sys

import numpy as np
import pygismo as gs

kv = gs.nurbs.gsKnotVector(np.array([0, 0, 0, 0.5, 1, 1, 1.0]), 2)
basis = gs.nurbs.gsTensorBSplineBasis3(kv, kv, kv)
g = np.linspace(0, 1, 4)
cps = np.array([[x + 0.1 * y * z, y, z] for z in g for y in g for x in g])
mp = gs.core.gsMultiPatch()
mp.addPatch(gs.nurbs.gsTensorBSpline3(basis, cps))
bp = gs.modelling.gsBarrierPatch3(mp, False)
options = bp.options()
for arg in sys.argv[1:]:
    key, value = arg.split("=")
    options.setInt(key, int(value))
bp.compute()
print("OK", bp.result().nPatches())
