#!/usr/bin/env bash
# The example station run as the README shows, with no PLC on the line:
# 1. with --no-plc its camera replays at `fps: 5` with a software trigger, which the station
#    then pulls itself. The configured rate must hold: it took about 100 parts a second (471
#    parts in 4.7 s, 430 stored as "missed: inspection fell behind").
# 2. without --no-plc, the missing PLC is said once with what to do, and the log backs off (it
#    logged "cannot connect ... retrying in 500 ms" twice a second forever).
#   station_without_plc.sh FACETD
set -u
facetd=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
recipes=$PWD/recipes
station=$work/station.yaml
sed -e "s#/tmp/facet-demo-results.db#$work/results.db#" -e "s#/tmp/facet-demo-archive#$work/archive#" \
    -e 's/port: 8080/port: 0/' -e "s#^recipes: \.\$#recipes: $recipes#" \
    -e "s#folder: demo/#folder: $recipes/demo/#" -e "s#file: calibration.yaml#file: $recipes/calibration.yaml#" \
    recipes/station.yaml > "$station"
grep -q 'fps: 5' "$station" || { echo "FAIL: the example station no longer says fps: 5"; exit 1; }
grep -q 'trigger: software' "$station" || { echo "FAIL: the example station no longer uses a software trigger"; exit 1; }
seconds=10
timeout -s TERM $seconds "$facetd" --config "$station" --no-plc --print-parts >"$work/parts.log" 2>"$work/err.log"
parts=$(grep -c '^part ' "$work/parts.log" || true)
echo "facetd --no-plc over $seconds s at fps 5: $parts parts taken"
# 5 per second at most. Parts may be missed when the first inspection is slow (a cold start on a
# busy machine); they are parts taken all the same, and were ~100 per second.
if [ "$parts" -gt $((5 * seconds + 3)) ]; then
  echo "FAIL: $parts parts in $seconds s: faster than the configured 5 per second"; head -5 "$work/parts.log"; exit 1
fi
if [ "$parts" -lt 1 ]; then
  echo "FAIL: no part in $seconds s"; cat "$work/err.log"; exit 1
fi

# 2. The station's PLC port, with nobody listening (a port we just found free).
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
sed -i "s/port: 1502/port: $port/" "$station"
timeout -s TERM 8 "$facetd" --config "$station" >"$work/out.log" 2>&1
advice=$(grep -c 'facetd with --no-plc' "$work/out.log" || true)
refused=$(grep -c 'cannot connect' "$work/out.log" || true)
echo "facetd without a PLC for 8 s: $refused 'cannot connect' lines, the advice $advice time(s)"
[ "$advice" -eq 1 ] || { echo "FAIL: the advice (plc-sim or --no-plc) should come once"; cat "$work/out.log"; exit 1; }
grep -q "facet plc-sim" "$work/out.log" || { echo "FAIL: no word of the PLC simulator"; exit 1; }
# At 500 ms between attempts, 8 s are about 16 attempts: logged at 1, 2, 4, 8 and 16.
[ "$refused" -le 6 ] || { echo "FAIL: the log did not back off"; cat "$work/out.log"; exit 1; }
echo "ok"
