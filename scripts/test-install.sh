#!/usr/bin/env bash
# Installs the build in BUILD_DIR (default build) into a temporary prefix and builds the C++
# example (examples/embed) against the installed package twice: with CMake's
# find_package(crowddb) and with pkg-config. Runs both. Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix/usr" >/dev/null
echo "-- installed into $prefix/usr: $(cd "$prefix/usr" && find . -type f | wc -l) files"

cmake -S examples/embed -B "$prefix/embed" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix/usr" >/dev/null
cmake --build "$prefix/embed" >/dev/null
"$prefix/embed/embed"

pc_dir=$(dirname "$(find "$prefix/usr" -name crowddb.pc)")
flags=$(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs crowddb)
# shellcheck disable=SC2086
c++ -std=c++20 -O2 examples/embed/main.cpp -o "$prefix/embed-pc" $flags
"$prefix/embed-pc" >/dev/null
echo "-- the example builds and runs against the installed package (CMake and pkg-config)"
