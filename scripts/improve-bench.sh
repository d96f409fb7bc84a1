#!/usr/bin/env bash
# `--improve winslow` on every shared geometry (tests/data, tests/data/gismo): solves each
# with the given `winslow` binary and prints a Markdown table of the Winslow value
# (eq. 16), the smallest scaled Jacobian and the largest orthogonality deviation before
# and after the improvement stage, its iterations and time, and the time of the EGG solve
# before it (the report's total minus the stage: the report's `seconds` count the levels,
# repair and certificate, not the boundary fit nor the report's own measurements; on solves
# of 1-3 ms one run resolves the ratio to about 10 %, `cargo bench --bench improve` times
# both warm). Extra arguments go to `winslow solve`.
#
#   cargo build --release -p winslow-cli
#   bash scripts/improve-bench.sh target/release/winslow
#   IMPROVE=weak bash scripts/improve-bench.sh target/release/winslow   # the weak form (eq. 14)
#
# Needs jq. A benchmark: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
shift
improve=${IMPROVE:-winslow}
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| geometry | verdict | DOFs | Winslow before | Winslow after | min scaled J before | after | orthogonality max before (deg) | after | accepted | iterations | improve s | EGG solve s | ratio | max move / diam |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|"
for f in tests/data/*.json tests/data/gismo/*.json; do
  name=$(basename "$f" .json)
  rc=0
  "$bin" solve "$f" -o "$tmp/$name.json" --improve "$improve" --json -q "$@" >"$tmp/$name.report.json" 2>"$tmp/$name.log" || rc=$?
  if [ ! -s "$tmp/$name.report.json" ]; then
    echo "| $name | error (exit $rc) | | | | | | | | | | | | | |"
    continue
  fi
  jq -r --arg name "$name" '
    def f(n): if . == null then "-" else (. * pow(10; n) | round / pow(10; n) | tostring) end;
    .improvement as $i
    | (.seconds - ($i.seconds // 0)) as $egg
    | "| \($name) | \(.verdict) | \(.levels[-1].unknowns) | \($i.before.winslow | f(6)) | \($i.after.winslow | f(6)) | \($i.before.scaled_jacobian_min | f(4)) | \($i.after.scaled_jacobian_min | f(4)) | \($i.before.orthogonality_max_degrees | f(2)) | \($i.after.orthogonality_max_degrees | f(2)) | \(if $i.accepted then "yes" else "no: " + ($i.failure // $i.message) end) | \($i.iterations) | \($i.seconds | f(3)) | \($egg | f(3)) | \(($i.seconds / $egg) | f(2)) | \($i.max_displacement | . * 1e6 | round / 1e6 | tostring) |"
  ' "$tmp/$name.report.json"
done
