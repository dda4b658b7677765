#pragma once
// Binary PGM files read in the process, without the image-codec module (image_codecs.hpp). A
// line that records frames for replay at a high rate keeps them as raw pixels (bench_daemon's
// --pgm), and loading the module for one cost a `facet` command ~0.4 s, ten times the rest of a
// shape match. The format is a text header and the rows as stored; no library is needed.
//
// Only what OpenCV's reader (the module's, for cv::imread and for replay frames) gives as the
// file's samples is read here, so that the result is the module's bit for bit: "P5", width,
// height and maximum value as decimal numbers separated by whitespace and `#` comments, one
// whitespace character, then the rows: one byte a sample up to a maximum of 255, else two
// (most significant first). Samples are kept as stored, also above the maximum (OpenCV does not
// scale them). Anything else (ASCII or colour PNM, a damaged or truncated file) is left to the
// module, which reads every kind and words every error.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "camera/stored_layout_filter.hpp"

namespace facet {

// The samples of `file` (CV_8UC1 or CV_16UC1) when it is such a PGM of at most `maxPixels`
// pixels whose layout `wanted` accepts (an empty filter accepts both); nullopt otherwise (the
// caller hands the file to the module).
std::optional<cv::Mat> readBinaryPgm(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted = {});

}  // namespace facet
