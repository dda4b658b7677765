#!/usr/bin/env bash
# What demo.sh runs once the build is done: facet over the bundled sample images.
set -euo pipefail
build=$1
root=$(cd "$(dirname "$0")/.." && pwd)
"$build/service/facet" version

# Subpixel edges of every sample image: one line per image with point count and time.
summary='
import json, sys
r = json.load(sys.stdin)
print("edges %s: %d points, %.1f ms, thresholds %.1f/%.1f"
      % (sys.argv[1], len(r["points"]), r["time_ms"], r["low"], r["high"]))'
for image in "$root"/recipes/samples/*.png; do
  "$build/service/facet" edges --image "$image" --json | /usr/bin/python3 -c "$summary" "$(basename "$image")"
done
