#!/usr/bin/env bash
# The main job, until the workstation server exists: install, build, then scan-
# and-reconstruct the shipped demo body end to end and report. Today the "scan" is
# a million points sampled from the demo body with 0.5 mm Gaussian noise (the
# simulated rig that renders camera frames arrives with the rig issue); the report
# is the reconstruction's size, time and accuracy against the true mesh.
set -euo pipefail
cd "$(dirname "$0")/.."
deploy/install-deps.sh
deploy/build.sh
OUT=${OUT:-out/demo}
mkdir -p "$OUT"
./build/bench/body_benchmark --body hw/sim/bodies/male_average.ply --points "${POINTS:-1000000}" \
  --noise 0.5 --cloud-out "$OUT/points.ply" --mesh-out "$OUT/mesh.ply"
echo
echo "The same with the command-line tool:"
./build/server/bodyscan reconstruct "$OUT/points.ply" -o "$OUT/mesh_cli.ply"
