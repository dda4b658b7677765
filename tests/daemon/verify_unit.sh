#!/usr/bin/env bash
# deploy/facetd.service must pass `systemd-analyze verify` without a single warning (verify exits
# 0 on unknown keys and unparsable values, so its output is checked too). The unit's ExecStart is
# pointed at the facetd of this build, as install.sh would put it in /usr/local/bin.
# Usage: verify_unit.sh <unit file> <facetd binary>. Exit 77 (skipped) without systemd-analyze.
set -u
unit=$1
facetd=$2
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "SKIPPED: systemd-analyze is not installed here; deploy/facetd.service was not verified"
  exit 77
fi
dir=$(mktemp -d /tmp/facet-unit-XXXXXX)
trap 'rm -rf "$dir"' EXIT

verify() {  # prints every complaint; fails on a non-zero exit or any output
  local out rc
  out=$(systemd-analyze verify --man=no "$1" 2>&1)
  rc=$?
  [[ -n $out ]] && echo "$out"
  [[ $rc -eq 0 && -z $out ]]
}

sed "s#/usr/local/bin/facetd#$facetd#" "$unit" >"$dir/facetd.service"
if ! verify "$dir/facetd.service"; then
  echo "FAILED: $unit does not verify cleanly"
  exit 1
fi
grep -q '^Type=notify$' "$unit" && grep -q '^WatchdogSec=' "$unit" && grep -q '^User=facet$' "$unit" ||
  { echo "FAILED: $unit lacks Type=notify, WatchdogSec or User=facet"; exit 1; }
# The check must be able to fail: a misspelt hardening option is reported.
sed 's/^ProtectSystem=strict$/ProtectSystem=strictly/' "$dir/facetd.service" >"$dir/broken.service"
if verify "$dir/broken.service" >/dev/null; then
  echo "FAILED: systemd-analyze accepted ProtectSystem=strictly; the check proves nothing"
  exit 1
fi
echo "deploy/facetd.service verifies cleanly (systemd-analyze $(systemd-analyze --version | head -1))"
