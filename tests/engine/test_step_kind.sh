#!/usr/bin/env bash
# A step kind added by a test alone (brightness_step.cpp, registered in facet_with_brightness and
# facetd_with_brightness) goes through every path a recipe takes: `facet recipe check`, the JSON
# schema, `facet replay` and facetd. The plain `facet`, which does not register it, refuses it.
# Usage: test_step_kind.sh FACET_WITH_BRIGHTNESS FACETD_WITH_BRIGHTNESS FACET
set -euo pipefail
facet_t=$1 facetd_t=$2 facet=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir -p "$work/recipes" "$work/images"
# Two bright parts and a dark one, 8-bit grey.
/usr/bin/python3 - "$work/images" <<'PY'
import sys, numpy as np, cv2
for name, level in (("part_1.png", 200), ("part_2.png", 190), ("part_3.png", 40)):
    cv2.imwrite(f"{sys.argv[1]}/{name}", np.full((60, 80), level, np.uint8))
PY
cat > "$work/recipes/light.recipe.yaml" <<'YAML'
schema_version: 1
id: 1
name: light
steps:
  - id: light
    kind: brightness
    region: [10, 10, 40, 30]
    checks:
      level: {nominal: 0.75, tol_minus: 0.1, tol_plus: 0.25}
YAML
recipe=$work/recipes/light.recipe.yaml

"$facet_t" recipe check "$recipe" || fail "recipe check refused the registered kind"
if "$facet" recipe check "$recipe" 2> "$work/plain.err"; then
  fail "facet without the kind accepted it"
fi
grep -q "brightness" "$work/plain.err" || fail "no message names the unknown kind: $(cat "$work/plain.err")"

"$facet_t" recipe schema recipe > "$work/schema.json"
/usr/bin/python3 - "$work/schema.json" <<'PY' || fail "the schema does not describe the kind"
import json, sys
text = json.dumps(json.load(open(sys.argv[1])))
assert '"brightness"' in text and "Mean grey level" in text
PY

"$facet_t" replay --recipe "$recipe" --images "$work/images" --mm-per-pixel 0.1 \
  --report "$work/report.html" --json > "$work/replay.json"
/usr/bin/python3 - "$work/replay.json" <<'PY' || fail "replay verdicts: $(cat "$work/replay.json")"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["counts"] == {"pass": 2, "fail": 1, "error": 0}, r["counts"]
PY

cat > "$work/station.yaml" <<YAML
schema_version: 1
name: brightness-station
camera:
  backend: replay
  replay:
    folder: $work/images
    glob: "*.png"
    loop: false
    fps: 50
    trigger: software
    colour: mono
recipes: $work/recipes
results:
  database: $work/results.db
http:
  bind: 127.0.0.1
  port: 0
calibration:
  mm_per_pixel: 0.1
YAML
timeout 60 "$facetd_t" --config "$work/station.yaml" --replay "$work/images" --no-plc \
  --print-parts > "$work/facetd.out" 2> "$work/facetd.err" || fail "facetd: $(tail -5 "$work/facetd.err")"
passes=$(grep -c "^part .* pass " "$work/facetd.out" || true)
fails=$(grep -c "^part .* fail " "$work/facetd.out" || true)
[ "$passes" = 2 ] && [ "$fails" = 1 ] || fail "facetd verdicts: $(cat "$work/facetd.out")"
grep -q "light.level=" "$work/facetd.out" || fail "facetd printed no level: $(cat "$work/facetd.out")"
echo "test step kind: recipe check, schema, replay and facetd all ran it"
