#!/usr/bin/env bash
# Installs every build, test and run-time dependency of crowddb from Debian 12 packages.
# Run as root (or with sudo) on a fresh machine; safe to run again.
set -euo pipefail
packages=(
  build-essential cmake ccache git python3 sqlite3
  libgtest-dev libgmock-dev libbenchmark-dev   # tests and benchmarks
  libcli11-dev nlohmann-json3-dev libfccp-dev  # CLI, scenario JSON, CSV tokenising
  libsqlite3-dev                               # trajectory output
  libtbb-dev                                   # threads (work stealing, caller participates)
  libcgal-dev libboost-dev                     # Delaunay heuristic; Boost.Geometry for WKT
  librecast-dev                                # navigation meshes
  libpugixml-dev                               # SDF3 XML
  libxsimd-dev                                 # SIMD inner loops (header-only)
  gnuplot-nox graphviz                         # experiment plots, DOT rendering
  clang libclang-rt-14-dev                     # libFuzzer targets (scripts/fuzz.sh)
  python3-dev pybind11-dev python3-numpy       # the Python module
  python3-pytest python3-matplotlib            # its tests and the plotting example
  pkg-config                                   # the install test (crowddb.pc)
  libcairo2-dev                                # crowddb render: pictures of runs
  libcpp-httplib-dev                           # crowddb view: the local web server
  chromium                                     # the viewer's browser test (headless)
)
# The viewer's page is bundled with npm packages; Debian's Node.js when the machine has none.
command -v npm > /dev/null || packages+=(nodejs npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# The viewer's npm packages (esbuild to bundle the page, uPlot for its chart, playwright-core to
# drive Chromium in its test), at the versions package-lock.json records; no browser download.
npm ci --prefix "$(dirname "$0")/../viewer" --no-audit --no-fund --loglevel=error
