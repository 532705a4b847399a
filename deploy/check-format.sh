#!/usr/bin/env bash
# Checks that every C++ source is laid out as .clang-format says; the test command
# runs it before building. `deploy/check-format.sh --fix` rewrites the files that
# are not. Needs Debian 12's clang-format (14; deploy/install-deps.sh installs it):
# other versions lay some constructs out differently, so the check refuses them
# rather than report layout they would change.
set -euo pipefail
cd "$(dirname "$0")/.."
fix=false
[[ "${1:-}" == "--fix" ]] && fix=true
tool=""
for candidate in clang-format-14 clang-format; do
  if command -v "$candidate" >/dev/null; then tool=$candidate; break; fi
done
if [[ -z "$tool" ]]; then
  echo "check-format: clang-format is missing (deploy/install-deps.sh installs it)" >&2
  exit 1
fi
version=$("$tool" --version | sed -n 's/.*version \([0-9]*\)\..*/\1/p')
if [[ "$version" != 14 ]]; then
  echo "check-format: $tool is version $version; the layout is defined by clang-format 14 (Debian 12's)" >&2
  exit 1
fi
if [[ -d .git ]] && command -v git >/dev/null; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cpp.in')
else
  mapfile -t files < <(find app bench core fuzz hw pipeline recon server storage tests \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cpp.in' \) | sort)
fi
if $fix; then
  "$tool" -i --style=file "${files[@]}"
  exit 0
fi
if ! "$tool" --dry-run -Werror --style=file "${files[@]}" 2>/tmp/check-format.$$; then
  grep -o '^[^:]*\.\(cpp\|hpp\|h\|cpp\.in\)' /tmp/check-format.$$ | sort -u | sed 's/^/check-format: not laid out as .clang-format says: /' >&2
  head -40 /tmp/check-format.$$ >&2
  rm -f /tmp/check-format.$$
  echo "check-format: run deploy/check-format.sh --fix" >&2
  exit 1
fi
rm -f /tmp/check-format.$$
echo "check-format: ${#files[@]} files laid out as .clang-format says"
