#!/usr/bin/env bash
# The whole test suite: a Release build with every test (C++, the Python module's pytest suite,
# the install and the example built against it), then the C++ tests built with clang's
# AddressSanitizer + UndefinedBehaviorSanitizer, then every parser's libFuzzer target from the
# same tree: its seed corpus replayed and FUZZ_SECONDS (default 60) of fuzzing (scripts/fuzz.sh). Tests
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
# Benchmarks are not built here: nothing in the suite runs them (docs/benchmarks.md builds them).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCROWDDB_WERROR=ON -DCROWDDB_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build -j "$jobs"
stage "Release tests"
ctest --test-dir build "${ctest_args[@]}"
stage "install, and the C++ example built against the installed package"
bash scripts/test-install.sh build

stage "ASan+UBSan build (clang; the tests and the libFuzzer targets in one tree)"
# One sanitizer tree serves the tests and the fuzzers: clang, ASan + UBSan, the library
# instrumented for libFuzzer's coverage (harmless to the tests). -O1 -g1 (line tables only):
# sanitizer reports keep file:line. A unity build (8 .cpp files per compiler run) is much faster;
# the Release tree above stays one file per run, so that every file still compiles on its own.
CC=clang CXX=clang++ cmake -S . -B build-san -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_UNITY_BUILD=ON -DCROWDDB_FUZZ=ON \
  -DCROWDDB_BUILD_BENCHMARKS=OFF -DCROWDDB_BUILD_PYTHON=OFF >/dev/null
cmake --build build-san -j "$jobs"
stage "ASan+UBSan tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp" \
  ctest --test-dir build-san "${ctest_args[@]}" -LE "slow|nosan"
stage "fuzzing (clang, libFuzzer, ASan+UBSan)"
FUZZ_TREE=build-san bash scripts/fuzz.sh
stage "all tests passed"
