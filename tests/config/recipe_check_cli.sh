#!/usr/bin/env bash
# `facet recipe check` on a broken recipe: exit code 1 and every problem as file:line:column.
set -u
facet=$1
file=tests/config/data/broken.recipe.yaml
out=$("$facet" recipe check --root . "$file" 2>&1)
rc=$?
echo "$out"
[ "$rc" -eq 1 ] || { echo "expected exit code 1, got $rc"; exit 1; }
for expected in \
  "$file:10:5: unknown key 'min_scor' in align step (did you mean 'min_score'?)" \
  "$file:13:18: 'relative_to' refers to unknown step 'prat' (did you mean 'part'?)" \
  "$file:18:43: tol_minus 1.5 of 'hole.diameter' is larger than its nominal 1 allows" \
  "facet: 3 error(s) in 1 recipe file(s)"; do
  grep -qF "$expected" <<<"$out" || { echo "missing: $expected"; exit 1; }
done
# Without --root the reference image lies outside the recipe's folder and is refused.
out=$("$facet" recipe check "$file" 2>&1)
grep -qF "$file:9:16: 'reference' path '../../../recipes/models/bracket_reference.png' leaves the recipes folder" <<<"$out" \
  || { echo "$out"; echo "missing: path escape"; exit 1; }
# A station file given as a recipe is recognised and checked as the station, with its recipes.
out=$("$facet" recipe check recipes/station.yaml 2>&1)
rc=$?
[ "$rc" -eq 0 ] || { echo "$out"; echo "station file as a recipe: expected exit code 0, got $rc"; exit 1; }
grep -qF "recipes/station.yaml: a station file" <<<"$out" || { echo "$out"; echo "missing: station file note"; exit 1; }
grep -qF "unknown key" <<<"$out" && { echo "$out"; echo "station keys reported as unknown recipe keys"; exit 1; }
grep -qF "ok (recipe" <<<"$out" || { echo "$out"; echo "missing: the station's recipes checked"; exit 1; }
echo "ok"
