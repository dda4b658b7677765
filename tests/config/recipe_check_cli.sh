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
echo "ok"
