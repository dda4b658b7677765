#!/usr/bin/env bash
# What demo.sh runs once the build is done: the example station of recipes/station.yaml, with the
# PLC simulator raising triggers on 127.0.0.1:1502 and facetd replaying each example recipe's
# recorded demo folder. Prints one line per part and a summary per recipe; leaves the results
# database and the image archive where recipes/station.yaml puts them (/tmp/facet-demo-*).
set -euo pipefail
build=$1
facet="$build/service/facet"
facetd="$build/service/daemon/facetd"
station=recipes/station.yaml
out=/tmp/facet-demo
db=/tmp/facet-demo-results.db
archive=/tmp/facet-demo-archive

# A fresh database and archive for every demo run.
rm -rf "$db" "$db-wal" "$db-shm" "$archive" "$out"
mkdir -p "$out"

echo "== facet $("$facet" version | cut -d' ' -f2): subpixel edges of the sample images"
for image in recipes/samples/*.png; do
  "$facet" edges --image "$image" --json | /usr/bin/python3 -c '
import json, sys
d = json.load(sys.stdin)
print("  %s: %d edge points in %.1f ms" % (sys.argv[1], len(d["points"]), d["time_ms"]))' "$image"
done

echo "== PLC simulator on 127.0.0.1:1502 (triggers at 5 per second)"
"$facet" plc-sim --map "$station" --key plc.register_map --port 1502 --rate 5 >"$out/plc-sim.log" 2>&1 &
sim=$!
trap 'kill $sim 2>/dev/null || true' EXIT
sleep 0.5

# recipe id : recorded folder
for run in 1:bracket_registration 2:bracket_shape 3:fiducial_board 4:scan_offset; do
  id=${run%%:*}
  folder=recipes/demo/${run#*:}
  # One part per recorded image or scan: facetd stops there instead of answering the
  # simulator's next trigger with "replay finished" (which it does, as an error part, on a line).
  parts=$(find "$folder" -maxdepth 1 \( -name '*.png' -o -name '*.csv' \) | wc -l)
  echo "== recipe $id over $folder ($parts recorded parts)"
  "$facetd" --config "$station" --recipe "$id" --replay "$folder" --max-parts "$parts" --print-parts \
    2> >(grep -v "has no value" >&2)
done

kill $sim 2>/dev/null || true
wait $sim 2>/dev/null || true
echo "== what the PLC simulator received: $(grep -c . "$out/plc-sim.log" || true) lines (log: $out/plc-sim.log)"
echo "== results database: $db ($(sqlite3 "$db" 'select count(*) from parts') parts)"
sqlite3 -column -header "$db" \
  "select recipe_id as recipe, recipe_name as name, sum(verdict='pass') as pass, sum(verdict='fail') as fail, sum(verdict='error') as error, round(avg(inspection_ms),1) as avg_ms from parts group by recipe_id"
echo "== image archive (failed parts with overlays): $archive ($(find "$archive" -name '*.png' | wc -l) files)"
echo "   export: $facet results export --db $db --csv"
