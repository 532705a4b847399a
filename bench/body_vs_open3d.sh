#!/usr/bin/env bash
# Figure 2 of the reconstruction issue, side by side in one run: 1M points sampled
# from the demo body with 0.5 mm noise, reconstructed by bodyscan (defaults, normals
# estimated) and by Open3D (estimate_normals + orient_normals_consistent_tangent_plane
# + Screened Poisson depth 9); both meshes measured against the true mesh by the
# same code. Usage: bench/body_vs_open3d.sh [POINTS] [OUTDIR] [--json OUT.json]
# (--json: both sides' figures, each process's wall time and peak memory included,
# with the run's provenance, for bench/tables.py).
set -euo pipefail
cd "$(dirname "$0")/.."
POINTS=${1:-1000000}
OUT=${2:-out/bench-body}
JSON=""
if [[ "${3:-}" == --json && -n "${4:-}" ]]; then JSON="$(realpath "$4")"; fi
BODY=hw/sim/bodies/male_average.ply
deploy/install-deps.sh --bench
deploy/build.sh
mkdir -p "$OUT"
echo "== machine: $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, $(uname -r)"
echo "== bodyscan (library, in-process, includes sampling-free timing)"
./build/bench/body_benchmark --body "$BODY" --points "$POINTS" --noise 0.5 \
  --cloud-out "$OUT/points.ply" --mesh-out "$OUT/bodyscan.ply" --json "$OUT/bodyscan.json"
echo
echo "== bodyscan reconstruct (the CLI, whole process incl. PLY read/write)"
/usr/bin/time -f "process: %e s wall, %M KB peak RSS" -o "$OUT/bodyscan.time" \
  ./build/app/bodyscan reconstruct "$OUT/points.ply" -o "$OUT/bodyscan_cli.ply" -q
cat "$OUT/bodyscan.time"
echo
echo "== Open3D"
/usr/bin/time -f "process: %e s wall, %M KB peak RSS" -o "$OUT/open3d.time" \
  /usr/bin/python3 bench/open3d_body.py "$OUT/points.ply" "$OUT/open3d.ply" --json "$OUT/open3d.json"
cat "$OUT/open3d.time"
./build/bench/body_benchmark --body "$BODY" --evaluate "$OUT/open3d.ply" --json "$OUT/open3d_accuracy.json"
if [[ -n "$JSON" ]]; then
  /usr/bin/python3 - "$OUT" <<'EOF' | bench/tables.py --wrap "$JSON" "bench/body_vs_open3d.sh $POINTS $OUT --json OUT.json"
import json, re, sys
out = sys.argv[1]
def process(name):  # the whole process, as /usr/bin/time measured it
    m = re.search(r"process: ([\d.]+) s wall, (\d+) KB", open(f"{out}/{name}.time").read())
    return {"process_seconds": float(m[1]), "process_peak_mb": int(m[2]) / 1024}
ours = json.load(open(f"{out}/bodyscan.json"))["records"][0] | process("bodyscan")
theirs = json.load(open(f"{out}/open3d.json")) | json.load(open(f"{out}/open3d_accuracy.json"))["records"][0]
theirs |= process("open3d") | {"mesh": "open3d"}
print(json.dumps([ours, theirs]))
EOF
fi
