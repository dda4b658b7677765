#!/usr/bin/env bash
# What demo.sh runs once the build is done: facet over the bundled sample images.
set -euo pipefail
build=$1
"$build/service/facet" version
