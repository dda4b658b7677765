#!/usr/bin/env bash
# Every example recipe, replayed by facetd over its recorded demo folder, must give the verdict
# recorded with each image (the sidecars' expected_verdict), and every image must be inspected.
# Each part's line (--print-parts, what the demo shows) is whole: a failed part says its cause
# and the recording's defect, and the bracket's bad parts fail by the measurement of their
# defect, not by an alignment lost to it.
#   replay_examples.sh FACETD
set -euo pipefail
facetd=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The example station, with the results and archive in a private folder and no fixed HTTP port.
# Its copy goes to that folder too, never into recipes/: other tests read (and copy) that folder
# meanwhile. Its relative paths (relative to the station file) become absolute.
recipes=$PWD/recipes
station=$work/station-under-test.yaml
sed -e "s#/tmp/facet-demo-results.db#$work/results.db#" -e "s#/tmp/facet-demo-archive#$work/archive#" \
    -e 's/port: 8080/port: 0/' -e "s#^recipes: \.\$#recipes: $recipes#" \
    -e "s#folder: demo/#folder: $recipes/demo/#" -e "s#file: calibration.yaml#file: $recipes/calibration.yaml#" \
    recipes/station.yaml > "$station"
status=0
for run in 1:bracket_registration 2:bracket_shape 3:fiducial_board 4:scan_offset; do
  id=${run%%:*}
  folder=recipes/demo/${run#*:}
  files=$(find "$folder" -maxdepth 1 \( -name '*.png' -o -name '*.csv' \) | wc -l)
  summary=$("$facetd" --config "$station" --no-plc --recipe "$id" \
              --replay "$folder" --print-parts | tee "$work/recipe-$id.log" | grep '^summary:')
  inspected=$(grep -c '^part .* \(pass\|fail\) ' "$work/recipe-$id.log" || true)
  echo "recipe $id ($folder, $files files): $summary; inspected $inspected"
  if ! grep -q ' unexpected=0$' <<<"$summary"; then
    echo "FAIL: recipe $id gave verdicts other than the recorded ones:"; grep UNEXPECTED "$work/recipe-$id.log" || true
    status=1
  fi
  if [ "$inspected" -ne "$files" ]; then
    echo "FAIL: recipe $id inspected $inspected of $files files"; status=1
  fi
  if grep '^part ' "$work/recipe-$id.log" | grep -v ' ms\]$' | grep -q .; then
    echo "FAIL: recipe $id: a part's line is cut (no time at its end)"; status=1
  fi
  if grep '^part .* fail ' "$work/recipe-$id.log" | grep -v '  cause: .*  recorded: fail (.*)  values: ' | grep -q .; then
    echo "FAIL: recipe $id: a failed part's line lacks its cause, recorded defect or values:"
    grep '^part .* fail ' "$work/recipe-$id.log"; status=1
  fi
done
# The recorded defects, by their cause and measured value (rendered: 1.2 mm and 0.85 mm bores,
# a bore 0.5 mm off its place), to the display's precision.
for expect in 'BR_003  fail  cause: big_bore\.diameter = 1\.2[0-9]* mm' \
              'BR_007  fail  cause: small_bore\.position = 0\.(49[0-9]*|5|50[0-9]*) mm' \
              'BR_011  fail  cause: big_bore\.diameter = 0\.(849[0-9]*|85|850[0-9]*) mm'; do
  if ! grep -qE -- "$expect" "$work/recipe-1.log"; then
    echo "FAIL: recipe 1 does not match '$expect':"; grep "${expect%%  *}" "$work/recipe-1.log"; status=1
  fi
done
exit $status
