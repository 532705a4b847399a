#!/usr/bin/env bash
# The checks of .clang-tidy (bugprone-*, and a limit on each function's cognitive
# complexity) over the product's code (core, recon, hw, storage, pipeline, server, app), as a ratchet:
# each check may warn at most as often as deploy/clang-tidy-baseline.txt allows,
# the count of the code when the checks came in. A change that adds a warning
# fails and is shown; one that removes warnings is told to lower the baseline
# (`deploy/check-tidy.sh --update`, and commit the file).
#
# Usage: deploy/check-tidy.sh [--update] [BUILD_DIR]   (default build-test, else build)
# Needs the build directory's compile_commands.json (deploy/build.sh makes it)
# and Debian 12's clang-tidy 14 (deploy/install-deps.sh --lint installs it):
# other versions have other checks, so the counts would not compare.
set -euo pipefail
cd "$(dirname "$0")/.."
update=false
build=""
for arg in "$@"; do
  case "$arg" in
    --update) update=true ;;
    *) build=$arg ;;
  esac
done
if [[ -z "$build" ]]; then
  build=${BUILD_DIR:-build-test}
  [[ -f "$build/compile_commands.json" ]] || build=build
fi
if [[ ! -f "$build/compile_commands.json" ]]; then
  echo "check-tidy: no $build/compile_commands.json: build first (deploy/build.sh)" >&2
  exit 1
fi
tool=""
for candidate in clang-tidy-14 clang-tidy; do
  if command -v "$candidate" >/dev/null; then tool=$candidate; break; fi
done
if [[ -z "$tool" ]] || ! "$tool" --version | grep -q 'version 14\.'; then
  echo "check-tidy: clang-tidy 14 is missing (deploy/install-deps.sh --lint installs it)" >&2
  exit 1
fi
baseline=deploy/clang-tidy-baseline.txt
if [[ -d .git ]] && command -v git >/dev/null; then
  mapfile -t files < <(git ls-files 'core/*.cpp' 'recon/*.cpp' 'hw/*.cpp' 'storage/*.cpp' 'pipeline/*.cpp' 'server/*.cpp' 'app/*.cpp')
else
  mapfile -t files < <(find core recon hw storage pipeline server app -name '*.cpp' | sort)
fi
out=$(mktemp)
trap 'rm -f "$out" "$out.found" "$out.counts"' EXIT
# Four files a run, one run per core; a header's warning is reported by every file
# that includes it and counted once.
printf '%s\0' "${files[@]}" | xargs -0 -n 4 -P "$(nproc)" "$tool" -p "$build" --quiet 2>/dev/null >"$out" || true
root="$PWD/"
grep -E '^[^ ].*:[0-9]+:[0-9]+: warning: .*\[[a-z0-9.,-]+\]$' "$out" | sed "s#^$root##" | sort -u >"$out.found" || true
sed -E 's/.*\[([a-z0-9.,-]+)\]$/\1/' "$out.found" | sort | uniq -c | awk '{print $2, $1}' >"$out.counts"
if $update; then
  {
    echo "# clang-tidy warnings allowed per check (deploy/check-tidy.sh): the product's"
    echo "# code as it is; a change may lower a count, never raise it."
    cat "$out.counts"
  } >"$baseline"
  echo "check-tidy: wrote $baseline ($(wc -l <"$out.found") warnings)"
  exit 0
fi
failed=false
while read -r check count; do
  allowed=$(awk -v c="$check" '$1 == c {print $2}' "$baseline")
  allowed=${allowed:-0}
  if ((count > allowed)); then
    echo "check-tidy: $check warns $count times, $allowed allowed:" >&2
    grep -F "[$check]" "$out.found" | sed 's/^/  /' >&2
    failed=true
  elif ((count < allowed)); then
    echo "check-tidy: $check warns $count times, fewer than the $allowed allowed: run deploy/check-tidy.sh --update and commit $baseline"
  fi
done <"$out.counts"
while read -r check allowed; do
  [[ "$check" == \#* ]] && continue
  if ! grep -q "^$check " "$out.counts" && ((allowed > 0)); then
    echo "check-tidy: $check no longer warns ($allowed allowed): run deploy/check-tidy.sh --update and commit $baseline"
  fi
done <"$baseline"
if $failed; then exit 1; fi
echo "check-tidy: ${#files[@]} files, $(wc -l <"$out.found") warnings, none beyond $baseline"
