#!/usr/bin/env bash
# Fuzzing stage of the test suite: builds every libFuzzer target with clang (the library
# instrumented for coverage, ASan + UBSan) in build-fuzz/ or in FUZZ_TREE, replays each seed
# corpus as a regression test, then fuzzes each target for FUZZ_SECONDS (default 60) from a copy
# of its corpus. Any crash, leak, sanitizer report or timeout fails the stage and leaves the input
# under build-fuzz/findings/. New interesting inputs stay in build-fuzz/corpus/ (add the useful
# ones to fuzz/corpus/).
# FUZZ_SEED (default 1) makes a run repeatable: the same binaries and seeds try the same inputs
# in the same order (how many depends on the machine's speed); FUZZ_SEED=0 draws a new one.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
export FUZZ_SEED=${FUZZ_SEED:-1}
jobs=$(nproc)

# target : seed files, comma-separated folders or globs (replayed as a regression test and
# fuzzed from); fuzz/corpus/ also keeps the inputs fuzzing has found (fixed since)
declare -A seeds=(
  [scenario_fuzz]="fuzz/corpus/scenario"
  [csv_fuzz]="fuzz/corpus/csv"
  [steersuite_fuzz]="fuzz/corpus/steersuite"
  [menge_fuzz]="fuzz/corpus/menge"
  [vadere_fuzz]="fuzz/corpus/vadere"
  [overrides_fuzz]="fuzz/corpus/overrides"
  [sdf_sdf3_fuzz]="tests/sdf/data/*.xml,fuzz/corpus/sdf3"
  [sdf_json_fuzz]="tests/sdf/data/*.json,fuzz/corpus/sdf_json"
  [checkpoint_fuzz]="fuzz/corpus/checkpoint"
  [runfile_fuzz]="fuzz/corpus/runfile"
  [partial_fuzz]="fuzz/corpus/partial"
)
targets=(scenario_fuzz csv_fuzz steersuite_fuzz menge_fuzz vadere_fuzz overrides_fuzz sdf_sdf3_fuzz sdf_json_fuzz
  checkpoint_fuzz runfile_fuzz partial_fuzz)

# FUZZ_TREE: a build tree already configured with CROWDDB_FUZZ=ON (scripts/test.sh's sanitizer
# tree, which holds the tests too); by default build-fuzz, configured here with the fuzz targets only.
if [[ -z ${FUZZ_TREE:-} ]]; then
  FUZZ_TREE=build-fuzz
  CC=clang CXX=clang++ cmake -S . -B "$FUZZ_TREE" -DCROWDDB_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_UNITY_BUILD=ON -DCROWDDB_BUILD_TESTS=OFF \
    -DCROWDDB_BUILD_BENCHMARKS=OFF -DCROWDDB_BUILD_PYTHON=OFF >/dev/null
fi
export FUZZ_TREE
cmake --build "$FUZZ_TREE" -j "$jobs" --target "${targets[@]}"

rm -rf "$FUZZ_TREE"/findings "$FUZZ_TREE"/corpus "$FUZZ_TREE"/logs
mkdir -p "$FUZZ_TREE"/findings "$FUZZ_TREE"/corpus "$FUZZ_TREE"/logs
export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

fuzz_one() {
  local t=$1 pattern=$2 seconds=$3
  local bin=$FUZZ_TREE/fuzz/$t corpus=$FUZZ_TREE/corpus/$t log=$FUZZ_TREE/logs/$t.log
  local -a files=()
  local p
  for p in ${pattern//,/ }; do
    if [[ -d $p ]]; then files+=("$p"/*); else files+=($p); fi
  done
  mkdir -p "$corpus" "$FUZZ_TREE/findings/$t"
  # 1. every seed once: a regression test
  if ! "$bin" -timeout=10 -rss_limit_mb=2560 -artifact_prefix="$FUZZ_TREE/findings/$t/" \
      "${files[@]}" >"$log" 2>&1; then
    echo "FAIL $t: a seed input fails ($FUZZ_TREE/logs/$t.log)"
    return 1
  fi
  cp "${files[@]}" "$corpus/"
  # 2. fuzzing from the seeds
  if ! "$bin" "$corpus" -seed="$FUZZ_SEED" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2560 \
      -artifact_prefix="$FUZZ_TREE/findings/$t/" -print_final_stats=1 >>"$log" 2>&1; then
    echo "FAIL $t: found $(ls "$FUZZ_TREE/findings/$t" | head -1) ($FUZZ_TREE/logs/$t.log)"
    return 1
  fi
  local runs
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  echo "ok   $t: ${#files[@]} seeds replayed; ${runs:-?} runs in ${seconds} s; corpus $(ls "$corpus" | wc -l) inputs"
}
export -f fuzz_one

echo "== fuzzing: ${#targets[@]} targets, ${seconds} s each, ${jobs} at a time"
for t in "${targets[@]}"; do echo "$t ${seeds[$t]}"; done |
  xargs -P "$jobs" -n 2 bash -c 'fuzz_one "$1" "$2" '"$seconds" _
