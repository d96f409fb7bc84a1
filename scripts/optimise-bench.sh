#!/usr/bin/env bash
# The paper's Table 3 (§10.3) on our geometries: the constrained optimisation of Gravesen
# et al. (min Liao / Winslow / area orthogonality subject to d(c) >= eps, SQP with Clarabel
# subproblems) started from the EGG map (G) and from the max-z point of eq. (49) reached
# from the Coons patch (Z), on the EGG map's basis (coarse: --fit-tol 1e-2). Prints a
# Markdown table: iterations from each start (restoration LPs + SQP QPs), whether each
# ended converged and certified, the functional values of the two starts (the paper's
# L(G), L(Z), ...), and the optimum reached. A benchmark, run by hand: CI does not call it.
#   scripts/optimise-bench.sh [WINSLOW_BIN] [OUT_DIR]
#   (GEOMS="tests/data/gismo/duck.json ..." and FUNCTIONALS="liao winslow ao" narrow it;
#    FIT_TOL, EPS and MAX_IT change the basis, eps and the iteration limit)
# Needs jq.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${1:-target/release/winslow}
OUT=${2:-out/optimise-bench}
GEOMS=${GEOMS:-"tests/data/gismo/duck.json tests/data/gismo/puzzle3.json tests/data/notched_square.json tests/data/horseshoe.json tests/data/narrow_tube.json"}
FUNCTIONALS=${FUNCTIONALS:-"liao winslow ao"}
FIT_TOL=${FIT_TOL:-1e-2}
EPS=${EPS:-1e-2}
MAX_IT=${MAX_IT:-200}
mkdir -p "$OUT"
echo "| geometry | basis | unknowns | functional | IT(G) | IT(Z) | max-z LPs | conv/cert G | conv/cert Z | L(G) | L(Z) | W(G) | W(Z) | AO(G) | AO(Z) | optimum G | optimum Z |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for g in $GEOMS; do
  name=$(basename "$g" .json)
  for f in $FUNCTIONALS; do
    js="$OUT/$name-$f.json"
    "$W" optimise "$g" --functional "$f" --from both --fit-tol "$FIT_TOL" --eps "$EPS" --max-iterations "$MAX_IT" --json >"$js" 2>/dev/null || true
    jq -r --arg f "$f" '
      def yn(b): if b then "yes" else "NO" end;
      def v(x): if x == null then "inf" else (x * 1000 | round / 1000 | tostring) end;
      def val(r): if $f == "liao" then r.values.liao elif $f == "winslow" then r.values.winslow else r.values.area_orthogonality end;
      .runs as [$g, $z] |
      "| \(.boundary | split("/") | last | sub(".json"; "")) | \(.basis[0])x\(.basis[1]) | \(.unknowns) | \($f) | \($g.iterations) | \($z.iterations) | \($z.max_z.iterations) | \(yn($g.converged))/\(yn($g.certified)) | \(yn($z.converged))/\(yn($z.certified)) | \(v($g.start_values.liao)) | \(v($z.start_values.liao)) | \(v($g.start_values.winslow)) | \(v($z.start_values.winslow)) | \(v($g.start_values.area_orthogonality)) | \(v($z.start_values.area_orthogonality)) | \(v(val($g))) | \(v(val($z))) |"
    ' "$js" || echo "| $name | | | $f | failed: see $js | | | | | | | | | | | | |"
  done
done
