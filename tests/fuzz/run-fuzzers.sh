#!/usr/bin/env bash
# Runs every fuzz target for SECONDS seconds, starting from its seed corpus and regressions, and
# prints one line per target: executions, coverage (cov: edges, ft: features), result.
#   run-fuzzers.sh SECONDS [BUILD_DIR] [TARGET...]
#   BUILD_DIR  folder holding the fuzz_* executables (default build/fuzz/tests/fuzz)
#   FACET_FUZZ_JOBS  targets run at the same time (default 2)
# New inputs go to a scratch corpus (the committed seeds stay small); crashes are kept in
# BUILD_DIR/artifacts/<target>/. Exit status 1 when any target found something.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
seconds=${1:?usage: run-fuzzers.sh SECONDS [BUILD_DIR] [TARGET...]}
bin=${2:-$here/../../build/fuzz/tests/fuzz}
shift $(( $# >= 2 ? 2 : 1 ))
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for d in "$here"/*/corpus; do targets+=("$(basename "$(dirname "$d")")"); done
fi
jobs=${FACET_FUZZ_JOBS:-2}
# Leaks inside third-party libraries (see the file) are not findings.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/../sanitizers/lsan.supp}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run_one() {
  local t=$1 exe="$bin/fuzz_$1" out="$work/$1.log" artifacts="$bin/artifacts/$1"
  if [ ! -x "$exe" ]; then echo "$t: no executable $exe" >"$out.summary"; return 1; fi
  mkdir -p "$work/$t.corpus" "$artifacts"
  touch "$work/$t.start"
  # OpenImageIO's leak is only recognised with full allocation stacks (libstdc++ has no frame
  # pointers for the fast unwinder); that costs speed, so only for the image target.
  local asan=${ASAN_OPTIONS:-}
  [ "$t" = image ] && asan=${ASAN_OPTIONS:-fast_unwind_on_malloc=0}
  ASAN_OPTIONS=$asan "$exe" "$work/$t.corpus" "$here/$t/corpus" "$here/$t/regressions" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" >"$out" 2>&1
  local rc=$?
  local execs cov ft
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$out" | tail -1)
  ft=$(grep -o 'ft: [0-9]*' "$out" | tail -1)
  if [ $rc -eq 0 ]; then
    printf '%-14s ok      %ss  execs %-10s %s %s\n' "$t" "$seconds" "${execs:-?}" "$cov" "$ft" >"$out.summary"
  else
    printf '%-14s FINDING (exit %s) artifacts in %s\n' "$t" "$rc" "$artifacts" >"$out.summary"
    # -a: the target's own messages may carry the input's bytes (NULs make grep call the log
    # binary and print nothing); without a sanitizer's report, the log's end says why it stopped.
    { grep -a -m1 -A25 'ERROR:\|runtime error\|deadly signal\|timeout\|out-of-memory' "$out" ||
        tail -n 25 "$out"; } | cat -v >>"$out.summary"
    # The input itself, so that a finding on a machine whose build folder is gone (CI) can be
    # replayed: base64 -d > input; fuzz_<target> input.
    find "$artifacts" -type f -newer "$work/$t.start" | while read -r f; do
      printf 'input %s, base64:\n' "$(basename "$f")"
      base64 -w 0 "$f" | head -c 8000
      echo
    done >>"$out.summary"
  fi
  return $rc
}

status=0
running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ $running -ge "$jobs" ]; then wait -n || status=1; running=$((running - 1)); fi
done
while [ $running -gt 0 ]; do wait -n || status=1; running=$((running - 1)); done
for t in "${targets[@]}"; do cat "$work/$t.log.summary"; done
exit $status
