#!/usr/bin/env bash
# The main job: install, build, make a demo scan, then run the workstation.
#
# 1. The whole scan on the simulated thesis rig with the shipped demo body -
#    calibrate from what the cameras see (dot grid, frame lights, lasers on the
#    poles), scan, turn the stripes into a point cloud, reconstruct the closed
#    surface, measure it - written to out/demo (points.ply, mesh.ply, mesh.glb,
#    measurements.json, calibration.json, scan.json, raw/) and stored in the
#    archive in out/data (docs/archive.md). Skipped when the archive already has
#    a scan (DEMO_SCAN=1 makes another).
# 2. `bodyscan serve` on that archive (docs/api.md): the simulated rig, the API
#    and the browser UI on http://localhost:8080/, with the demo scan ready. The
#    first admin's password is printed on the first start (and kept in
#    out/data/first-admin-password) unless BODYSCAN_ADMIN_PASSWORD sets it.
#    Ctrl-C stops it cleanly (lasers off, a running scan marked cancelled).
set -euo pipefail
cd "$(dirname "$0")/.."
deploy/install-deps.sh
deploy/install-web.sh
BUILD_TARGETS="bodyscan web" deploy/build.sh  # the program and the UI; tests come with run-tests.sh
OUT=${OUT:-out/demo}
DATA=${DATA:-out/data}
PORT=${PORT:-8080}
mkdir -p "$OUT"
if [[ "${DEMO_SCAN:-}" == 1 || ! -s "$DATA/archive.db" ]] ||
   ! ./build/app/bodyscan archive "$DATA" list | grep -q complete; then
  ./build/app/bodyscan scan --rig sim --out "$OUT" --archive "$DATA" --new-customer "Demo customer" --operator demo
fi
exec ./build/app/bodyscan serve --rig sim --data "$DATA" --port "$PORT"
