#!/usr/bin/env bash
# Installs the Debian 12 packages bodyscan needs. Idempotent: packages already
# present are skipped, so the README commands can call it on every run.
#
#   deploy/install-deps.sh            build + test dependencies
#   deploy/install-deps.sh --browser  also Chromium, for the browser UI's tests
#   deploy/install-deps.sh --bench    also the peers the benchmarks compare with (Open3D)
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
  libcairo2-dev fonts-dejavu-core  # measurement sheets as PDF (storage/formats)
  libsqlite3-dev       # the scan archive's index (storage/archive)
  libsodium-dev        # checksums of archived files; password hashing (server)
  libboost1.81-dev     # Beast HTTP + WebSocket (server); 1.74 lacks message_generator
  libssl-dev openssl   # TLS for `bodyscan serve`; the tests make a certificate with openssl
  libaravis-dev aravis-tools  # GenICam cameras (hw/aravis); the tests run arv-fake-gv-camera-0.8
  libusb-1.0-0-dev     # the TMCL controller board over USB (hw/usb)
  libgtest-dev libgmock-dev libbenchmark-dev
  poppler-utils        # pdftotext: the tests read the PDF sheets back
)
for arg in "$@"; do
  case "$arg" in
    --browser) packages+=(chromium) ;;  # driven headless by playwright-core (web/tests/e2e)
    --bench) packages+=(python3-open3d python3-numpy time wrk curl chromium) ;;
    *) echo "install-deps: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all ${#packages[@]} packages present"
fi
