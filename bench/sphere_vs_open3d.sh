#!/usr/bin/env bash
# The nonuniform sphere (density varying RATIO x across the sphere, default 8) of the
# reconstruction issue, side by side with Open3D on the very same clouds: bodyscan
# defaults and tuned (sphere_table) against Open3D's estimate_normals +
# orient_normals_consistent_tangent_plane + Screened Poisson at its best depth (so
# Open3D is tuned per cell, our defaults are not; TUNED=1 adds our tuned search).
# Usage: bench/sphere_vs_open3d.sh [RATIO] [OUTDIR] [--json OUT.json]
# (--json: sphere_table's cells, each with Open3D's best depth and RMS, with the
# run's provenance, for bench/tables.py).
set -euo pipefail
cd "$(dirname "$0")/.."
RATIO=${1:-8}
OUT=${2:-out/bench-sphere}
JSON=""
if [[ "${3:-}" == --json && -n "${4:-}" ]]; then JSON="$(realpath "$4")"; fi
deploy/install-deps.sh --bench
deploy/build.sh
mkdir -p "$OUT"
echo "== bodyscan (sphere_table --nonuniform $RATIO)"
./build/bench/sphere_table --nonuniform "$RATIO" --cloud-dir "$OUT" --defaults ${TUNED:+--tuned} \
  --json "$OUT/bodyscan.json" | tee "$OUT/bodyscan.md"
echo
echo "== Open3D on the same clouds (RMS of |v| - 1 at its best Poisson depth)"
echo "| N | s | open3d | depth |"
echo "|---:|---:|---:|---:|"
for f in "$OUT"/sphere_*.ply; do
  base=$(basename "$f" .ply)
  n=$(echo "$base" | cut -d_ -f2)
  s=$(echo "$base" | cut -d_ -f3)
  /usr/bin/python3 bench/open3d_sphere.py "$f" --json "$OUT/$base.open3d.json" >/dev/null
  read -r depth rms < <(/usr/bin/python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["depth"], j["rms"])' \
    "$OUT/$base.open3d.json")
  echo "| $n | $s | $rms | $depth |"
done | sort -t'|' -k2,2nr -k3,3n
if [[ -n "$JSON" ]]; then
  /usr/bin/python3 - "$OUT" <<'EOF' | bench/tables.py --wrap "$JSON" "bench/sphere_vs_open3d.sh $RATIO $OUT --json OUT.json"
import json, sys
out = sys.argv[1]
records = json.load(open(f"{out}/bodyscan.json"))["records"]
for r in records:
    r["open3d"] = json.load(open(f"{out}/sphere_{r['points']}_{r['noise']:.2f}.open3d.json"))
print(json.dumps(records))
EOF
fi
