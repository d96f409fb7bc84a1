#!/usr/bin/env bash
# Solves every bundled geometry (tests/data, tests/data/gismo, tests/data/gismo/xml) with
# the given `winslow` binary and writes each map with the time-dependent report fields
# (every key ending in "seconds") removed and keys sorted, so that the outputs of two
# builds can be compared byte for byte (a refactor must not change results); the
# progress on stderr goes to NAME.log (timings differ from run to run):
#
#   cargo build --release -p winslow-cli && cp target/release/winslow /tmp/winslow-before
#   bash scripts/solve-digest.sh /tmp/winslow-before /tmp/before
#   ... change, rebuild ...
#   bash scripts/solve-digest.sh target/release/winslow /tmp/after
#   diff -r -x "*.log" /tmp/before /tmp/after && echo identical
#
# Needs jq. A development tool: CI does not run it.
set -euo pipefail
bin=$(realpath "$1")
out=$2
shift 2
cd "$(dirname "$0")/.."
mkdir -p "$out"
for f in tests/data/*.json tests/data/gismo/*.json tests/data/gismo/xml/*.xml; do
  name=$(basename "$f")
  name=${name%.*}
  case "$f" in *.xml) name="xml_$name" ;; esac
  rc=0
  "$bin" solve "$f" -o "$out/$name.map.json" "$@" >/dev/null 2>"$out/$name.log" || rc=$?
  echo "$rc" >"$out/$name.exit"
  if [ -f "$out/$name.map.json" ]; then
    jq -S 'walk(if type == "object" then with_entries(select(.key | test("seconds$") | not)) else . end)' \
      "$out/$name.map.json" >"$out/$name.digest.json"
    rm "$out/$name.map.json"
  fi
  echo "$name: exit $rc"
done
