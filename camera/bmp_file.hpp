#pragma once
// BMP files read in the process, without the image-codec module (image_codecs.hpp). Machine-vision
// tools and their sample sets store grey images as 8-bit BMPs; loading the module for one (the
// ~200 libraries behind OpenCV's imgcodecs) cost a `facet` command ~0.6 s, a hundred times the
// work of a shape search. No small, well-kept library in Debian reads BMP alone, and the plain
// layouts are a header and rows: they are read here.
//
// Only plain BMPs are read, so that the result is the module's bit for bit: uncompressed
// (BI_RGB), one plane, bottom-up or top-down rows, and either 8 bits per pixel with a grey
// palette (every entry r = g = b, every pixel's index inside it; the grey values are the
// palette's) or 24 bits per pixel (BGR as stored). Anything else (colour palettes, fewer bits,
// 16 or 32 bits, run-length or bit-field compression, a damaged or truncated file) is left to
// the module, which reads every kind and words every error.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "camera/stored_layout_filter.hpp"

namespace facet {

// The pixels of `file` when it is a plain BMP of at most `maxPixels` pixels whose layout `wanted`
// accepts (CV_8UC1 for grey, CV_8UC3 BGR; an empty filter accepts both); nullopt otherwise (the
// caller hands the file to the module).
std::optional<cv::Mat> readPlainBmp(const std::filesystem::path& file, std::uint64_t maxPixels,
                                    const StoredLayoutFilter& wanted = {});

}  // namespace facet
