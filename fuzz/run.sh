#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and runs
# each for SECONDS seconds from seeds: testdata/, the bad-input corpus (tests/corpus) when a
# geardiag binary is given, and small valid files made by fuzz/make_seeds.py. Fails on the first
# crash, leak, sanitizer report, timeout or non-InputError exception; the input is saved as
# BUILD/artifacts/<target>-crash-*. Prints executions and coverage per target (FUZZING.md).
# The mutation sequence is fixed by FUZZ_SEED (default 1), so a run explores the same inputs each
# time up to where its time runs out; another seed explores others.
#
# usage: fuzz/run.sh BUILD_DIR SECONDS [GEARDIAG_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: fuzz/run.sh BUILD_DIR SECONDS [GEARDIAG_BINARY]}
seconds=${2:?usage: fuzz/run.sh BUILD_DIR SECONDS [GEARDIAG_BINARY]}
geardiag=${3:-}
jobs=$(nproc 2>/dev/null || echo 2)

# Configured once: cmake --build reconfigures by itself when a CMakeLists.txt changes.
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEARDIAG_FUZZ=ON \
    -DGEARDIAG_BUILD_TESTS=OFF \
    ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER} >/dev/null
fi
cmake --build "$build" -j "$jobs" --target fuzzers

seeds="$build/seeds"
rm -rf "$seeds"
"${PYTHON:-/usr/bin/python3}" fuzz/make_seeds.py "$seeds" ${geardiag:+--geardiag "$geardiag"}
mkdir -p "$build/artifacts"
summary="$build/fuzz-summary.txt"
: >"$summary"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for target in csv csv_gz wav mat hdf5 face_gear_table gearbox_json scenario_json channel_map; do
  corpus="$build/corpus/$target"
  mkdir -p "$corpus"
  log="$build/fuzz-$target.log"
  # -timeout: one input may take this long (the HDF5 reader's survey child gives up after 30 s).
  # Inputs that once failed (fuzz/regressions/<target>) run first, as seeds.
  regressions=()
  if [ -d "fuzz/regressions/$target" ]; then regressions=("fuzz/regressions/$target"); fi
  # FUZZ_RUNS_FILE (CI): at most the number of inputs a run with this seed was seen to pass on
  # this kind of machine (fuzz/ci-runs.txt), so that CI replays a verified sequence and gives the
  # same answer every time, however fast the machine is.
  runs=()
  if [ -n "${FUZZ_RUNS_FILE:-}" ]; then
    cap=$(awk -v t="$target" '$1 == t { print $2 }' "$FUZZ_RUNS_FILE")
    if [ -n "$cap" ]; then runs=(-runs="$cap"); fi
  fi
  if "$build/fuzz/fuzz_$target" "$corpus" "$seeds/$target" "${regressions[@]}" "${runs[@]}" -max_total_time="$seconds" \
      -seed="${FUZZ_SEED:-1}" -timeout=45 -rss_limit_mb=2560 -max_len=1048576 -print_final_stats=1 \
      -artifact_prefix="$build/artifacts/$target-" >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    status=1
  fi
  # The last figures are the run's (the HDF5 reader's survey child can print its own on a crash).
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || echo '?')
  cov=$(grep -E '^#[0-9]+' "$log" | tail -1 | grep -o 'cov: [0-9]*' | grep -o '[0-9]*' || echo '?')
  ft=$(grep -E '^#[0-9]+' "$log" | tail -1 | grep -o 'ft: [0-9]*' | grep -o '[0-9]*' || echo '?')
  inputs=$(find "$corpus" -type f | wc -l)
  printf '%-14s %-6s %8s s %10s execs  cov %6s  ft %7s  corpus %5s\n' "$target" "$result" \
    "$seconds" "$execs" "$cov" "$ft" "$inputs" | tee -a "$summary"
  if [ "$result" != ok ]; then tail -40 "$log"; fi
done
exit $status
