#!/usr/bin/env bash
# The surface against Kazhdan's Screened Poisson (PoissonRecon), side by side in one
# run, on two clouds:
#  - uniform: POINTS points sampled from the demo body with 0.5 mm noise per axis;
#    PoissonRecon depth 9 gets PCA normals (20 neighbours) turned to the true side;
#  - scan: the demo body scanned on the tiered rig (measure_benchmark --save, about
#    ten minutes, kept in OUTDIR for the next run); PoissonRecon depth 10 gets PCA
#    normals turned toward the camera that saw each point, bodyscan the scan job's
#    settings (`bodyscan reconstruct --body`).
# Each side is one process timed by /usr/bin/time (wall, peak RSS); PoissonRecon's
# time adds the normals' (body_benchmark --oriented-out). Both meshes are measured
# against the true mesh by the same code (body_benchmark --evaluate).
#
# PoissonRecon is not part of the product: it is looked for at $POISSONRECON, else
# ../shared/tools/poissonrecon/PoissonRecon (a benchmark-only build, MIT); where it
# is absent the comparison is skipped and says so.
#
# Usage: bench/surface_vs_poissonrecon.sh [--points N] [--out OUTDIR] [--json OUT.json]
set -euo pipefail
cd "$(dirname "$0")/.."
POINTS=1000000
OUT=out/bench-poisson
JSON=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --points) POINTS="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --json) JSON="$(realpath -m "$2")"; shift 2 ;;
    *) echo "usage: bench/surface_vs_poissonrecon.sh [--points N] [--out OUTDIR] [--json OUT.json]" >&2; exit 2 ;;
  esac
done
BODY=hw/sim/bodies/male_average.ply
POISSON=${POISSONRECON:-../shared/tools/poissonrecon/PoissonRecon}
deploy/install-deps.sh --bench
deploy/build.sh
mkdir -p "$OUT"
have_poisson=1
if [[ ! -x "$POISSON" ]]; then
  have_poisson=0
  echo "== PoissonRecon not found at $POISSON: the comparison is skipped, bodyscan runs alone"
fi
echo "== machine: $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, $(uname -r)"

timed() {  # timed NAME COMMAND...: runs it, /usr/bin/time's wall and peak RSS into OUT/NAME.time
  local name="$1"
  shift
  /usr/bin/time -f "process: %e s wall, %M KB peak RSS" -o "$OUT/$name.time" "$@"
  cat "$OUT/$name.time"
}

# run CASE TRUTH CLOUD ORIENTED DEPTH BODYSCAN_OPTIONS...
run() {
  local case="$1" truth="$2" cloud="$3" oriented="$4" depth="$5"
  shift 5
  echo
  echo "== $case: bodyscan reconstruct $*"
  timed "$case-bodyscan" ./build/app/bodyscan reconstruct "$cloud" -o "$OUT/$case-bodyscan.ply" -q "$@"
  ./build/bench/body_benchmark --body "$truth" --evaluate "$OUT/$case-bodyscan.ply" --json "$OUT/$case-bodyscan.json"
  if [[ $have_poisson == 1 ]]; then
    echo "== $case: PoissonRecon --depth $depth"
    OMP_WAIT_POLICY=passive timed "$case-poisson" "$POISSON" --in "$oriented" --out "$OUT/$case-poisson.ply" \
      --depth "$depth"
    ./build/bench/body_benchmark --body "$truth" --evaluate "$OUT/$case-poisson.ply" --json "$OUT/$case-poisson.json"
  fi
}

echo "== uniform: $POINTS points from $BODY, 0.5 mm noise"
./build/bench/body_benchmark --body "$BODY" --points "$POINTS" --noise 0.5 --cloud-out "$OUT/uniform.ply" \
  --oriented-out "$OUT/uniform-oriented.ply" --json "$OUT/uniform-normals.json"
run uniform "$BODY" "$OUT/uniform.ply" "$OUT/uniform-oriented.ply" 9

SCAN="$OUT/scan/$(basename "$BODY")"
if [[ ! -f "$SCAN-cloud.ply" || ! -f "$SCAN-truth.ply" ]]; then
  echo
  echo "== scan: $BODY on the tiered rig (measure_benchmark --save $OUT/scan)"
  ./build/bench/measure_benchmark --rig tiered --body "$BODY" --save "$OUT/scan" > "$OUT/scan.log"
fi
./build/bench/body_benchmark --cloud "$SCAN-cloud.ply" --oriented-out "$OUT/scan-oriented.ply" \
  --json "$OUT/scan-normals.json"
run scan "$SCAN-truth.ply" "$SCAN-cloud.ply" "$OUT/scan-oriented.ply" 10 --body

if [[ -n "$JSON" ]]; then
  /usr/bin/python3 - "$OUT" "$have_poisson" <<'EOF' | bench/tables.py --wrap "$JSON" \
    "bench/surface_vs_poissonrecon.sh --points $POINTS --out $OUT --json OUT.json"
import json, re, sys
out, have_poisson = sys.argv[1], sys.argv[2] == "1"
def process(name):  # the whole process, as /usr/bin/time measured it
    m = re.search(r"process: ([\d.]+) s wall, (\d+) KB", open(f"{out}/{name}.time").read())
    return {"process_seconds": float(m[1]), "process_peak_mb": int(m[2]) / 1024}
rows = []
for case in ("uniform", "scan"):
    normals = json.load(open(f"{out}/{case}-normals.json"))["records"][0]
    for method in ("bodyscan", "poisson") if have_poisson else ("bodyscan",):
        row = json.load(open(f"{out}/{case}-{method}.json"))["records"][0] | process(f"{case}-{method}")
        row |= {"case": case, "method": method, "points": normals["points"]}
        if method == "poisson":
            row |= {"depth": 9 if case == "uniform" else 10, "normals_seconds": normals["normals_seconds"]}
        rows.append(row)
print(json.dumps(rows))
EOF
fi
