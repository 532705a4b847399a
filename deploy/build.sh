#!/usr/bin/env bash
# Configures and builds bodyscan (Release, Ninja, ccache) into ./build.
# Usage: [BUILD_TARGETS="bodyscan web"] deploy/build.sh [extra cmake args]
# (BUILD_TARGETS: only these targets; default everything, tests and benchmarks too)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
BUILD_TYPE=${BUILD_TYPE:-Release}
export CCACHE_DIR=${CCACHE_DIR:-$PWD/.cache/ccache}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" "$@" >/dev/null
# shellcheck disable=SC2086  # BUILD_TARGETS is a list of names
cmake --build "$BUILD_DIR" -j "$(nproc)" ${BUILD_TARGETS:+--target $BUILD_TARGETS}
