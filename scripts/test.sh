#!/usr/bin/env bash
# The whole test suite: a Release build with every test (C++, the Python module's pytest suite,
# the install and the example built against it), then the C++ tests built with
# AddressSanitizer + UndefinedBehaviorSanitizer, then every parser's libFuzzer target (clang):
# its seed corpus replayed and FUZZ_SECONDS (default 60) of fuzzing (scripts/fuzz.sh). Tests
# labelled `slow` run only with CROWDDB_SLOW_TESTS=1. Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
ctest_args=(--output-on-failure -j "$jobs" --timeout 900)
[[ "${CROWDDB_SLOW_TESTS:-0}" == 1 ]] || ctest_args+=(-LE slow)

# Each stage says how long the suite has run so far, to see where CI's time goes.
stage() { echo "== $1 ($((SECONDS / 60)) min $((SECONDS % 60)) s so far)"; }
# Object files cached by ccache are found again from another clone of the repository (CI runs in
# a fresh one): paths under the clone are hashed relative to it.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
stage "Release build"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCROWDDB_WERROR=ON >/dev/null
cmake --build build -j "$jobs"
stage "Release tests"
ctest --test-dir build "${ctest_args[@]}"
stage "install, and the C++ example built against the installed package"
bash scripts/test-install.sh build

stage "ASan+UBSan build"
# -g1 (line tables only): sanitizer reports keep file:line, and the build is much lighter than -g.
# A unity build (8 .cpp files per compiler run) takes 17 instead of 27 min on 2 cores; the
# Release tree above stays one file per run, so that every file still compiles on its own.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" \
  -DCMAKE_UNITY_BUILD=ON -DCROWDDB_SANITIZE=ON -DCROWDDB_WERROR=ON -DCROWDDB_BUILD_BENCHMARKS=OFF -DCROWDDB_BUILD_PYTHON=OFF >/dev/null
cmake --build build-asan -j "$jobs"
stage "ASan+UBSan tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp" \
  ctest --test-dir build-asan "${ctest_args[@]}" -LE "slow|nosan"
stage "fuzzing (clang, libFuzzer, ASan+UBSan)"
bash scripts/fuzz.sh
stage "all tests passed"
