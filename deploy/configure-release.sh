#!/usr/bin/env bash
# Configures the Release build folder that demo.sh and test.sh share (default build/release).
# One set of flags for both: a demo followed by the test suite builds everything once (a folder
# configured with other flags is rebuilt from scratch, 284 steps on this project).
#   usage: deploy/configure-release.sh BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: deploy/configure-release.sh BUILD_DIR}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFACET_WERROR=ON >/dev/null
