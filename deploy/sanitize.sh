#!/usr/bin/env bash
# The sanitizer and fuzzing pass of the test command (deploy/run-tests.sh; CI):
# builds bodyscan with clang, AddressSanitizer and UndefinedBehaviorSanitizer
# into ./build-san, runs the storage, hardware and server tests on that build,
# then runs each libFuzzer target (fuzz/) from its corpus for FUZZ_SECONDS
# (default 60), one per core at a time. Any sanitizer report or fuzzer finding
# fails it; a fuzzer's crashing input is left in build-san/fuzz-findings/.
#
#   deploy/sanitize.sh              tests, then fuzzing
#   deploy/sanitize.sh --fuzz-only  fuzzing only (e.g. FUZZ_SECONDS=3600 for an hour each)
#
# Needs clang and its runtime libraries (deploy/install-deps.sh --sanitize).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${SAN_BUILD_DIR:-build-san}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
fuzz_only=0
for arg in "$@"; do
  case "$arg" in
    --fuzz-only) fuzz_only=1 ;;
    *) echo "sanitize: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

fuzzers=(ply_fuzzer png_fuzzer json_body_fuzzer http_request_fuzzer)
targets=("${fuzzers[@]}")
((fuzz_only)) || targets+=(bodyscan storage_tests hw_tests server_tests)

export CCACHE_DIR=${CCACHE_DIR:-$PWD/.cache/ccache}
# The fuzzers' coverage guidance is added where they need it (fuzz/CMakeLists.txt).
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBODYSCAN_WEB=OFF -DBODYSCAN_BUILD_BENCH=OFF -DBODYSCAN_FUZZ=ON -DCMAKE_CXX_FLAGS="$flags" >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)" --target "${targets[@]}"

# Leaks are reported at exit; a report of any kind ends the process with an error.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:allow_user_segv_handler=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/deploy/lsan-suppressions.txt:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if ((!fuzz_only)); then
  # Left out: the test that runs the server out of descriptors (UBSan's type
  # check opens a pipe to probe an object's memory, and without one reports every
  # type it checks as invalid), and the three that scan a whole body and
  # reconstruct it, the posture check's sweep among them (tens of minutes under
  # the sanitizers, past their waits); the other scan tests stop mid-scan.
  (cd "$BUILD_DIR" && ctest --output-on-failure -j "$(nproc)" --timeout 900 -L 'storage|hw|server' \
    -E 'ServeCli.RunningOutOfDescriptorsBacksOffAndRecovers|ServeCli.SigtermMidScanCancelsTheScanAndStopsCleanly|ApiScan.SimulatedScanThroughTheApiWithLiveEvents|ApiScan.PostureCheckReadsHowTheCustomerStandsAndStoresNothing')
fi

findings="$BUILD_DIR/fuzz-findings"
mkdir -p "$findings"
# One fuzzer per core at a time (each is a single process); the first that finds
# a problem fails the pass once the running ones end.
fuzz() {
  local f=$1 name=${1%_fuzzer} work status=0
  work=$(mktemp -d)  # new inputs the run finds; the corpus in the repo stays as it is
  local log="$findings/$name.log"
  (cd "$BUILD_DIR" && "./fuzz/$f" -max_total_time="$FUZZ_SECONDS" -max_len=65536 -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="$PWD/fuzz-findings/$name-" -print_final_stats=1 "$work" "$OLDPWD/fuzz/corpus/$name") \
    >"$log" 2>&1 || status=$?
  rm -rf "$work"
  # One write, so that the fuzzers running side by side do not interleave their lines.
  printf 'sanitize: %s ran %s s from fuzz/corpus/%s\n%s\n' "$f" "$FUZZ_SECONDS" "$name" \
    "$(grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss_mb)" "$log" || true)"
  if ((status != 0)); then
    tail -n 60 "$log" >&2
    echo "sanitize: $f found a problem (exit $status); the input is in $findings, the log in $log" >&2
    return 1
  fi
}
failed=0
pids=()
for f in "${fuzzers[@]}"; do
  if ((${#pids[@]} >= $(nproc))); then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
  fuzz "$f" &
  pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
((failed == 0)) || exit 1
echo "sanitize: tests and fuzzers clean"
