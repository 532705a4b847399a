#!/usr/bin/env bash
# The browser UI: time from opening a scan to its first rendered frame, the BVH
# build and picking (docs/benchmarks.md §10).
#   [RUNS=5] [BODYSCAN_BIN=build/server/bodyscan] [BODYSCAN_WEB_ROOT=build/web] bench/ui_first_frame.sh
# Builds nothing (run deploy/build.sh first); needs Chromium (deploy/install-deps.sh
# --browser). Makes, once, two archives of the demo body in out/bench-ui: a scan at
# every 3rd laser step (about 630 k triangles: the issue's 500 k-triangle body) and
# the full scan (1.57 M triangles, ~3 min). Then web/bench/first-frame.mjs serves
# each with `bodyscan serve` and opens its scan in headless Chromium RUNS times.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
export BODYSCAN_BIN="$(realpath "${BODYSCAN_BIN:-$here/build/server/bodyscan}")"
export BODYSCAN_WEB_ROOT="$(realpath "${BODYSCAN_WEB_ROOT:-$here/build/web}")"
out="$here/out/bench-ui"
mkdir -p "$out"
for every in 3 1; do
  dir="$out/every$every"
  if ! "$BODYSCAN_BIN" archive "$dir" list 2>/dev/null | grep -q complete; then
    echo "ui_first_frame: scanning the demo body at every ${every} laser step(s) into $dir" >&2
    rm -rf "$dir"
    "$BODYSCAN_BIN" scan --rig sim --every "$every" --archive "$dir" --new-customer "Benchmark" -q
  fi
done
cd "$here/web"
exec node bench/first-frame.mjs --runs "${RUNS:-5}" "every 3rd step=$out/every3" "full scan=$out/every1"
