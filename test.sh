#!/usr/bin/env bash
# Runs the whole test suite: installs what is missing, builds (Release, warnings as errors) and
# runs every test with CTest, including a short smoke run of each benchmark.
#   FACET_BUILD_DIR  build folder (default build/release)
set -euo pipefail
cd "$(dirname "$0")"
bash deploy/install-deps.sh
build=${FACET_BUILD_DIR:-build/release}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFACET_WERROR=ON >/dev/null
cmake --build "$build" -j2
ctest --test-dir "$build" --output-on-failure -j2 --timeout 900 "$@"
