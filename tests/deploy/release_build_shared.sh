#!/usr/bin/env bash
# demo.sh and test.sh configure their Release folder through deploy/configure-release.sh and
# nowhere else; configuring a folder with it twice leaves the build with nothing to do.
set -u
fail() { echo "FAIL: $*"; exit 1; }
for script in demo.sh test.sh; do
  grep -qF 'bash deploy/configure-release.sh "$build"' "$script" \
    || fail "$script does not configure its Release folder through deploy/configure-release.sh"
  if grep -nE 'cmake .*-DCMAKE_BUILD_TYPE=Release' "$script"; then
    fail "$script configures a Release folder with flags of its own"
  fi
done
# The shared script in a scratch folder: a second run (test.sh after demo.sh) changes nothing.
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
bash deploy/configure-release.sh "$scratch/build" || fail "deploy/configure-release.sh failed"
grep -q '^FACET_WERROR:BOOL=ON' "$scratch/build/CMakeCache.txt" || fail "not the CI's flags"
# The cache and every compile and link command (CMake may regenerate bookkeeping lines such as
# the unused TARGET_PDB of static libraries, which rebuild nothing).
state() {
  md5sum "$scratch/build/CMakeCache.txt"
  grep -E '^ *(FLAGS|DEFINES|INCLUDES|LINK_FLAGS|LINK_LIBRARIES) = ' "$scratch/build/build.ninja" | md5sum
}
before=$(state)
bash deploy/configure-release.sh "$scratch/build" || fail "second run failed"
after=$(state)
[ "$before" = "$after" ] || fail "a second configure changed the build"
echo "ok"
