#!/usr/bin/env bash
# The main job, until the workstation server exists: install, build, then the whole
# scan on the simulated thesis rig with the shipped demo body - calibrate from what
# the cameras see (dot grid, frame lights, lasers on the poles), scan, turn the
# stripes into a point cloud, reconstruct the closed surface, measure it - and write
# the results to out/demo (points.ply, mesh.ply, mesh.glb, measurements.json,
# calibration.json, scan.json, raw/) and into the scan archive in out/data
# (docs/archive.md; `./build/server/bodyscan archive out/data list`).
set -euo pipefail
cd "$(dirname "$0")/.."
deploy/install-deps.sh
deploy/build.sh
OUT=${OUT:-out/demo}
mkdir -p "$OUT"
DATA=${DATA:-out/data}
./build/server/bodyscan scan --rig sim --out "$OUT" --archive "$DATA" --new-customer "Demo customer" --operator demo
