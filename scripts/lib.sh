# Shared by scripts/demo and scripts/test: install what is missing, then configure and build.
# Sourced, not run. Works on a fresh Debian 12 as root; later runs are incremental.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-"$ROOT/build"}
JOBS=${JOBS:-2}
# Tests at a time (ctest -j): one more than the cores. About a third of the suite's wall time is
# waiting, not computing (Chromium, live runs paced in real time between two processes); the
# extra slot fills it. On the 2-core machine: -j2 55-62 s, -j3 40-48 s (5 suites; the first failed on
# a port race of the page test, since fixed), -j4 39-49 s but the live cross-process runs
# then failed in 1 of 4 suites (docs/benchmarks.md, "Test suite and demo").
TEST_JOBS=${TEST_JOBS:-$((JOBS + 1))}

PACKAGES=(
  build-essential cmake pkg-config
  libusb-1.0-0-dev libhidapi-dev libeigen3-dev libboost-dev libsqlite3-dev libspdlog-dev
  libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev clang
  libplplot-dev
  libpq-dev libpqxx-dev
)
# The headless browser of the report and live-page tests (and of daq report --format pdf).
# The Python package (python/, docs/python.md): pybind11 and Python's headers to build it; numpy,
# pytest, pandas and matplotlib for its tests (pytest in ctest) and the notebook walk-through.
# PostgreSQL's server for the central-store tests (tests/cli/pg_server.sh starts a throwaway one).
TEST_PACKAGES=(chromium chromium-driver python3 poppler-utils postgresql
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest python3-pandas
  python3-matplotlib)

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

configure() {
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    # Debian's interpreter, where the python3-* packages above are (not a pyenv or venv python
    # first on PATH).
    local python=()
    if [ -x /usr/bin/python3 ]; then python=(-DPython3_EXECUTABLE=/usr/bin/python3); fi
    cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${python[@]}"
  fi
}

configure_and_build() {
  configure
  cmake --build "$BUILD_DIR" -j "$JOBS"
}
