#!/usr/bin/env bash
# Runs bench_daemon of two builds alternately (A B A B ...) and prints, per build, the median over
# the rounds of: trigger -> result registers p50 and p99, free-run parts per second, the mean
# inspect time and the same run's OpenCV baseline of the inspection; then the ratios B / A (> 1
# for latency and inspect = B slower; for the free-run rate < 1 = B slower). Alternating spreads
# a busy machine's load over both builds alike.
#
#   bench/daemon/compare_builds.sh BASELINE_BENCH_DAEMON NEW_BENCH_DAEMON [ROUNDS] [-- ARGS...]
#   e.g. compare_builds.sh ../base/build/release/bench/daemon/bench_daemon \
#          build/release/bench/daemon/bench_daemon 5 -- --parts 2000 --triggers 200
set -euo pipefail
a=$1 b=$2 rounds=${3:-5}
shift $(( $# >= 3 ? 3 : $# ))
[ "${1:-}" = "--" ] && shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for r in $(seq 1 "$rounds"); do
  for side in a b; do
    bin=$a; [ "$side" = b ] && bin=$b
    "$bin" "$@" > "$work/$side.$r.txt" 2>&1 || { echo "$bin failed:"; tail -5 "$work/$side.$r.txt"; exit 1; }
  done
done
/usr/bin/python3 - "$work" "$rounds" "$a" "$b" <<'PY'
import re, statistics, sys
work, rounds, names = sys.argv[1], int(sys.argv[2]), {"a": sys.argv[3], "b": sys.argv[4]}
pats = {
    "p50 ms": r"trigger -> result registers, p50\s*\|\s*([\d.]+) ms",
    "p99 ms": r"trigger -> result registers, p99\s*\|\s*([\d.]+) ms",
    "free run /s": r"\| free run\s*\|\s*([\d.]+) /s",
    "inspect ms": r"\| inspect\s*\|\s*([\d.]+) ms \|",
    # The same run's OpenCV baseline: the same code in both binaries, so its ratio is the
    # machine's (or the process's) speed, not the build's.
    "opencv ms": r"\| inspect\s*\|\s*[\d.]+ ms \|\s*([\d.]+) ms matchTemplate",
}
med = {}
for side in "ab":
    for key, pat in pats.items():
        vals = []
        for r in range(1, rounds + 1):
            m = re.search(pat, open(f"{work}/{side}.{r}.txt").read())
            if m: vals.append(float(m.group(1)))
        med[side, key] = statistics.median(vals) if vals else float("nan")
print(f"bench_daemon, {rounds} alternating rounds per build, medians over the rounds")
print(f"A = {names['a']}\nB = {names['b']}\n")
print(f"| figure       | A (baseline) | B (new)   | B / A |")
print(f"| ------------ | ------------ | --------- | ----- |")
for key in pats:
    x, y = med["a", key], med["b", key]
    print(f"| {key:<12} | {x:12.2f} | {y:9.2f} | {y / x:5.3f} |")
PY
