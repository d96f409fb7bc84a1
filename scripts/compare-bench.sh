#!/usr/bin/env bash
# `winslow compare` (paper §10, Tables 1-2) on every shared geometry (tests/data,
# tests/data/gismo): EGG, the variational harmonic method (eq. 46) and the quasi-conformal
# functional (eq. 47-48) on one basis, from one start. Prints a Markdown table: per
# method the nonlinear iterations (IT), whether it converged, the certificate's verdict
# (BIJ), Q(x)/Q(x_G) and the seconds; the ratio IT(VHM)/IT(EGG) where both converged to
# certified maps; the geometry's basis. Extra arguments go to `winslow compare`.
#
#   cargo build --release -p winslow-cli
#   bash scripts/compare-bench.sh target/release/winslow
#   TIMEOUT=120 bash scripts/compare-bench.sh target/release/winslow --levels 3
#
# A geometry whose comparison takes longer than TIMEOUT seconds (default 900) is a row
# saying so. Needs jq. A benchmark: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
shift
limit=${TIMEOUT:-900}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| geometry | basis | EGG IT | EGG BIJ | VHM IT | VHM BIJ | VHM Q/Q(x_G) | IT VHM / EGG | QC IT | QC BIJ | QC Q/Q(x_G) | EGG s | VHM s | QC s |"
echo "|---|---|---:|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|"
for f in tests/data/*.json tests/data/gismo/*.json; do
  name=$(basename "$f" .json)
  rc=0
  timeout "$limit" "$bin" compare "$f" --json "$@" >"$tmp/$name.json" 2>"$tmp/$name.log" || rc=$?
  if [ "$rc" = 124 ]; then
    echo "| $name | timeout (${limit} s) | | | | | | | | | | | | |"
    continue
  fi
  if [ ! -s "$tmp/$name.json" ]; then
    echo "| $name | error (exit $rc): $(tail -n 1 "$tmp/$name.log") | | | | | | | | | | | | |"
    continue
  fi
  jq -r --arg name "$name" '
    def f(n): if . == null then "-" else (. * pow(10; n) | round / pow(10; n) | tostring) end;
    def row(m): (.rows[] | select(.method == m)) // null;
    def it(r): if r == null then "-" elif r.converged then (r.iterations | tostring) else "\(r.iterations) (not converged)" end;
    def bij(r): if r == null then "-" elif r.measures == null then "error" else r.measures.verdict end;
    def good(r): r != null and r.converged and r.measures != null
      and (r.measures.verdict == "certified" or r.measures.verdict == "degenerate-corner");
    row("egg") as $e | row("vhm") as $v | row("qc") as $q
    | (if good($e) and good($v) then ($v.iterations / $e.iterations | f(1)) else "-" end) as $ratio
    | "| \($name) | \(.basis) \($e.measures.shape[0])x\($e.measures.shape[1]) | \(it($e)) | \(bij($e)) | \(it($v)) | \(bij($v)) | \($v.q_ratio | f(3)) | \($ratio) | \(it($q)) | \(bij($q)) | \($q.q_ratio | f(3)) | \($e.seconds | f(3)) | \($v.seconds | f(3)) | \($q.seconds | f(2)) |"
  ' "$tmp/$name.json"
done
