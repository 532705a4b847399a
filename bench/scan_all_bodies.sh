#!/usr/bin/env bash
# The scan pipeline's figures (docs/benchmarks.md §6) on both shipped rigs for every
# body: the shared bodies next to the clone (../shared/data/bodies) when present,
# else the two shipped with the simulator.
#   bench/scan_all_bodies.sh [BUILD_DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
bodies=("$here"/../shared/data/bodies/*.ply)
[[ -e "${bodies[0]}" ]] || bodies=("$here"/hw/sim/bodies/*.ply)
args=()
for b in "${bodies[@]}"; do args+=(--body "$(realpath "$b")"); done
exec "$build/bench/scan_benchmark" --rig thesis --rig square "${args[@]}"
