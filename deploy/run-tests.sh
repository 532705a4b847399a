#!/usr/bin/env bash
# Installs what the project needs, checks the C++ layout and the benchmark tables
# against their figures, builds everything (with asserts on), holds clang-tidy's
# warnings to the baseline, runs every test, then the sanitizer and fuzzing pass.
# CI calls this through .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."
deploy/install-deps.sh --browser --sanitize --lint
deploy/install-web.sh
deploy/check-format.sh
bench/tables.py --check  # docs/benchmarks.md's rendered tables against docs/figures
BUILD_DIR=${BUILD_DIR:-build-test} BUILD_TYPE=RelWithDebInfo deploy/build.sh -DBODYSCAN_WERROR=ON
deploy/check-tidy.sh "${BUILD_DIR:-build-test}"
(cd "${BUILD_DIR:-build-test}" && ctest --output-on-failure -j "$(nproc)" --timeout 600)
# The same code again under AddressSanitizer and UndefinedBehaviorSanitizer, and
# each parser's fuzzer for a minute (docs/security.md).
deploy/sanitize.sh
