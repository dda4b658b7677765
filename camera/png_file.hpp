#pragma once
// PNG files read in the process with libpng, without the image-codec module (image_codecs.hpp).
// PNG is what stations record and what models are trained from; loading the module
// (OpenImageIO, OpenCV's imgcodecs and the ~200 libraries behind them) cost each `facet` image
// command ~0.35 s, ten times the work of most commands. libpng alone is two small libraries.
//
// Only plain PNGs are read here, so that the result is the one the module gives bit for bit:
// 8 or 16 bits per channel, grey, grey+alpha, RGB or RGBA, not interlaced, without a
// transparency chunk. Anything else (other formats, palettes, fewer bits, Adam7, any error) is
// left to the module, which reads every format and words every error.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "camera/stored_layout_filter.hpp"

namespace facet {

struct PlainPng {
  // The file's channels as stored, colour in OpenCV's order (BGR, BGRA); CV_8U or CV_16U in the
  // machine's byte order.
  cv::Mat pixels;
  bool hasExif = false;  // an eXIf chunk (an orientation OpenCV's reader may apply)
};

// Reads `file` when it is a plain PNG of at most `maxPixels` pixels whose layout `wanted` accepts
// (an empty filter accepts every plain layout); nullopt otherwise (the caller hands the file to
// the module).
std::optional<PlainPng> readPlainPng(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted = {});

}  // namespace facet
