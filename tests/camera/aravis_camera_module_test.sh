#!/usr/bin/env bash
# The aravis camera backend is a module loaded when the first aravis camera is made
# (camera/aravis_backend.hpp): facet and facetd must not link Aravis or GLib (each start would
# load 16 more libraries), commands without a GigE camera must not load them, a station with an
# aravis camera must find the module in the build tree and in the installed layout, and a module
# that cannot be loaded must be a clear error naming the path and the loader's reason.
#   usage: aravis_camera_module_test.sh FACET FACETD BUILD_DIR   (from the repository root)
set -uo pipefail
facet=$1 facetd=$2 build=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
work=$(mktemp -d)
prefix=$work/prefix
trap 'rm -rf "$work"' EXIT
gige_libraries='libaravis|libglib-2|libgobject-2|libgio-2'

for program in "$facet" "$facetd"; do
  needed=$(readelf -d "$program" | grep NEEDED) || fail "readelf -d $program"
  if grep -Ei "$gige_libraries" <<<"$needed"; then
    fail "$program links Aravis or GLib directly"
  fi
done

# The loader lists every library it opens on stderr.
png=recipes/demo/bracket_shape/part_000.png
png_match=(match --model recipes/models/bracket.shape --image "$png" --json)
for command in version "${png_match[*]}"; do
  # shellcheck disable=SC2086  # the command's words
  trace=$(LD_DEBUG=files "$facet" $command 2>&1 >/dev/null) || fail "facet $command failed: $trace"
  grep -q "file=libopencv_core" <<<"$trace" || fail "no loader trace for facet $command"
  if grep -Eo "file=[^ ]*($gige_libraries|libfacet_aravis_camera)[^ ]*" <<<"$trace" | sort -u; then
    fail "facet $command loaded the libraries above"
  fi
done

# A station with a GigE camera at an address where none answers (127.0.0.1, no fake camera):
# facetd gets as far as opening it, then stops with the camera's error, as for any camera that
# is not there at start.
cat >"$work/station.yaml" <<YAML
schema_version: 1
name: gige-module
camera:
  backend: aravis
  aravis:
    address: 127.0.0.1
    pixel_format: Mono8
    region: [0, 0, 640, 480]
recipes: $PWD/recipes
results:
  database: $work/results.db
http:
  bind: 127.0.0.1
  port: 0
calibration:
  file: $PWD/recipes/calibration.yaml
YAML
station=(--config "$work/station.yaml" --no-plc)

err=$(LD_DEBUG=files "$facetd" "${station[@]}" 2>&1 >/dev/null)
[[ $? -eq 1 ]] || fail "facetd without its camera must exit 1: $err"
grep -qF "$build/camera/libfacet_aravis_camera.so" <<<"$err" ||
  fail "facetd did not load the module of the build tree"
grep -q "file=libaravis-0.8" <<<"$err" || fail "the module did not bring libaravis"
grep -q "aravis camera 127.0.0.1: cannot open" <<<"$err" ||
  fail "the camera's own error must say it cannot be opened: $(grep facetd: <<<"$err")"

missing=/nonexistent/libfacet_aravis_camera.so
err=$(FACET_ARAVIS_CAMERA=$missing "$facetd" "${station[@]}" 2>&1 >/dev/null)
rc=$?
[[ $rc -eq 1 ]] || fail "a missing module must stop facetd with exit 1, got $rc: $err"
grep -q "aravis camera: the GigE Vision camera module cannot be loaded" <<<"$err" &&
  grep -q "$missing: cannot open shared object file" <<<"$err" ||
  fail "the error must say what cannot be loaded, the path tried and dlerror(): $err"

# The installed layout: <prefix>/bin/facetd finds <prefix>/lib/facet/ through /proc/self/exe.
cmake --install "$build" --prefix "$prefix" >/dev/null || fail "cmake --install"
err=$(LD_DEBUG=files "$prefix/bin/facetd" "${station[@]}" 2>&1 >/dev/null)
grep -qF "$prefix/lib/facet/libfacet_aravis_camera.so" <<<"$err" ||
  fail "installed facetd did not load the module beside it in $prefix/lib/facet"
grep -q "aravis camera 127.0.0.1: cannot open" <<<"$err" ||
  fail "installed facetd: $(grep facetd: <<<"$err")"
echo "aravis camera: a module, loaded only for a GigE camera, from the build tree or the install"
