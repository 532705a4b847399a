#!/usr/bin/env bash
# Installs the Debian 12 packages bodyscan needs. Idempotent: packages already
# present are skipped, so the README commands can call it on every run.
#
#   deploy/install-deps.sh            build + test dependencies, Node.js for the UI
#   deploy/install-deps.sh --browser  also Chromium, for the browser UI's tests
#   deploy/install-deps.sh --bench    also the peers the benchmarks compare with (Open3D)
#   deploy/install-deps.sh --sanitize also clang and its sanitizer and libFuzzer runtimes
#   deploy/install-deps.sh --lint     also clang-format, clang-tidy and Python, for deploy/check-format.sh,
#                                     check-tidy.sh and the benchmark tables' check (bench/tables.py --check)
#
# It never removes a package: before installing it asks apt what the install
# would do, says how many packages and how many megabytes that is, and stops
# naming the conflict when apt would have to remove anything (the install itself
# runs with --no-remove as well). Run it as root, or as a user who may sudo.
#
# The browser UI's npm packages are installed by deploy/install-web.sh.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libeigen3-dev        # linear algebra (recon)
  libnanoflann-dev     # k-nearest-neighbour search (recon)
  libtbb-dev           # parallel loops (recon)
  robin-map-dev        # open-addressing hash map, header-only (recon/geometry/fill_holes)
  nlohmann-json3-dev   # rig descriptions, API documents (hw, server)
  libembree-dev        # ray casting for the simulated rig (hw/sim)
  libpng-dev           # camera images (recon/io)
  libdraco-dev libtinygltf-dev  # glTF binary with Draco, Draco point clouds (storage/formats)
  libmeshoptimizer-dev # decimating surfaces to a triangle budget (recon/geometry/simplify)
  libcairo2-dev fonts-dejavu-core  # measurement sheets as PDF (storage/formats)
  libqrencode-dev                  # the share link as a QR code on the customer sheet
  libsqlite3-dev       # the scan archive's index (storage/archive)
  libsodium-dev        # checksums of archived files; password hashing (server)
  libboost-dev         # Beast HTTP + WebSocket (server): Debian's default Boost, 1.74
  libssl-dev openssl   # TLS for `bodyscan serve`; the tests make a certificate with openssl
  libaravis-dev aravis-tools  # GenICam cameras (hw/aravis); the tests run arv-fake-gv-camera-0.8
  libusb-1.0-0-dev     # the TMCL controller board over USB (hw/usb)
  libgtest-dev libgmock-dev libbenchmark-dev
  poppler-utils        # pdftotext: the tests read the PDF sheets back
)
# The browser UI is bundled and tested with Node.js 18 or newer (Debian 12 has
# 18.20). A Node.js installed from elsewhere (with its own npm) is used as it is:
# Debian's npm package would replace it.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  packages+=(nodejs npm)
fi
for arg in "$@"; do
  case "$arg" in
    --browser) packages+=(chromium) ;;  # driven headless by playwright-core (web/tests/e2e)
    --bench) packages+=(python3-open3d python3-numpy time wrk curl chromium) ;;
    --sanitize) packages+=(clang libclang-rt-dev) ;;  # deploy/sanitize.sh
    --lint) packages+=(clang-format clang-tidy python3) ;;  # check-format.sh, check-tidy.sh, bench/tables.py --check
    *) echo "install-deps: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=()
if [[ $(id -u) -ne 0 ]]; then
  if ! command -v sudo >/dev/null; then
    echo "install-deps: these packages are missing and installing them needs root: ${missing[*]}" >&2
    echo "install-deps: run this script as root, or install sudo and run it as a user who may use it" >&2
    exit 1
  fi
  SUDO=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive

echo "install-deps: missing ${missing[*]}; updating the package lists"
"${SUDO[@]}" apt-get update -qq

# What apt would do, asked first (a simulation needs no root): the packages it
# would add with their sizes, and any it would remove.
if ! plan=$(LC_ALL=C apt-get -s install --no-install-recommends "${missing[@]}" 2>&1); then
  { sed -n '/unmet dependencies/,$p' <<<"$plan" | grep . || grep '^E:' <<<"$plan" || echo "$plan"; } >&2
  echo "install-deps: apt cannot install ${missing[*]} on this machine (above); nothing was changed" >&2
  exit 1
fi
removals=$(awk '$1 == "Remv" { print $2 }' <<<"$plan" | sort -u | xargs)
if [[ -n $removals ]]; then
  echo "install-deps: installing ${missing[*]} would remove these packages: $removals" >&2
  echo "install-deps: nothing was changed. Those packages conflict with what bodyscan needs;" >&2
  echo "install-deps: resolve the conflict by hand (or install on a machine without them)." >&2
  exit 1
fi
mapfile -t adds < <(awk '$1 == "Inst" { v = $3; gsub(/[()[\]]/, "", v); print $2 "=" v }' <<<"$plan")
size=$(apt-cache show --no-all-versions "${adds[@]}" 2>/dev/null | awk '/^Size:/ { s += $2 }
  /^Installed-Size:/ { i += $2 } END { printf "%.1f MB to download, %.1f MB on disk", s / 1e6, i * 1024 / 1e6 }')
echo "install-deps: installing ${#adds[@]} packages (${missing[*]} and what they depend on): $size"
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install --no-remove --no-install-recommends -y -qq "${missing[@]}"
echo "install-deps: done"
