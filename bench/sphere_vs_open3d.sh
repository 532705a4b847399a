#!/usr/bin/env bash
# The nonuniform sphere (density varying RATIO x across the sphere, default 8) of the
# reconstruction issue, side by side with Open3D on the very same clouds: bodyscan
# defaults and tuned (sphere_table) against Open3D's estimate_normals +
# orient_normals_consistent_tangent_plane + Screened Poisson at its best depth (so
# Open3D is tuned per cell, our defaults are not; TUNED=1 adds our tuned search).
# Usage: bench/sphere_vs_open3d.sh [RATIO] [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
RATIO=${1:-8}
OUT=${2:-out/bench-sphere}
deploy/install-deps.sh --bench
deploy/build.sh
mkdir -p "$OUT"
echo "== bodyscan (sphere_table --nonuniform $RATIO)"
./build/bench/sphere_table --nonuniform "$RATIO" --cloud-dir "$OUT" --defaults ${TUNED:+--tuned} | tee "$OUT/bodyscan.md"
echo
echo "== Open3D on the same clouds (RMS of |v| - 1 at its best Poisson depth)"
echo "| N | s | open3d | depth |"
echo "|---:|---:|---:|---:|"
for f in "$OUT"/sphere_*.ply; do
  base=$(basename "$f" .ply)
  n=$(echo "$base" | cut -d_ -f2)
  s=$(echo "$base" | cut -d_ -f3)
  best=$(/usr/bin/python3 bench/open3d_sphere.py "$f" | awk '/^best/{print $5, $3}')
  echo "| $n | $s | ${best% *} | ${best#* } |"
done | sort -t'|' -k2,2nr -k3,3n
