#!/usr/bin/env bash
# Runs the whole test suite as CI does: installs what is missing, then up to three phases, each
# in its own build folder, and prints how long each took.
#   1. release: Release build (warnings as errors), every test with CTest, including a short
#      smoke run of each benchmark.                     FACET_CI_RELEASE=1, FACET_BUILD_DIR
#   2. asan:    AddressSanitizer + UBSan build (gcc), the suite again (unit, integration
#      with facetd/fake camera/pymodbus, browser), benchmarks excepted (not built there).
#      FACET_CI_ASAN_LABELS limits it to a label regex. FACET_CI_ASAN=1, FACET_ASAN_BUILD_DIR
#   3. fuzz:    clang + libFuzzer build of tests/fuzz, every seed corpus and regression input
#      replayed, then each fuzz target run for FACET_FUZZ_SECONDS (default 30).
#                                                       FACET_CI_FUZZ=1, FACET_FUZZ_BUILD_DIR
# Set a phase's variable to 0 to skip it. Extra arguments go to the release phase's ctest.
set -euo pipefail
cd "$(dirname "$0")"
bash deploy/install-deps.sh
# ccache (when installed) reuses objects across clones at other paths: paths become relative.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
# The ASan build has debug info, whose hash would include the build folder's path: leave it out
# so another clone hits the cache too (only the debugger's compilation folder differs).
export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-true}

run_release=${FACET_CI_RELEASE:-1}
run_asan=${FACET_CI_ASAN:-1}
run_fuzz=${FACET_CI_FUZZ:-1}
asan_labels=${FACET_CI_ASAN_LABELS:-}
fuzz_seconds=${FACET_FUZZ_SECONDS:-30}
timings=()

phase_done() {
  timings+=("$(printf '%-8s %4d s' "$1" "$(($(date +%s) - $2))")")
}
report_timings() {
  echo "test.sh: phase durations"
  for t in "${timings[@]}"; do echo "  $t"; done
}
trap report_timings EXIT

if [ "$run_release" = 1 ]; then
  start=$(date +%s)
  build=${FACET_BUILD_DIR:-build/release}
  bash deploy/configure-release.sh "$build"  # the same folder and flags as ./demo.sh
  cmake --build "$build" -j2
  ctest --test-dir "$build" --output-on-failure -j2 --timeout 900 "$@"
  phase_done release "$start"
fi

if [ "$run_asan" = 1 ]; then
  start=$(date +%s)
  build=${FACET_ASAN_BUILD_DIR:-build/asan}
  # No benchmarks: they are not run under ASan, and building them would double the build time.
  # Warnings are enforced by the release phase; at -O1 with sanitizer instrumentation GCC 12
  # reports false maybe-uninitialized warnings inside <regex> and <functional>, so no -Werror here.
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Asan -DFACET_WERROR=OFF \
    -DFACET_BUILD_BENCH=OFF >/dev/null
  cmake --build "$build" -j2
  # Leak checks stay on (third-party leaks suppressed, see the file); halt on the first report
  # so that CTest sees a failure.
  # Allocation stacks by frame pointers (ASan's default): full unwinding on every allocation
  # (fast_unwind_on_malloc=0) made the phase twice as long and OpenCV's board search ten times
  # slower (calibration tests 5 minutes each), and the suite runs clean without it. Set
  # ASAN_OPTIONS with fast_unwind_on_malloc=0 to follow a leak report into a library built
  # without frame pointers.
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1} \
  LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/sanitizers/lsan.supp} \
  UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    ctest --test-dir "$build" --output-on-failure -j2 --timeout 900 \
      ${asan_labels:+-L "$asan_labels"}
  phase_done asan "$start"
fi

if [ "$run_fuzz" = 1 ]; then
  start=$(date +%s)
  build=${FACET_FUZZ_BUILD_DIR:-build/fuzz}
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DFACET_FUZZ=ON -DFACET_BUILD_BENCH=OFF -DFACET_FUZZ_SECONDS="$fuzz_seconds" >/dev/null
  cmake --build "$build" -j2 --target fuzzers
  ctest --test-dir "$build" --output-on-failure -j2 -R '^fuzz'
  phase_done fuzz "$start"
fi
