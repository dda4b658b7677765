#!/usr/bin/env bash
# The image codecs are a module loaded on first use (camera/image_codecs.hpp): facet and facetd
# must not link OpenImageIO or OpenCV's imgcodecs (each start would map ~200 more libraries), an
# image command must find the module in the build tree and in the installed layout, and a missing
# module must be a clear error, not a crash. Plain PNG, JPEG and TIFF files and binary PGMs are
# read without the module (camera/png_file.hpp, camera/jpeg_file.hpp, camera/tiff_file.hpp,
# camera/pgm_file.hpp); a Targa copy of the same image (made with OpenImageIO's oiiotool, which
# writes the others too) needs it.
#   usage: image_codecs_module_test.sh FACET FACETD BUILD_DIR   (from the repository root)
set -uo pipefail
facet=$1 facetd=$2 build=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v oiiotool >/dev/null || fail "oiiotool is missing (deploy/install-deps.sh installs openimageio-tools)"
work=$(mktemp -d)
prefix=$work/prefix
trap 'rm -rf "$work"' EXIT
png=recipes/demo/bracket_shape/part_000.png
tga=$work/part_000.tga
oiiotool "$png" -o "$tga" || fail "oiiotool could not write $tga"
png_match=(match --model recipes/models/bracket.shape --image "$png" --json)
match=(match --model recipes/models/bracket.shape --image "$tga" --json)

for program in "$facet" "$facetd"; do
  needed=$(readelf -d "$program" | grep NEEDED) || fail "readelf -d $program"
  if grep -Ei 'libOpenImageIO|libopencv_imgcodecs' <<<"$needed"; then
    fail "$program links an image codec library directly"
  fi
done

out=$("$facet" "${match[@]}") || fail "facet match with the module of the build tree: $out"
grep -q '"score"' <<<"$out" || fail "facet match printed no match: $out"

missing=/nonexistent/libfacet_image_codecs.so
png_out=$(FACET_IMAGE_CODECS=$missing "$facet" "${png_match[@]}" 2>&1) ||
  fail "a plain PNG must be read without the module: $png_out"
[[ $(grep -o '"score":[0-9.]*' <<<"$png_out") == $(grep -o '"score":[0-9.]*' <<<"$out") ]] ||
  fail "the PNG read without the module must match as the Targa file read by it: $png_out / $out"
grep -q "image codecs not loaded" <<<"$png_out" && fail "a plain PNG loaded the module: $png_out"

jpeg=$work/part_000.jpg
oiiotool "$png" --compression jpeg:95 -o "$jpeg" || fail "oiiotool could not write $jpeg"
jpeg_out=$(FACET_IMAGE_CODECS=$missing "$facet" match --model recipes/models/bracket.shape \
  --image "$jpeg" --json 2>&1) || fail "a plain JPEG must be read without the module: $jpeg_out"
grep -q '"score"' <<<"$jpeg_out" || fail "facet match found nothing in the JPEG: $jpeg_out"
grep -q "image codecs not loaded" <<<"$jpeg_out" && fail "a plain JPEG loaded the module: $jpeg_out"

tiff=$work/part_000.tif
oiiotool "$png" --compression lzw -o "$tiff" || fail "oiiotool could not write $tiff"
tiff_out=$(FACET_IMAGE_CODECS=$missing "$facet" match --model recipes/models/bracket.shape \
  --image "$tiff" --json 2>&1) || fail "a plain TIFF must be read without the module: $tiff_out"
[[ $(grep -o '"score":[0-9.]*' <<<"$tiff_out") == $(grep -o '"score":[0-9.]*' <<<"$out") ]] ||
  fail "the TIFF read without the module must match as the Targa file read by it: $tiff_out / $out"
grep -q "image codecs not loaded" <<<"$tiff_out" && fail "a plain TIFF loaded the module: $tiff_out"

pgm=$work/part_000.pgm
oiiotool "$png" -o "$pgm" || fail "oiiotool could not write $pgm"
pgm_out=$(FACET_IMAGE_CODECS=$missing "$facet" match --model recipes/models/bracket.shape \
  --image "$pgm" --json 2>&1) || fail "a binary PGM must be read without the module: $pgm_out"
[[ $(grep -o '"score":[0-9.]*' <<<"$pgm_out") == $(grep -o '"score":[0-9.]*' <<<"$out") ]] ||
  fail "the PGM read without the module must match as the Targa file read by it: $pgm_out / $out"
grep -q "image codecs not loaded" <<<"$pgm_out" && fail "a binary PGM loaded the module: $pgm_out"

err=$(FACET_IMAGE_CODECS=$missing "$facet" "${match[@]}" 2>&1 >/dev/null)
rc=$?
[[ $rc -eq 1 ]] || fail "a missing module must exit 1 (an unreadable image), got $rc: $err"
grep -q "part_000.tga: cannot read image: image codecs not loaded" <<<"$err" &&
  grep -q "$missing: cannot open shared object file" <<<"$err" ||
  fail "the error must name the image, the path tried and dlerror(): $err"

# The installed layout: <prefix>/bin/facet finds <prefix>/lib/facet/ through /proc/self/exe.
cmake --install "$build" --prefix "$prefix" >/dev/null || fail "cmake --install"
err=$(LD_DEBUG=files "$prefix/bin/facet" "${match[@]}" 2>&1 >/dev/null) ||
  fail "installed facet match failed"
grep -qF "$prefix/lib/facet/libfacet_image_codecs.so" <<<"$err" ||
  fail "installed facet did not load the module beside it in $prefix/lib/facet"
echo "image codecs: a module, found in the build tree and beside the installed binaries"
