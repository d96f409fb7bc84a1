#!/usr/bin/env bash
# The automatic layout against the hand-made one (issue 31): for each shared G+Smo
# multipatch geometry, the hand-made layout solved as it is (`winslow solve FILE.xml`,
# fixed interfaces, the input bases), and its outline (`winslow convert FILE.xml
# --outline`: the outer boundary and holes, tangent joints merged) laid out and solved
# automatically (`winslow solve DOMAIN.json`). One row per layout: patches, the worst
# patch's min scaled Jacobian (the smallest `report.solve.quality.scaled_jacobian.min`
# over the patches: det J / (|x_xi| |x_eta|) at the (p+2)^2 Gauss points of every
# element), the total Winslow value (`report.winslow`, eq. 16 summed over the patches)
# and that total over twice the patch count (its lower bound: every patch's value is at
# least 2, equality for a conformal map), and the verdict.
#
#   bash scripts/layout-vs-hand.sh target/debug/winslow [SMOOTH_BELOW_DEGREES]
#
# A benchmark: CI does not run it.
set -uo pipefail
bin=$(realpath "$1")
smooth=${2:-5}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
row() {
  python3 - "$1" "$2" <<'PY'
import json, sys
what, path = sys.argv[1], sys.argv[2]
try:
    d = json.load(open(path))
except OSError:
    print(f"| {what} | - | - | - | - | no map written |")
    sys.exit()
patches = d.get("patches") or []
if not patches or d["report"].get("winslow") is None:
    print(f"| {what} | - | - | - | - | {d['report'].get('message', 'no map')} |")
    sys.exit()
sj = min(p["report"]["solve"]["quality"]["scaled_jacobian"]["min"] for p in patches)
w = d["report"]["winslow"]
print(f"| {what} | {len(patches)} | {sj:.4f} | {w:.4f} | {w / (2 * len(patches)):.4f} | {d['report']['verdict']} |")
PY
}
echo "| layout | patches | worst min scaled Jacobian | Winslow value | Winslow / (2 patches) | verdict |"
echo "|---|---:|---:|---:|---:|---|"
for g in plateWithHoleMP TUDflame; do
  xml=tests/data/gismo/xml/multipatch/$g.xml
  "$bin" solve "$xml" -o "$tmp/$g-hand.json" -q
  row "$g, hand-made" "$tmp/$g-hand.json"
  "$bin" convert "$xml" --outline --smooth-below "$smooth" -o "$tmp/$g-domain.json" -q
  # a folded or undecided map is written (exit 3) and says so in its verdict; with -q
  # only an error (no map) prints anything
  err=$("$bin" solve "$tmp/$g-domain.json" -o "$tmp/$g-auto.json" -q 2>&1)
  rc=$?
  if [ "$rc" -ne 0 ]; then
    echo "$g, automatic: exit $rc${err:+: $err}" >&2
  fi
  row "$g, automatic" "$tmp/$g-auto.json"
done
