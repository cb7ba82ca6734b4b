# Shared by scripts/demo and scripts/test: install what is missing, then configure and build.
# Sourced, not run. Works on a fresh Debian 12 as root; later runs are incremental.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-"$ROOT/build"}
JOBS=${JOBS:-2}
# Tests at a time (ctest -j). About a third of the suite's wall time is waiting, not computing
# (Chromium, live runs paced in real time between two processes): TEST_JOBS=4 takes the suite
# from ~55 s to ~40 s on 2 cores, but the live runs then see more load (cli_run_linear failed in
# one of four whole suites at -j4), so the default stays one test per core (docs/benchmarks.md).
TEST_JOBS=${TEST_JOBS:-$JOBS}

PACKAGES=(
  build-essential cmake pkg-config
  libusb-1.0-0-dev libhidapi-dev libeigen3-dev libboost-dev libsqlite3-dev libspdlog-dev
  libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev clang
  libplplot-dev
)
# The headless browser of the report and live-page tests (and of daq report --format pdf).
TEST_PACKAGES=(chromium chromium-driver python3 poppler-utils)

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then return 0; fi
  echo "==> installing: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

configure_and_build() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo
  fi
  cmake --build "$BUILD_DIR" -j "$JOBS"
}
