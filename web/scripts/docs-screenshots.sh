#!/usr/bin/env bash
# The screenshots docs/ui.md shows, made by the browser test as it goes (the
# station mid-scan, the customer's phone in English and German, the customer's
# sheet), copied into docs/ui/. Run after a build (deploy/build.sh):
#
#   web/scripts/docs-screenshots.sh [BUILD_DIR]     (default: build)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
bin="$build/app/bodyscan"
[[ -x "$bin" && -f "$build/web/index.html" ]] || { echo "docs-screenshots: build first ($bin, $build/web)" >&2; exit 1; }
shots=$(mktemp -d)
trap 'rm -rf "$shots"' EXIT
(cd web && BODYSCAN_BIN="$PWD/../$bin" BODYSCAN_WEB_ROOT="$PWD/../$build/web" BODYSCAN_TEST_ARTIFACTS="$shots" \
  node --test tests/e2e/ui.test.mjs >"$shots/test.log" 2>&1) || { tail -40 "$shots/test.log" >&2; exit 1; }
mkdir -p docs/ui
cp "$shots/first-station-scanning.png" docs/ui/station-mid-scan.png
cp "$shots/customer-phone.png" docs/ui/customer-phone.png
cp "$shots/customer-phone-de.png" docs/ui/customer-phone-de.png
pdftoppm -r 72 -png -singlefile "$shots/customer-sheet.pdf" docs/ui/customer-sheet
echo "docs-screenshots: wrote docs/ui/{station-mid-scan,customer-phone,customer-phone-de,customer-sheet}.png"
