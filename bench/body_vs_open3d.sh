#!/usr/bin/env bash
# Figure 2 of the reconstruction issue, side by side in one run: 1M points sampled
# from the demo body with 0.5 mm noise, reconstructed by bodyscan (defaults, normals
# estimated) and by Open3D (estimate_normals + orient_normals_consistent_tangent_plane
# + Screened Poisson depth 9); both meshes measured against the true mesh by the
# same code. Usage: bench/body_vs_open3d.sh [POINTS] [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
POINTS=${1:-1000000}
OUT=${2:-out/bench-body}
BODY=hw/sim/bodies/male_average.ply
deploy/install-deps.sh --bench
deploy/build.sh
mkdir -p "$OUT"
echo "== machine: $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, $(uname -r)"
echo "== bodyscan (library, in-process, includes sampling-free timing)"
./build/bench/body_benchmark --body "$BODY" --points "$POINTS" --noise 0.5 \
  --cloud-out "$OUT/points.ply" --mesh-out "$OUT/bodyscan.ply"
echo
echo "== bodyscan reconstruct (the CLI, whole process incl. PLY read/write)"
/usr/bin/time -f "process: %e s wall, %M KB peak RSS" ./build/app/bodyscan reconstruct "$OUT/points.ply" -o "$OUT/bodyscan_cli.ply" -q
echo
echo "== Open3D"
/usr/bin/time -f "process: %e s wall, %M KB peak RSS" /usr/bin/python3 bench/open3d_body.py "$OUT/points.ply" "$OUT/open3d.ply"
./build/bench/body_benchmark --body "$BODY" --evaluate "$OUT/open3d.ply"
