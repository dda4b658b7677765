#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs facet on the bundled example station.
set -euo pipefail
cd "$(dirname "$0")"
bash deploy/install-deps.sh
build=${FACET_BUILD_DIR:-build/release}
bash deploy/configure-release.sh "$build"  # the same folder and flags as ./test.sh
cmake --build "$build" -j2
exec bash deploy/demo-run.sh "$build"
