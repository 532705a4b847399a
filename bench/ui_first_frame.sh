#!/usr/bin/env bash
# The browser UI: time from opening a scan to its first rendered frame and to
# picking ready, the display mesh the app serves against the whole surface, side
# by side in one run (docs/benchmarks.md §10).
#   [RUNS=5] [BODYSCAN_BIN=build/app/bodyscan] [BODYSCAN_WEB_ROOT=build/web] bench/ui_first_frame.sh [--json OUT.json]
# Builds nothing (run deploy/build.sh first); needs Chromium (deploy/install-deps.sh
# --browser). Makes, once, an archive of the demo body's full scan in
# out/bench-ui/every1 (1.55 M triangles, ~3 min; its mesh.glb the display mesh of
# 500 k) and exports its whole surface as a GLB beside it. Then
# web/bench/first-frame.mjs serves the archive with `bodyscan serve` and opens the
# scan in headless Chromium RUNS times with each model. --json writes the table's
# rows with the run's provenance (bench/tables.py --wrap).
set -euo pipefail
json_out=""
if [[ "${1:-}" == --json && -n "${2:-}" ]]; then json_out="$(realpath "$2")"; fi
here="$(cd "$(dirname "$0")/.." && pwd)"
export BODYSCAN_BIN="$(realpath "${BODYSCAN_BIN:-$here/build/app/bodyscan}")"
export BODYSCAN_WEB_ROOT="$(realpath "${BODYSCAN_WEB_ROOT:-$here/build/web}")"
out="$here/out/bench-ui"
dir="$out/every1"
mkdir -p "$out"
if ! "$BODYSCAN_BIN" archive "$dir" list 2>/dev/null | grep -q complete; then
  echo "ui_first_frame: scanning the demo body in full into $dir" >&2
  rm -rf "$dir"
  "$BODYSCAN_BIN" scan --rig sim --archive "$dir" --new-customer "Benchmark" -q
fi
scan="$("$BODYSCAN_BIN" archive "$dir" list | awk '$2 == "complete" { print $1; exit }')"
"$BODYSCAN_BIN" archive "$dir" mesh "$scan" -o "$out/every1-whole.glb" >/dev/null
cd "$here/web"
rows="$out/rows.json"
node bench/first-frame.mjs --runs "${RUNS:-5}" ${json_out:+--json "$rows"} \
  "display mesh=$dir" "whole surface=$dir=$out/every1-whole.glb"
if [[ -n "$json_out" ]]; then
  "$here/bench/tables.py" --wrap "$json_out" "RUNS=${RUNS:-5} bench/ui_first_frame.sh --json OUT.json" <"$rows"
fi
